#include "CoupledSystem.hpp"

#include "BlockKernels.hpp"

#include "dda/core/CapacityBytes.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace dda {

struct CoupledSystem::Analysis {
	std::vector<int> pattern;  // unknowns per slot, then each link's (lo, hi) within the component
	std::size_t hash = 0;
	bool analysed = false;
	BlockCholesky cholesky;
	long lastBuild = 0;
	std::size_t bytes = 0;
	// The blocks (moving indices) and attempt of the factor it holds.
	std::vector<int> factoredMembers;
	std::size_t membersHash = 0;
	long factoredAttempt = -1;
	long factoredSolve = -1;  // the solve that made it (CoupledSystem::solves_)
};

void CoupledSystem::AnalysisDeleter::operator()(Analysis* a) const { delete a; }

namespace {

// Patterns unused for this many builds are dropped.
constexpr long kKeptBuilds = 16;

// Refinement (CoupledSystem.hpp): the normwise backward error it stops at,
// about 50 units of round-off (a direct Cholesky of a few hundred unknowns
// reaches about n u; the residual itself is computed with an error of a few
// u per entry, so much less could not be certified), and the most
// iterations it may take, a cap on its cost-based budget.
constexpr double kRefineTolerance = 1e-14;
constexpr int kMaxRefineIterations = 100;
// The iterative path stops after this many iterations (then the component
// is factorised): jointed masses of 150 to 1,700 free blocks take 50 to
// 160 at a backward error of 1e-12, static steps of the start from rest up
// to 300.
constexpr int kMaxIterativeIterations = 2000;
// The iterative path's rows are threaded from this many blocks (a block
// row's product is about 4,000 flops).
constexpr int kIterativeThreadsFrom = 128;
// Components of fewer blocks are always factorised: their factorisation
// costs a few iterations (12 blocks at half density: 7).
constexpr int kMinRefineBlocks = 8;

template <class Iterator>
std::size_t patternHash(Iterator first, Iterator last) {
	std::size_t h = 1469598103934665603ull;
	for (; first != last; ++first) h = (h ^ static_cast<std::size_t>(static_cast<unsigned>(*first))) * 1099511628211ull;
	return h;
}

int findRoot(std::vector<int>& parent, int k) {
	while (parent[k] != k) {
		parent[k] = parent[parent[k]];
		k = parent[k];
	}
	return k;
}

}  // namespace

void CoupledSystem::build(int movingBlocks, const std::vector<std::pair<int, int>>& links,
                          const std::vector<char>& hasSprings, const std::vector<int>& unknowns) {
	// Union-find over the links. A root is its set's smallest block (a union
	// hangs the larger root under the smaller), so a block's root is numbered
	// before the block itself and components come in the order of their
	// smallest blocks.
	std::vector<int> parent(movingBlocks);
	std::iota(parent.begin(), parent.end(), 0);
	for (auto [a, b] : links) {
		const int ra = findRoot(parent, a), rb = findRoot(parent, b);
		if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
	}
	// slot_ holds each coupled block's component first, its slot after the
	// component sizes are summed into componentStart_.
	slot_.assign(movingBlocks, -1);
	componentStart_.assign(1, 0);
	for (int k = 0; k < movingBlocks; ++k) {
		if (!hasSprings[k]) continue;
		const int root = findRoot(parent, k);
		if (root == k) {
			slot_[k] = components();
			componentStart_.push_back(0);
		} else {
			slot_[k] = slot_[root];
		}
		++componentStart_[slot_[k] + 1];
	}
	std::partial_sum(componentStart_.begin(), componentStart_.end(), componentStart_.begin());
	const int coupledBlocks = componentStart_.back();
	members_.resize(coupledBlocks);
	unknowns_.resize(coupledBlocks);
	std::vector<int> next(componentStart_.begin(), componentStart_.end() - 1);
	for (int k = 0; k < movingBlocks; ++k) {
		if (slot_[k] < 0) continue;
		const int s = next[slot_[k]]++;
		slot_[k] = s;
		members_[s] = k;
		unknowns_[s] = unknowns[k];
	}
	// A pair joined by several contacts is one link.
	linkSlots_.clear();
	for (auto [a, b] : links) {
		if (a == b) continue;
		linkSlots_.emplace_back(std::min(slot_[a], slot_[b]), std::max(slot_[a], slot_[b]));
	}
	std::sort(linkSlots_.begin(), linkSlots_.end());
	linkSlots_.erase(std::unique(linkSlots_.begin(), linkSlots_.end()), linkSlots_.end());
	// Both slots of a link lie in one component, whose slots are contiguous.
	linkStart_.resize(componentStart_.size());
	std::size_t link = 0;
	for (std::size_t c = 0; c < componentStart_.size(); ++c) {
		while (link < linkSlots_.size() && linkSlots_[link].first < componentStart_[c]) ++link;
		linkStart_[c] = static_cast<int>(link);
	}
	offDiagonal_.resize(linkSlots_.size());
	diagonal_.resize(coupledBlocks);
	force_.resize(coupledBlocks);
	keepAnalyses();
}

