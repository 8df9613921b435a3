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

// What the pair cache sees: one item per block, its box widened by d0, its
// D-box that box widened by the skin (which contains it exactly: x - skin <=
// x and x + skin >= x in floats, all the cache relies on), and the sweep.
struct DESSCollider::Volumes {
	DESSCollider& dess;
	const std::vector<Block>& blocks;
	double skin;
	int count() const { return static_cast<int>(blocks.size()); }
	int first(int block) const { return block; }
	int end(int block) const { return block + 1; }
	int blockOf(int item) const { return item; }
	const Eigen::AlignedBox3d& box(int item) const { return dess.boxes_[item]; }
	Eigen::AlignedBox3d searchBox(int item) const { return widened(dess.boxes_[item], skin); }
	long search(const std::vector<Eigen::AlignedBox3d>& boxes, std::vector<ItemPair>& out, std::vector<ItemPair>&) {
		return dess.sweep(blocks, boxes, out);
	}
	void sort(std::vector<ItemPair>& pairs, std::vector<ItemPair>&) const { std::sort(pairs.begin(), pairs.end()); }
};

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
	const double skin = margin * PairCache::kVerletSkinFactor;
	boxes_.resize(n);
	for (int b = 0; b < n; ++b) {
		Eigen::AlignedBox3d box;
		for (const Vector3& x : blocks[b].vertices) box.extend(x);
		boxes_[b] = widened(box, margin);
	}
	stats.shells = stats.shellUpdates = n;

	if (!cache_.reuse()) {
		stats.shellTests = sweep(blocks, boxes_, pairs);
		stats.blocksResearched = n;
	} else {
		Volumes volumes{*this, blocks, skin};
		cache_.update(volumes, blocks, stats);
		// The pairs a search without cache returns: those whose d0-boxes meet.
		pairs.clear();
		for (const auto& [a, b] : cache_.pairs())
			if (boxes_[a].intersects(boxes_[b])) pairs.emplace_back(a, b);
		stats.shellTests += static_cast<long>(cache_.pairs().size());
	}
	stats.candidatePairs = stats.shellPairs = static_cast<long>(pairs.size());
	for (auto [a, b] : pairs) stats.subUnitPairs += allSubUnitPairs(*blocks[a].shape, *blocks[b].shape);
}

}  // namespace dda
