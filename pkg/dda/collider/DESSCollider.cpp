#include "Collider.hpp"

#include <algorithm>

namespace dda {

void DESSCollider::findPairs(const std::vector<Block>& blocks, double contactDistance,
                             std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) {
	pairs.clear();
	const int n = static_cast<int>(blocks.size());
	boxes_.resize(n);
	Eigen::AlignedBox3d all;
	const Vector3 margin = Vector3::Constant(kBroadPhaseMarginFactor * contactDistance);
	for (int b = 0; b < n; ++b) {
		Eigen::AlignedBox3d box;
		for (const Vector3& x : blocks[b].vertices) box.extend(x);
		box.min() -= margin;
		box.max() += margin;
		boxes_[b] = box;
		all.extend(box.center());
	}
	stats = BroadPhaseStatistics{};
	stats.shells = stats.shellUpdates = n;
	if (n < 2) return;
	int axis;
	all.sizes().maxCoeff(&axis);
	order_.resize(n);
	for (int b = 0; b < n; ++b) order_[b] = b;
	std::sort(order_.begin(), order_.end(), [&](int a, int b) {
		const double ma = boxes_[a].min()(axis), mb = boxes_[b].min()(axis);
		return ma < mb || (ma == mb && a < b);
	});
	long tested = 0;
	for (int p = 0; p < n; ++p) {
		const int a = order_[p];
		const Eigen::AlignedBox3d& boxA = boxes_[a];
		for (int q = p + 1; q < n; ++q) {
			const int b = order_[q];
			if (boxes_[b].min()(axis) > boxA.max()(axis)) break;
			if (blocks[a].fixed && blocks[b].fixed) continue;
			++tested;
			if (boxA.intersects(boxes_[b])) pairs.emplace_back(std::min(a, b), std::max(a, b));
		}
	}
	std::sort(pairs.begin(), pairs.end());
	stats.candidatePairs = stats.shellPairs = static_cast<long>(pairs.size());
	stats.shellTests = tested;
	for (auto [a, b] : pairs) stats.subUnitPairs += allSubUnitPairs(*blocks[a].shape, *blocks[b].shape);
}

}  // namespace dda