void CoupledSystem::keepAnalyses() {
	// Each sparse component's kept analysis, by its pattern (a pattern kept
	// once serves one component per build: components solve in parallel).
	++builds_;
	componentAnalysis_.assign(components(), nullptr);
	componentHash_.assign(components(), 0);
	if (!reuse_) {
		analyses_.clear();
		analysisByHash_.clear();
		return;
	}
	std::vector<int> pattern;
	for (int c = 0; c < components(); ++c) {
		const int first = componentStart_[c], last = componentStart_[c + 1];
		if (last - first == 1) continue;
		pattern.assign(unknowns_.begin() + first, unknowns_.begin() + last);
		for (int l = linkStart_[c]; l < linkStart_[c + 1]; ++l) {
			pattern.push_back(linkSlots_[l].first - first);
			pattern.push_back(linkSlots_[l].second - first);
		}
		const std::size_t hash = patternHash(pattern.begin(), pattern.end());
		componentHash_[c] = hash;
		Analysis* found = nullptr;
		for (auto [it, end] = analysisByHash_.equal_range(hash); it != end; ++it) {
			Analysis* a = it->second;
			if (a->lastBuild != builds_ && a->pattern == pattern) {
				found = a;
				// Claimed entries leave the index for this build: identical
				// patterns (many equal clusters) are found in constant time.
				analysisByHash_.erase(it);
				break;
			}
		}
		if (!found) {
			analyses_.emplace_back(new Analysis);
			found = analyses_.back().get();
			found->pattern = pattern;
			found->hash = hash;
		}
		found->lastBuild = builds_;
		componentAnalysis_[c] = found;
	}
	// Drop patterns unused for kKeptBuilds builds, and the oldest unused ones
	// while they hold more than the used ones (plus 1 MB); never a factor of
	// this attempt while refinement may use it (no more than the attempt's
	// factorisations).
	std::size_t used = 0, unused = 0;
	for (const AnalysisPtr& a : analyses_) (a->lastBuild == builds_ ? used : unused) += a->bytes;
	auto kept = [this](const Analysis& a) {
		return a.lastBuild == builds_ || (refine_ && a.factoredAttempt == attempt_);
	};
	std::stable_sort(analyses_.begin(), analyses_.end(), [&kept](const AnalysisPtr& a, const AnalysisPtr& b) {
		if (kept(*a) != kept(*b)) return kept(*a);
		return a->lastBuild > b->lastBuild;
	});
	while (!analyses_.empty()) {
		const Analysis& oldest = *analyses_.back();
		if (kept(oldest)) break;
		if (oldest.lastBuild >= builds_ - kKeptBuilds && unused <= used + (std::size_t(1) << 20)) break;
		unused -= oldest.bytes;
		analyses_.pop_back();
	}
	analysisByHash_.clear();
	for (const AnalysisPtr& a : analyses_) analysisByHash_.emplace(a->hash, a.get());
	// The factors of this attempt among the analyses kept.
	factorByMembers_.clear();
	for (const AnalysisPtr& a : analyses_)
		if (a->factoredAttempt == attempt_) factorByMembers_.emplace(a->membersHash, a.get());
}

void CoupledSystem::reset(const std::vector<BlockSystem>& systems, const std::vector<int>& systemOf) {
	for (std::size_t s = 0; s < members_.size(); ++s) {
		const BlockSystem& own = systems[systemOf[members_[s]]];
		diagonal_[s] = own.stiffness;
		force_[s] = own.force;
	}
	for (Matrix12& m : offDiagonal_) m.setZero();
}

