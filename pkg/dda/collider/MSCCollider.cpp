#include "MSCCollider.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <string>

// Why the linked sub-units hold every feature of a pair's contacts. A
// vertex-face contact P -> F has P within reach = d0 + lengthTolerance of F's
// plane (or penetrating by at most delta, the pair's depth) and P's projection
// within reach of F (a distance to the polygon, also near its acute corners),
// so P is within sqrt(2) max(reach, delta) of a point q of F.
// P lies in a slice of its block, q in a slice of the other; those slices'
// shells link P and F (a feature is linked to every slab it touches), and
// their boxes, widened by d0 + w each, overlap whenever every coordinate of
// P - q is at most 2 d0 + wA + wB: true for delta <= d0 / 2 (w covers the
// length tolerance). An edge-edge contact's closest points are |gap| apart,
// gap in [2 min(separation, 0) - reach, reach]: the same bound. So the union
// over the overlapping shells links them. Deeper overlaps are not covered by
// this argument (a corner far inside may pick a face beyond its shells).

namespace dda {

namespace {

void checkCover(double criticalLength, int segments, const std::string& what) {
	if (!(criticalLength > 0) || !std::isfinite(criticalLength))
		throw InputError(what + ": critical length must be positive and finite, got " + std::to_string(criticalLength));
	if (segments < 1 || segments > MSCCollider::kMaxSegments)
		throw InputError(what + ": segments must be in [1, " + std::to_string(MSCCollider::kMaxSegments) + "], got " +
		                 std::to_string(segments));
}

// The block's size [m]: its creation size, else the cube root of its volume.
double blockSize(const Block& block) { return block.size > 0 ? block.size : std::cbrt(block.volume); }

}  // namespace

MSCCollider::MSCCollider(double criticalLengthFactor, int segments)
    : criticalLengthFactor_(criticalLengthFactor), segments_(segments) {
	checkCover(criticalLengthFactor, segments, "MSCCollider");
}

void MSCCollider::setCover(double criticalLength, int segments) {
	if (!(criticalLength >= 0) || !std::isfinite(criticalLength))
		throw InputError("MSCCollider: critical length must be >= 0 (0: by block size) and finite, got " +
		                 std::to_string(criticalLength));
	checkCover(criticalLength == 0 ? 1.0 : criticalLength, segments, "MSCCollider");
	criticalLength_ = criticalLength;
	segments_ = segments;
	coverChanged_ = true;
}

void MSCCollider::setBlockCover(int block, double criticalLength, int segments) {
	if (block < 0) throw InputError("MSCCollider: block index must be >= 0, got " + std::to_string(block));
	checkCover(criticalLength, segments, "MSCCollider block " + std::to_string(block));
	overrides_[block] = Override{criticalLength, segments};
	coverChanged_ = true;
}

const LinkedSubUnits* MSCCollider::linked(int pairIndex) const {
	return pairIndex >= 0 && pairIndex < linkedCount_ ? &linked_[pairIndex] : nullptr;
}

const Eigen::AlignedBox3d& MSCCollider::shellBox(int block, int shell) const {
	const BlockCover& cover = covers_.at(block);
	if (shell < 0 || shell >= cover.shellCount)
		throw InputError("MSCCollider: block " + std::to_string(block) + " has " + std::to_string(cover.shellCount) +
		                 " shells, asked for shell " + std::to_string(shell));
	return boxes_[cover.firstShell + shell];
}

void MSCCollider::buildCover(const Block& block, double criticalLength, int segments, BlockCover& cover) const {
	const ConvexPolyhedron& shape = *block.shape;
	const std::vector<Vector3>& x = block.vertices;
	const int nv = static_cast<int>(x.size());
	const int ne = static_cast<int>(shape.edges.size());
	const int nf = static_cast<int>(shape.faces.size());
	cover.shape = block.shape.get();
	cover.criticalLength = criticalLength;
	cover.segments = segments;
	cover.boxesBuilt = false;
	Eigen::AlignedBox3d box;
	for (const Vector3& p : x) box.extend(p);
	cover.widening = kShellWideningRelative * box.diagonal().norm();
	double longest = 0;
	for (const auto& e : shape.edges) longest = std::max(longest, (x[e[1]] - x[e[0]]).norm());
	const int k = longest > criticalLength ? segments : 1;
	cover.shellCount = k;
	cover.shells.assign(k, Shell{});
	if (k == 1) {
		for (int v = 0; v < nv; ++v) cover.shells[0].corners.push_back(v);
		cover.vertexShells.assign(nv, 1);
		cover.edgeShells.assign(ne, 1);
		cover.faceShells.assign(nf, 1);
		return;
	}
	// Main axis: the principal direction of largest spread of the corners.
	Vector3 mean = Vector3::Zero();
	for (const Vector3& p : x) mean += p;
	mean /= nv;
	Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
	for (const Vector3& p : x) spread += (p - mean) * (p - mean).transpose();
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(spread);
	const Vector3 axis = eigen.eigenvectors().col(2);  // eigenvalues ascending
	std::vector<double> s(nv);
	for (int v = 0; v < nv; ++v) s[v] = axis.dot(x[v] - mean);
	const double low = *std::min_element(s.begin(), s.end()), high = *std::max_element(s.begin(), s.end());
	// Slab j is [bound[j], bound[j + 1]], closed: a sub-unit on a plane is in both.
	std::vector<double> bound(k + 1);
	for (int j = 0; j <= k; ++j) bound[j] = low + (high - low) * j / k;
	bound[k] = high;
	const auto shellsOf = [&](double lo, double hi) {
		std::uint64_t mask = 0;
		for (int j = 0; j < k; ++j)
			if (lo <= bound[j + 1] && hi >= bound[j]) mask |= std::uint64_t{1} << j;
		return mask;
	};
	cover.vertexShells.resize(nv);
	for (int v = 0; v < nv; ++v) cover.vertexShells[v] = shellsOf(s[v], s[v]);
	cover.edgeShells.resize(ne);
	for (int e = 0; e < ne; ++e) {
		const double s0 = s[shape.edges[e][0]], s1 = s[shape.edges[e][1]];
		cover.edgeShells[e] = shellsOf(std::min(s0, s1), std::max(s0, s1));
	}
	cover.faceShells.resize(nf);
	for (int f = 0; f < nf; ++f) {
		double lo = s[shape.faces[f][0]], hi = lo;
		for (int v : shape.faces[f]) {
			lo = std::min(lo, s[v]);
			hi = std::max(hi, s[v]);
		}
		cover.faceShells[f] = shellsOf(lo, hi);
	}
	for (int j = 0; j < k; ++j) {
		Shell& shell = cover.shells[j];
		for (int v = 0; v < nv; ++v)
			if (cover.vertexShells[v] >> j & 1) shell.corners.push_back(v);
		// Division points on the slab's inner planes (its outer ends hold corners).
		for (int side = 0; side < 2; ++side) {
			if ((side == 0 && j == 0) || (side == 1 && j == k - 1)) continue;
			const double plane = bound[j + side];
			for (int e = 0; e < ne; ++e) {
				const double s0 = s[shape.edges[e][0]], s1 = s[shape.edges[e][1]];
				if (std::min(s0, s1) < plane && plane < std::max(s0, s1))
					shell.divisions.push_back({e, std::clamp((plane - s0) / (s1 - s0), 0.0, 1.0)});
			}
		}
	}
}

void MSCCollider::updateBoxes(const Block& block, BlockCover& cover) {
	const ConvexPolyhedron& shape = *block.shape;
	const std::vector<Vector3>& x = block.vertices;
	for (int j = 0; j < cover.shellCount; ++j) {
		const Shell& shell = cover.shells[j];
		Eigen::AlignedBox3d box;
		for (int v : shell.corners) box.extend(x[v]);
		for (const DivisionPoint& d : shell.divisions) {
			const Vector3& p = x[shape.edges[d.edge][0]];
			const Vector3& q = x[shape.edges[d.edge][1]];
			box.extend(p + d.fraction * (q - p));
		}
		boxes_[cover.firstShell + j] = box;
	}
	cover.boxesBuilt = true;
	totalShellUpdates_ += cover.shellCount;
}

void MSCCollider::collect(const std::vector<std::uint64_t>& linkedShells, std::uint64_t shells, std::vector<int>& out) {
	out.clear();
	const int n = static_cast<int>(linkedShells.size());
	for (int i = 0; i < n; ++i)
		if (linkedShells[i] & shells) out.push_back(i);
}

void MSCCollider::findPairs(const std::vector<Block>& blocks, double contactDistance,
                            std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) {
	pairs.clear();
	stats = BroadPhaseStatistics{};
	linkedCount_ = 0;
	const int n = static_cast<int>(blocks.size());

	// Topology: the block count changed (all), a block's shape changed, or the
	// cover's parameters changed (blocks whose parameters differ).
	bool layoutChanged = false;
	if (static_cast<int>(covers_.size()) != n) {
		covers_.assign(n, BlockCover{});
		layoutChanged = true;
	}
	for (int b = 0; b < n; ++b) {
		BlockCover& cover = covers_[b];
		const bool fresh = cover.shape != blocks[b].shape.get();
		if (!fresh && !coverChanged_) continue;
		const auto own = overrides_.find(b);
		const double criticalLength = own != overrides_.end() ? own->second.criticalLength
		                              : criticalLength_ > 0  ? criticalLength_
		                                                     : criticalLengthFactor_ * blockSize(blocks[b]);
		const int segments = own != overrides_.end() ? own->second.segments : segments_;
		if (!fresh && criticalLength == cover.criticalLength && segments == cover.segments) continue;
		buildCover(blocks[b], criticalLength, segments, cover);
		++coverBuilds_;
		layoutChanged = true;
	}
	coverChanged_ = false;
	if (layoutChanged) {
		int total = 0;
		for (BlockCover& cover : covers_) {
			cover.firstShell = total;
			cover.boxesBuilt = false;
			total += cover.shellCount;
		}
		boxes_.resize(total);
		shellBlock_.resize(total);
		shellIndex_.resize(total);
		for (int b = 0; b < n; ++b)
			for (int j = 0; j < covers_[b].shellCount; ++j) {
				shellBlock_[covers_[b].firstShell + j] = b;
				shellIndex_[covers_[b].firstShell + j] = j;
			}
	}
	const int shellTotal = static_cast<int>(boxes_.size());
	stats.shells = shellTotal;

	// Boxes: moving blocks every call, fixed blocks once.
	const long updatesBefore = totalShellUpdates_;
	for (int b = 0; b < n; ++b)
		if (!blocks[b].fixed || !covers_[b].boxesBuilt) updateBoxes(blocks[b], covers_[b]);
	stats.shellUpdates = totalShellUpdates_ - updatesBefore;
	if (n < 2) return;

	widened_.resize(shellTotal);
	Eigen::AlignedBox3d domain;
	double sideSum = 0;
	const double margin = kBroadPhaseMarginFactor * contactDistance;
	for (int s = 0; s < shellTotal; ++s) {
		const Vector3 w = Vector3::Constant(margin + covers_[shellBlock_[s]].widening);
		widened_[s] = Eigen::AlignedBox3d(boxes_[s].min() - w, boxes_[s].max() + w);
		domain.extend(widened_[s]);
		sideSum += widened_[s].sizes().maxCoeff();
	}

	// Subspaces: cubic cells as wide as the mean shell's largest side (at
	// least 1/kMaxCellsPerAxis of the domain). A shell enters every cell it
	// overlaps; one spanning more than kMaxCellsPerShell cells (a floor, a
	// block much larger than the rest) is compared with every shell instead.
	// Two shells are compared in one cell only: the cell holding the lower
	// corner of their boxes' intersection.
	const Vector3 origin = domain.min();
	const double cell = std::max(sideSum / shellTotal, domain.sizes().maxCoeff() / kMaxCellsPerAxis);
	const auto cellOf = [&](const Vector3& x) {
		return ((x - origin) / cell).array().floor().cast<long>().min(kMaxCellsPerAxis - 1).max(0).eval();
	};
	const auto key = [](const Eigen::Array<long, 3, 1>& c) {
		return static_cast<std::uint64_t>(c.x()) << 42 | static_cast<std::uint64_t>(c.y()) << 21 |
		       static_cast<std::uint64_t>(c.z());
	};
	cellEntries_.clear();
	oversize_.clear();
	for (int s = 0; s < shellTotal; ++s) {
		const Eigen::Array<long, 3, 1> lo = cellOf(widened_[s].min()), hi = cellOf(widened_[s].max());
		const Eigen::Array<long, 3, 1> span = hi - lo + 1;
		if (span.prod() > kMaxCellsPerShell) {
			oversize_.push_back(s);
			continue;
		}
		for (long i = lo.x(); i <= hi.x(); ++i)
			for (long j = lo.y(); j <= hi.y(); ++j)
				for (long k = lo.z(); k <= hi.z(); ++k)
					cellEntries_.emplace_back(key(Eigen::Array<long, 3, 1>(i, j, k)), s);
	}
	std::sort(cellEntries_.begin(), cellEntries_.end());
	isOversize_.assign(shellTotal, 0);
	for (int s : oversize_) isOversize_[s] = 1;

	hits_.clear();
	const auto compare = [&](int s, int t) {
		const int a = shellBlock_[s], b = shellBlock_[t];
		if (a == b || (blocks[a].fixed && blocks[b].fixed)) return;
		++stats.shellTests;
		if (!widened_[s].intersects(widened_[t])) return;
		const std::uint64_t bitS = std::uint64_t{1} << shellIndex_[s], bitT = std::uint64_t{1} << shellIndex_[t];
		hits_.push_back(a < b ? ShellHit{a, b, bitS, bitT} : ShellHit{b, a, bitT, bitS});
	};
	const std::size_t entries = cellEntries_.size();
	for (std::size_t first = 0; first < entries;) {
		std::size_t last = first + 1;
		while (last < entries && cellEntries_[last].first == cellEntries_[first].first) ++last;
		const std::uint64_t here = cellEntries_[first].first;
		for (std::size_t p = first; p < last; ++p)
			for (std::size_t q = p + 1; q < last; ++q) {
				const int s = cellEntries_[p].second, t = cellEntries_[q].second;
				const Vector3 low = widened_[s].min().cwiseMax(widened_[t].min());
				if (key(cellOf(low)) != here) continue;  // compared in another cell
				compare(s, t);
			}
		first = last;
	}
	for (int s : oversize_)
		for (int t = 0; t < shellTotal; ++t)
			if (t != s && (!isOversize_[t] || s < t)) compare(s, t);
	stats.shellPairs = static_cast<long>(hits_.size());
	std::sort(hits_.begin(), hits_.end());

	// One candidate per block pair, linking the union of its overlapping shells' sub-units.
	for (std::size_t h = 0; h < hits_.size();) {
		ShellHit merged = hits_[h];
		for (++h; h < hits_.size() && hits_[h].a == merged.a && hits_[h].b == merged.b; ++h) {
			merged.shellsA |= hits_[h].shellsA;
			merged.shellsB |= hits_[h].shellsB;
		}
		pairs.emplace_back(merged.a, merged.b);
		if (linkedCount_ == static_cast<int>(linked_.size())) linked_.emplace_back();
		LinkedSubUnits& out = linked_[linkedCount_++];
		const int block[2] = {merged.a, merged.b};
		const std::uint64_t shells[2] = {merged.shellsA, merged.shellsB};
		for (int i = 0; i < 2; ++i) {
			const BlockCover& cover = covers_[block[i]];
			collect(cover.vertexShells, shells[i], out.vertices[i]);
			collect(cover.edgeShells, shells[i], out.edges[i]);
			collect(cover.faceShells, shells[i], out.faces[i]);
		}
		stats.subUnitPairs += out.subUnitPairs();
	}
	stats.candidatePairs = static_cast<long>(pairs.size());
}

}  // namespace dda
