#include "Collider.hpp"

#include <algorithm>
#include <cmath>

namespace dda {

namespace {

// 21 bits per axis; cells are offset so that indices are non-negative.
std::uint64_t cellKey(std::int64_t x, std::int64_t y, std::int64_t z) {
	const std::uint64_t mask = (1u << 21) - 1;
	return (static_cast<std::uint64_t>(x) & mask) << 42 | (static_cast<std::uint64_t>(y) & mask) << 21 |
	       (static_cast<std::uint64_t>(z) & mask);
}

}  // namespace

void NBSCollider::findPairs(const std::vector<Block>& blocks, double contactDistance,
                           std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) {
	pairs.clear();
	stats = BroadPhaseStatistics{};
	const int n = static_cast<int>(blocks.size());
	stats.shells = stats.shellUpdates = n;
	if (n < 2) return;
	centres_.resize(n);
	radii_.resize(n);
	double largest = 0;
	Eigen::AlignedBox3d domain;
	for (int b = 0; b < n; ++b) {
		Eigen::AlignedBox3d box;
		for (const Vector3& x : blocks[b].vertices) box.extend(x);
		centres_[b] = box.center();
		double r2 = 0;
		for (const Vector3& x : blocks[b].vertices) r2 = std::max(r2, (x - centres_[b]).squaredNorm());
		// Inflated by 1e-9 relative: spheres of blocks that touch exactly (corner
		// on corner, d0 = 0) touch exactly too, and the rounding of the square
		// root and of the squared distance must not part them.
		radii_[b] = std::sqrt(r2) * (1 + 1e-9) + kBroadPhaseMarginFactor * contactDistance;
		largest = std::max(largest, radii_[b]);
		domain.extend(centres_[b]);
	}
	// Cells at least one diameter wide, and few enough per axis for the key.
	const double cell = std::max(2 * largest, domain.sizes().maxCoeff() / ((1 << 20) - 2));
	cellOf_.resize(n);
	std::vector<std::array<std::int64_t, 3>> index(n);
	for (int b = 0; b < n; ++b) {
		for (int k = 0; k < 3; ++k)
			index[b][k] = static_cast<std::int64_t>(std::floor((centres_[b](k) - domain.min()(k)) / cell)) + 1;
		cellOf_[b] = {cellKey(index[b][0], index[b][1], index[b][2]), b};
	}
	std::sort(cellOf_.begin(), cellOf_.end());
	long tested = 0;
	for (int a = 0; a < n; ++a) {
		for (int dx = -1; dx <= 1; ++dx)
			for (int dy = -1; dy <= 1; ++dy)
				for (int dz = -1; dz <= 1; ++dz) {
					const std::uint64_t key = cellKey(index[a][0] + dx, index[a][1] + dy, index[a][2] + dz);
					auto it = std::lower_bound(cellOf_.begin(), cellOf_.end(), std::make_pair(key, 0));
					for (; it != cellOf_.end() && it->first == key; ++it) {
						const int b = it->second;
						if (b <= a || (blocks[a].fixed && blocks[b].fixed)) continue;
						++tested;
						const double reach = radii_[a] + radii_[b];
						if ((centres_[a] - centres_[b]).squaredNorm() <= reach * reach) pairs.emplace_back(a, b);
					}
				}
	}
	std::sort(pairs.begin(), pairs.end());
	stats.candidatePairs = stats.shellPairs = static_cast<long>(pairs.size());
	stats.shellTests = tested;
	for (auto [a, b] : pairs) stats.subUnitPairs += allSubUnitPairs(*blocks[a].shape, *blocks[b].shape);
}

}  // namespace dda