Matrix12& CoupledSystem::offDiagonal(int a, int b, bool& transposed) {
	const int sa = slot_[a], sb = slot_[b];
	// Within a component slots ascend with the moving-block index, so this is a > b.
	transposed = sa > sb;
	const std::pair<int, int> key(std::min(sa, sb), std::max(sa, sb));
	const auto link = std::lower_bound(linkSlots_.begin(), linkSlots_.end(), key);
	if (link == linkSlots_.end() || *link != key)
		throw std::out_of_range("no link between moving blocks " + std::to_string(a) + " and " + std::to_string(b));
	return offDiagonal_[link - linkSlots_.begin()];
}

int CoupledSystem::largestComponent() const {
	int largest = 0;
	for (int c = 0; c < components(); ++c) largest = std::max(largest, componentStart_[c + 1] - componentStart_[c]);
	return largest;
}

std::size_t CoupledSystem::memoryBytes() const {
	std::size_t kept = capacityBytes(analyses_) + capacityBytes(componentAnalysis_) + capacityBytes(componentHash_) +
	                   analysisByHash_.size() * (sizeof(std::size_t) + sizeof(Analysis*) + 2 * sizeof(void*));
	for (const AnalysisPtr& a : analyses_) kept += sizeof(Analysis) + capacityBytes(a->pattern) + a->bytes;
	kept += iterative_.memoryBytes() + capacityBytes(slotCentroids_);
	return capacityBytes(slot_) + capacityBytes(members_) + capacityBytes(unknowns_) + capacityBytes(componentStart_) +
	       capacityBytes(diagonal_) + capacityBytes(force_) + capacityBytes(linkSlots_) + capacityBytes(linkStart_) +
	       capacityBytes(offDiagonal_) + kept;
}

bool CoupledSystem::solveSingleBlock(int slot, std::vector<Vector12>& solutions) const {
	const int k = members_[slot];
	if (unknowns_[slot] == kRigidBlockDofs) {
		Eigen::LLT<Matrix6> llt(diagonal_[slot].topLeftCorner<kRigidBlockDofs, kRigidBlockDofs>());
		solutions[k].head<kRigidBlockDofs>() = llt.solve(force_[slot].head<kRigidBlockDofs>());
		solutions[k].tail<kBlockDofs - kRigidBlockDofs>().setZero();
		return llt.info() == Eigen::Success;
	}
	Eigen::LLT<Matrix12> llt(diagonal_[slot]);
	solutions[k] = llt.solve(force_[slot]);
	return llt.info() == Eigen::Success;
}

void CoupledSystem::writeSolutions(int c, const std::vector<Vector12>& x, std::vector<Vector12>& solutions) const {
	const int first = componentStart_[c], last = componentStart_[c + 1];
	for (int s = first; s < last; ++s) {
		Vector12& solution = solutions[members_[s]];
		solution = x[s - first];
		if (unknowns_[s] != kBlockDofs) solution.tail<kBlockDofs - kRigidBlockDofs>().setZero();
	}
}

std::vector<std::pair<int, int>> CoupledSystem::localLinks(int c) const {
	const int first = componentStart_[c];
	std::vector<std::pair<int, int>> links;
	links.reserve(linkStart_[c + 1] - linkStart_[c]);
	for (int l = linkStart_[c]; l < linkStart_[c + 1]; ++l)
		links.emplace_back(linkSlots_[l].first - first, linkSlots_[l].second - first);
	return links;
}

bool CoupledSystem::solveComponent(int c, BlockCholesky& cholesky, bool analyse,
                                   std::vector<Vector12>& solutions) const {
	const int first = componentStart_[c], last = componentStart_[c + 1];
	if (analyse) cholesky.analyse(last - first, localLinks(c));
	if (!cholesky.factorize(&diagonal_[first], &offDiagonal_[linkStart_[c]], &unknowns_[first])) return false;
	std::vector<Vector12> x(force_.begin() + first, force_.begin() + last);
	cholesky.solve(x.data());
	writeSolutions(c, x, solutions);
	return true;
}

CoupledSystem::Analysis* CoupledSystem::preconditionerFor(int c) const {
	const int first = componentStart_[c], last = componentStart_[c + 1];
	const std::size_t hash = membersHash(c);
	// The latest factor of these blocks (the closest to the matrix now).
	Analysis* latest = nullptr;
	for (auto [it, end] = factorByMembers_.equal_range(hash); it != end; ++it) {
		Analysis* a = it->second;
		if (a->factoredAttempt != attempt_) continue;
		// Another component of this build refactorises it (in parallel).
		if (a->lastBuild == builds_ && a != componentAnalysis_[c]) continue;
		if (std::equal(members_.begin() + first, members_.begin() + last, a->factoredMembers.begin(),
		               a->factoredMembers.end()) &&
		    (!latest || a->factoredSolve > latest->factoredSolve))
			latest = a;
	}
	return latest;
}

