#include "CoupledSystem.hpp"

#include "dda/util/CapacityBytes.hpp"

#include <Eigen/Cholesky>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace dda {

namespace {

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
	return capacityBytes(slot_) + capacityBytes(members_) + capacityBytes(unknowns_) + capacityBytes(componentStart_) +
	       capacityBytes(diagonal_) + capacityBytes(force_) + capacityBytes(linkSlots_) + capacityBytes(linkStart_) +
	       capacityBytes(offDiagonal_);
}

void CoupledSystem::solve(std::vector<Vector12>& solutions, int threadsFrom) {
	const int count = components();
	bool failed = false;
	// An integer sum, exact in any order: the count does not depend on the thread count.
	long solved = 0;
#pragma omp parallel for schedule(dynamic) reduction(+ : solved) if (count >= threadsFrom)
	for (int c = 0; c < count; ++c) {
		const int first = componentStart_[c], last = componentStart_[c + 1];
		if (last - first == 1) {
			const int k = members_[first];
			solved += unknowns_[first];
			if (unknowns_[first] == kRigidBlockDofs) {
				Eigen::LLT<Matrix6> llt(diagonal_[first].topLeftCorner<kRigidBlockDofs, kRigidBlockDofs>());
				if (llt.info() != Eigen::Success) {
#pragma omp atomic write
					failed = true;
				}
				solutions[k].head<kRigidBlockDofs>() = llt.solve(force_[first].head<kRigidBlockDofs>());
				solutions[k].tail<kBlockDofs - kRigidBlockDofs>().setZero();
			} else {
				Eigen::LLT<Matrix12> llt(diagonal_[first]);
				if (llt.info() != Eigen::Success) {
#pragma omp atomic write
					failed = true;
				}
				solutions[k] = llt.solve(force_[first]);
			}
			continue;
		}
		// Variable block sizes: slot s's unknowns start at offset[s - first]
		// and number unknowns_[s] (12, or 6 for a rigid block, whose strain
		// rows and columns of the stored 12x12 blocks are left out).
		std::vector<int> offset(last - first + 1, 0);
		for (int s = first; s < last; ++s) offset[s - first + 1] = offset[s - first] + unknowns_[s];
		const int n = offset.back();
		solved += n;
		std::vector<Eigen::Triplet<double>> entries;
		entries.reserve(static_cast<std::size_t>(last - first) * 78 +
		                static_cast<std::size_t>(linkStart_[c + 1] - linkStart_[c]) * 144);
		Eigen::VectorXd rhs(n);
		for (int s = first; s < last; ++s) {
			const int base = offset[s - first], size = unknowns_[s];
			for (int col = 0; col < size; ++col)
				for (int row = col; row < size; ++row) entries.emplace_back(base + row, base + col, diagonal_[s](row, col));
			rhs.segment(base, size) = force_[s].head(size);
		}
		for (int link = linkStart_[c]; link < linkStart_[c + 1]; ++link) {
			// Stored block is K[lo][hi]; the lower triangle holds K[hi][lo] = its transpose.
			const auto [lo, hi] = linkSlots_[link];
			const int rowBase = offset[hi - first], colBase = offset[lo - first];
			const int rows = unknowns_[hi], cols = unknowns_[lo];
			const Matrix12& m = offDiagonal_[link];
			for (int col = 0; col < cols; ++col)
				for (int row = 0; row < rows; ++row) entries.emplace_back(rowBase + row, colBase + col, m(col, row));
		}
		Eigen::SparseMatrix<double> K(n, n);
		K.setFromTriplets(entries.begin(), entries.end());
		Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> llt(K);
		if (llt.info() != Eigen::Success) {
#pragma omp atomic write
			failed = true;
			continue;
		}
		const Eigen::VectorXd x = llt.solve(rhs);
		for (int s = first; s < last; ++s) {
			const int k = members_[s], size = unknowns_[s];
			solutions[k].setZero();
			solutions[k].head(size) = x.segment(offset[s - first], size);
		}
	}
	if (failed) throw std::runtime_error("the DDA system is not positive definite (Cholesky failed)");
	solvedUnknowns_ = solved;
}

}  // namespace dda
