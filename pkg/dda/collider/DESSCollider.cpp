#include "Collider.hpp"

#include <algorithm>
#include <cmath>

namespace dda {

namespace {
Eigen::AlignedBox3d widened(const Eigen::AlignedBox3d& box, double margin) {
	Eigen::AlignedBox3d out = box;
	out.min().array() -= margin;
	out.max().array() += margin;
	return out;
}
}  // namespace

void DESSCollider::setPairReuse(bool reuse) {
	reuse_ = reuse;
	if (!reuse) cacheValid_ = false;
}

long DESSCollider::sweep(const std::vector<Block>& blocks, const std::vector<Eigen::AlignedBox3d>& boxes,
                         std::vector<std::pair<int, int>>& pairs) {
	pairs.clear();
	const int n = static_cast<int>(blocks.size());
	if (n < 2) return 0;
	Eigen::AlignedBox3d all;
	for (const Eigen::AlignedBox3d& box : boxes) all.extend(box.center());
	int axis;
	all.sizes().maxCoeff(&axis);
	order_.resize(n);
	for (int b = 0; b < n; ++b) order_[b] = b;
	fixed_.resize(n);  // the flags in one compact array (blocks are large and far apart)
	for (int b = 0; b < n; ++b) fixed_[b] = blocks[b].fixed;
	std::sort(order_.begin(), order_.end(), [&](int a, int b) {
		const double ma = boxes[a].min()(axis), mb = boxes[b].min()(axis);
		return ma < mb || (ma == mb && a < b);
	});
	long tested = 0;
	for (int p = 0; p < n; ++p) {
		const int a = order_[p];
		const Eigen::AlignedBox3d& boxA = boxes[a];
		for (int q = p + 1; q < n; ++q) {
			const int b = order_[q];
			if (boxes[b].min()(axis) > boxA.max()(axis)) break;
			if (fixed_[a] && fixed_[b]) continue;
			++tested;
			if (boxA.intersects(boxes[b])) pairs.emplace_back(std::min(a, b), std::max(a, b));
		}
	}
	std::sort(pairs.begin(), pairs.end());
	return tested;
}

void DESSCollider::findPairs(const std::vector<Block>& blocks, double contactDistance,
                             std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) {
	stats = BroadPhaseStatistics{};
	const int n = static_cast<int>(blocks.size());
	const double margin = kBroadPhaseMarginFactor * contactDistance;
	// A D-box is the d0-box widened by the skin: it contains the d0-box
	// exactly (x - skin <= x and x + skin >= x in floats), which is all the
	// cache relies on.
	const double skin = margin * kVerletSkinFactor;
	boxes_.resize(n);
	for (int b = 0; b < n; ++b) {
		Eigen::AlignedBox3d box;
		for (const Vector3& x : blocks[b].vertices) box.extend(x);
		boxes_[b] = widened(box, margin);
	}
	stats.shells = stats.shellUpdates = n;

	if (!reuse_) {
		cacheValid_ = false;
		stats.shellTests = sweep(blocks, boxes_, pairs);
		stats.blocksResearched = n;
	} else {
		// Blocks whose d0-box left the D-box of their last search. The test is
		// on the same floats the final filter uses: boxes inside their D-boxes
		// that meet imply D-boxes that meet, with no round-off argument needed.
		bool full = !cacheValid_ || static_cast<int>(searchedBoxes_.size()) != n;
		movers_.clear();
		moved_.assign(n, 0);
		for (int b = 0; b < n && !full; ++b) {
			if (static_cast<char>(blocks[b].fixed) != searchedFixed_[b]) full = true;
			else if (!searchedBoxes_[b].contains(boxes_[b])) {
				movers_.push_back(b);
				moved_[b] = 1;
			}
		}
		const double partialLimit = kVerletPartialFactor * std::log2(std::max(2, n));
		if (!full && static_cast<double>(movers_.size()) > partialLimit) full = true;
		if (full) {
			searchedBoxes_.resize(n);
			searchedFixed_.resize(n);
			for (int b = 0; b < n; ++b) {
				searchedBoxes_[b] = widened(boxes_[b], skin);
				searchedFixed_[b] = blocks[b].fixed;
			}
			stats.shellTests = sweep(blocks, searchedBoxes_, cached_);
			stats.blocksResearched = n;
			cacheValid_ = true;
		} else {
			stats.broadPhaseSkipped = 1;
			stats.blocksResearched = static_cast<long>(movers_.size());
			if (!movers_.empty()) {
				// Each mover gets a new D-box and is compared with every block.
				for (int m : movers_) searchedBoxes_[m] = widened(boxes_[m], skin);
				kept_.clear();
				for (const auto& pair : cached_)
					if (!moved_[pair.first] && !moved_[pair.second]) kept_.push_back(pair);
				stats.pairsReused = static_cast<long>(kept_.size());
				for (int m : movers_)
					for (int b = 0; b < n; ++b) {
						if (b == m || (moved_[b] && b < m) || (blocks[b].fixed && blocks[m].fixed)) continue;
						++stats.shellTests;
						if (searchedBoxes_[m].intersects(searchedBoxes_[b])) kept_.emplace_back(std::min(m, b), std::max(m, b));
					}
				std::sort(kept_.begin(), kept_.end());
				cached_.swap(kept_);
			} else {
				stats.pairsReused = static_cast<long>(cached_.size());
			}
		}
		// The pairs a search without cache returns: those whose d0-boxes meet.
		pairs.clear();
		for (const auto& [a, b] : cached_)
			if (boxes_[a].intersects(boxes_[b])) pairs.emplace_back(a, b);
		stats.shellTests += static_cast<long>(cached_.size());
	}
	stats.candidatePairs = stats.shellPairs = static_cast<long>(pairs.size());
	for (auto [a, b] : pairs) stats.subUnitPairs += allSubUnitPairs(*blocks[a].shape, *blocks[b].shape);
}

}  // namespace dda