std::size_t CoupledSystem::membersHash(int c) const {
	return patternHash(members_.begin() + componentStart_[c], members_.begin() + componentStart_[c + 1]);
}

double CoupledSystem::componentNorm(int c) const {
	// |K| (infinity norm: the largest absolute row sum), over the rows of the
	// restricted system (a rigid block's strain rows are the identity's,
	// left out).
	const int first = componentStart_[c], n = componentStart_[c + 1] - first;
	std::vector<Vector12> rowSums(n, Vector12::Zero());
	for (int k = 0; k < n; ++k) {
		const Matrix12 lower = diagonal_[first + k].selfadjointView<Eigen::Lower>();
		rowSums[k] += lower.cwiseAbs().rowwise().sum();
	}
	for (int l = linkStart_[c]; l < linkStart_[c + 1]; ++l) {
		const int lo = linkSlots_[l].first - first, hi = linkSlots_[l].second - first;
		rowSums[lo] += offDiagonal_[l].cwiseAbs().rowwise().sum();
		rowSums[hi] += offDiagonal_[l].cwiseAbs().colwise().sum().transpose();
	}
	double largest = 0;
	for (int k = 0; k < n; ++k) {
		if (unknowns_[first + k] != kBlockDofs) rowSums[k].tail<kBlockDofs - kRigidBlockDofs>().setZero();
		largest = std::max(largest, rowSums[k].lpNorm<Eigen::Infinity>());
	}
	return largest;
}

bool CoupledSystem::refineComponent(int c, const BlockCholesky& factor, int maxIterations,
                                    std::vector<Vector12>& solutions, int& iterations) const {
	const int first = componentStart_[c], last = componentStart_[c + 1], n = last - first;
	const int linkFirst = linkStart_[c], linkLast = linkStart_[c + 1];
	// A rigid block's strain unknowns are zero: its vectors' strain parts are
	// kept zero (the restricted system, as BlockCholesky factorises it).
	auto restrictRigid = [&](std::vector<Vector12>& v) {
		for (int k = 0; k < n; ++k)
			if (unknowns_[first + k] != kBlockDofs) v[k].tail<kBlockDofs - kRigidBlockDofs>().setZero();
	};
	// y = K x, K symmetric from the lower triangles of its diagonal blocks
	// (the triangles the Cholesky reads) and the stored upper blocks.
	auto multiply = [&](const std::vector<Vector12>& x, std::vector<Vector12>& y) {
		for (int k = 0; k < n; ++k) symmetricLowerProduct(y[k], diagonal_[first + k], x[k]);
		for (int l = linkFirst; l < linkLast; ++l) {
			const int lo = linkSlots_[l].first - first, hi = linkSlots_[l].second - first;
			addProduct(y[lo], offDiagonal_[l], x[hi]);
			addTransposedProduct(y[hi], offDiagonal_[l], x[lo]);
		}
		restrictRigid(y);
	};
	auto dot = [n](const std::vector<Vector12>& a, const std::vector<Vector12>& b) {
		double sum = 0;
		for (int k = 0; k < n; ++k) sum += a[k].dot(b[k]);
		return sum;
	};
	auto largest = [n](const std::vector<Vector12>& a) {
		double m = 0;
		for (int k = 0; k < n; ++k) m = std::max(m, a[k].lpNorm<Eigen::Infinity>());
		return m;
	};
	const double normK = componentNorm(c);

	std::vector<Vector12> b(force_.begin() + first, force_.begin() + last);
	restrictRigid(b);
	const double normB = largest(b);
	std::vector<Vector12> x(n, Vector12::Zero()), r = b, z = r, p(n), q(n);
	factor.solve(z.data());
	p = z;
	double rz = dot(r, z);
	bool converged = false;
	iterations = 0;
	// Converged (true residual, not the recurrence's) when its backward error is within the tolerance.
	auto certified = [&]() {
		multiply(x, q);
		for (int k = 0; k < n; ++k) q[k] = b[k] - q[k];
		return largest(q) <= kRefineTolerance * (normK * largest(x) + normB);
	};
	if (!(normB > 0)) {
		converged = true;  // b = 0: x = 0
	} else {
		while (iterations < maxIterations) {
			++iterations;
			multiply(p, q);
			const double pq = dot(p, q);
			if (!(pq > 0) || !std::isfinite(pq)) break;
			const double alpha = rz / pq;
			for (int k = 0; k < n; ++k) {
				x[k] += alpha * p[k];
				r[k] -= alpha * q[k];
			}
			if (largest(r) <= kRefineTolerance * (normK * largest(x) + normB) && certified()) {
				converged = true;
				break;
			}
			z = r;
			factor.solve(z.data());
			const double rzNext = dot(r, z);
			const double beta = rzNext / rz;
			rz = rzNext;
			for (int k = 0; k < n; ++k) p[k] = z[k] + beta * p[k];
		}
	}
	if (!converged) return false;
	writeSolutions(c, x, solutions);
	return true;
}

