#include "Collider.hpp"

namespace dda {

void AllPairsCollider::findPairs(const std::vector<Block>& blocks, double, std::vector<std::pair<int, int>>& pairs,
                                 BroadPhaseStatistics& stats) {
	pairs.clear();
	const int n = static_cast<int>(blocks.size());
	for (int a = 0; a < n; ++a)
		for (int b = a + 1; b < n; ++b)
			if (!(blocks[a].fixed && blocks[b].fixed)) pairs.emplace_back(a, b);
	stats = BroadPhaseStatistics{};
	stats.candidatePairs = static_cast<long>(pairs.size());
	for (auto [a, b] : pairs) stats.subUnitPairs += allSubUnitPairs(*blocks[a].shape, *blocks[b].shape);
}

}  // namespace dda