bool CoupledSystem::iterateComponent(int c, std::vector<Vector12>& solutions, int& iterations, int threadsFrom) {
	const int first = componentStart_[c], last = componentStart_[c + 1];
	std::vector<std::pair<int, int>> links = localLinks(c);
	BlockConjugateGradient::Matrix matrix;
	matrix.blocks = last - first;
	matrix.diagonal = &diagonal_[first];
	matrix.offDiagonal = &offDiagonal_[linkStart_[c]];
	matrix.links = links.data();
	matrix.linkCount = static_cast<int>(links.size());
	matrix.sizes = &unknowns_[first];
	if (centroids_ && coarseFrom_ > 0 && last - first >= coarseFrom_) {
		slotCentroids_.resize(last - first);
		for (int s = first; s < last; ++s) slotCentroids_[s - first] = (*centroids_)[members_[s]];
		matrix.centroids = slotCentroids_.data();
	}
	BlockConjugateGradient& solver = iterative_;
	iterations = 0;
	if (!solver.prepare(matrix, std::min(threadsFrom, kIterativeThreadsFrom), coarseFrom_)) return false;
	coarseAggregates_ += solver.coarseAggregates();
	// The first iterate: this attempt's last solution (the open-close
	// iteration's systems differ by a few contacts' terms), else zero.
	std::vector<Vector12> x(last - first, Vector12::Zero());
	if (warm_)
		for (int s = first; s < last; ++s) x[s - first] = solutions[members_[s]];
	const bool converged = solver.solve(&force_[first], x.data(), iterativeTolerance_, kMaxIterativeIterations);
	iterations = solver.iterations();
	if (!converged) return false;
	writeSolutions(c, x, solutions);
	return true;
}

void CoupledSystem::iterateLargeComponents(std::vector<Vector12>& solutions, int threadsFrom,
                                           std::vector<char>& iterated, long& solved) {
	// One component after another, each threaded over its rows (inside the
	// components' parallel loop it would run on one thread); one that does
	// not converge is factorised by solveOtherComponents.
	const int count = components();
	iterated.assign(count, 0);
	coarseAggregates_ = 0;
	int done = 0, iterations = 0, fallbacks = 0;
	for (int c = 0; iterativeFrom_ > 0 && c < count; ++c) {
		const int first = componentStart_[c], last = componentStart_[c + 1];
		if (last - first < std::max(iterativeFrom_, 2)) continue;
		int its = 0;
		iterated[c] = iterateComponent(c, solutions, its, threadsFrom);
		iterations += its;
		if (iterated[c]) {
			++done;
			for (int s = first; s < last; ++s) solved += unknowns_[s];
		} else {
			++fallbacks;
		}
	}
	iterativeComponents_ = done;
	iterativeIterations_ = iterations;
	iterativeFallbacks_ = fallbacks;
}

long CoupledSystem::refineBudget(int c, const Analysis& from) const {
	// A budget of iterations that cost about one factorisation: a product of
	// the factorisation is 12 matrix-vector products, an iteration 2 per
	// factor block (the preconditioner's solve), about 3 per diagonal block
	// and 2 per link (K p), and runs at about half the products' rate
	// (measured: a dense 66-block factorisation costs 29 iterations, 40
	// blocks at half density 20, 20 blocks at 30 % 9; the budgets are 32,
	// 22, 8).
	const long perIteration = 2 * from.cholesky.factorBlocks() + 3 * (componentStart_[c + 1] - componentStart_[c]) +
	                          2 * (linkStart_[c + 1] - linkStart_[c]);
	return std::min<long>(kMaxRefineIterations, 6 * from.cholesky.factorProducts() / perIteration);
}

bool CoupledSystem::factorComponent(int c, std::vector<Vector12>& solutions, Factorisation& how) {
	Analysis* analysis = componentAnalysis_.empty() ? nullptr : componentAnalysis_[c];
	if (!analysis) {
		how = Factorisation::Own;
		BlockCholesky cholesky;
		return solveComponent(c, cholesky, true, solutions);
	}
	const bool analyse = !analysis->analysed;
	how = analyse ? Factorisation::NewAnalysis : Factorisation::KeptAnalysis;
	const bool solvedHere = solveComponent(c, analysis->cholesky, analyse, solutions);
	if (analyse) {
		analysis->analysed = true;
		analysis->bytes = analysis->cholesky.memoryBytes();
	}
	return solvedHere;
}

void CoupledSystem::keepFactors(const std::vector<char>& factored) {
	// The factors made now precondition the attempt's later solves of the same blocks.
	for (int c = 0; c < components(); ++c) {
		if (!factored[c] || !refine_ || componentStart_[c + 1] - componentStart_[c] < kMinRefineBlocks) continue;
		Analysis* a = componentAnalysis_[c];
		a->factoredMembers.assign(members_.begin() + componentStart_[c], members_.begin() + componentStart_[c + 1]);
		a->membersHash = membersHash(c);
		a->factoredAttempt = attempt_;
		a->factoredSolve = solves_;
		for (auto [it, end] = factorByMembers_.equal_range(a->membersHash); it != end; ++it)
			if (it->second == a) {
				factorByMembers_.erase(it);
				break;
			}
		factorByMembers_.emplace(a->membersHash, a);
	}
}

void CoupledSystem::solve(std::vector<Vector12>& solutions, int threadsFrom) {
	++solves_;
	const int count = components();
	bool failed = false;
	// An integer sum, exact in any order: the count does not depend on the thread count.
	long solved = 0;
	int reusedAnalyses = 0, newAnalyses = 0, refined = 0, refineIterations = 0, fallbacks = 0;
	std::vector<char> iteratedHere;
	iterateLargeComponents(solutions, threadsFrom, iteratedHere, solved);
	// Refinement's preconditioners, found before the components run in parallel.
	std::vector<Analysis*> preconditioner(count, nullptr);
	std::vector<char> factored(count, 0);
	if (refine_ && reuse_)
		for (int c = 0; c < count; ++c)
			if (componentStart_[c + 1] - componentStart_[c] >= kMinRefineBlocks) preconditioner[c] = preconditionerFor(c);
#pragma omp parallel for schedule(dynamic) \
    reduction(+ : solved, reusedAnalyses, newAnalyses, refined, refineIterations, fallbacks) if (count >= threadsFrom)
	for (int c = 0; c < count; ++c) {
		if (iteratedHere[c]) continue;
		const int first = componentStart_[c], last = componentStart_[c + 1];
		for (int s = first; s < last; ++s) solved += unknowns_[s];
		if (last - first == 1) {
			if (!solveSingleBlock(first, solutions)) {
#pragma omp atomic write
				failed = true;
			}
			continue;
		}
		if (const Analysis* from = preconditioner[c]) {
			const long budget = refineBudget(c, *from);
			int iterations = 0;
			if (budget >= 2) {
				const bool converged = refineComponent(c, from->cholesky, static_cast<int>(budget), solutions, iterations);
				refineIterations += iterations;
				if (converged) {
					++refined;
					continue;
				}
				++fallbacks;
			}
		}
		Factorisation how = Factorisation::Own;
		const bool solvedHere = factorComponent(c, solutions, how);
		if (how != Factorisation::Own) {
			factored[c] = 1;
			++(how == Factorisation::NewAnalysis ? newAnalyses : reusedAnalyses);
		}
		if (!solvedHere) {
#pragma omp atomic write
			failed = true;
		}
	}
	if (failed) throw std::runtime_error("the DDA system is not positive definite (Cholesky failed)");
	solvedUnknowns_ = solved;
	reusedAnalyses_ = reusedAnalyses;
	newAnalyses_ = newAnalyses;
	refinedComponents_ = refined;
	refineIterations_ = refineIterations;
	refineFallbacks_ = fallbacks;
	warm_ = true;
	keepFactors(factored);
}

}  // namespace dda
