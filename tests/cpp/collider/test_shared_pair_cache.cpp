// The pair cache DESS and MSC share (PairCache.hpp), on its own: blocks of
// one to three boxes drift inside the skin, a few jump out of it, most jump
// at once, one is freed; every round the cached pairs whose d0-boxes meet
// must be exactly the pairs a brute-force search finds, in its order, with
// either growth policy, and the rounds must take each of the cache's paths
// (pairs reused, movers re-searched, full search).
#include "dda/collider/PairCache.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <random>
#include <vector>

using namespace dda;

namespace {

// Blocks of consecutive items (boxes); items widened by d0 and by D.
struct TestVolumes {
	std::vector<int> firstItem;  // per block, and one past the last
	std::vector<int> itemBlock;
	std::vector<Eigen::AlignedBox3d> tight;  // per item, not widened [m]
	std::vector<Eigen::AlignedBox3d> boxes;  // widened by d0 [m]
	const std::vector<Block>* blocks = nullptr;
	double skin = 0;  // D - d0 [m]
	long searches = 0;

	int count() const { return static_cast<int>(itemBlock.size()); }
	int first(int block) const { return firstItem[block]; }
	int end(int block) const { return firstItem[block + 1]; }
	int blockOf(int item) const { return itemBlock[item]; }
	const Eigen::AlignedBox3d& box(int item) const { return boxes[item]; }
	Eigen::AlignedBox3d searchBox(int item) const {
		Eigen::AlignedBox3d out = boxes[item];
		out.min().array() -= skin;
		out.max().array() += skin;
		return out;
	}
	long search(const std::vector<Eigen::AlignedBox3d>& searched, std::vector<ItemPair>& out, std::vector<ItemPair>&) {
		++searches;
		out = bruteForce(searched);
		return 0;
	}
	void sort(std::vector<ItemPair>& pairs, std::vector<ItemPair>&) const { std::sort(pairs.begin(), pairs.end()); }
	// Every item pair of different blocks, not both fixed, whose boxes meet, sorted.
	std::vector<ItemPair> bruteForce(const std::vector<Eigen::AlignedBox3d>& searched) const {
		std::vector<ItemPair> out;
		for (int s = 0; s < count(); ++s)
			for (int t = s + 1; t < count(); ++t) {
				const int a = itemBlock[s], b = itemBlock[t];
				if (a == b || ((*blocks)[a].fixed && (*blocks)[b].fixed)) continue;
				if (searched[s].intersects(searched[t])) out.emplace_back(s, t);
			}
		std::sort(out.begin(), out.end());
		return out;
	}
};

void runRounds(PairCache::Growth growth) {
	const int n = 60;
	const double d0 = 0.05;
	std::mt19937 rng(3);
	std::uniform_real_distribution<double> unit(0, 1);
	std::vector<Block> blocks(n);
	TestVolumes volumes;
	volumes.blocks = &blocks;
	volumes.skin = d0 * PairCache::kVerletSkinFactor;
	for (int b = 0; b < n; ++b) {
		blocks[b].fixed = b % 7 == 0;
		volumes.firstItem.push_back(volumes.count());
		const Vector3 centre(2.5 * unit(rng), 2.5 * unit(rng), 2.5 * unit(rng));
		for (int k = 0; k < 1 + b % 3; ++k) {
			const Vector3 low = centre + Vector3(0.3 * k, 0, 0);
			volumes.tight.emplace_back(low, low + Vector3(0.3, 0.2 + 0.2 * unit(rng), 0.3));
			volumes.itemBlock.push_back(b);
		}
	}
	volumes.firstItem.push_back(volumes.count());
	PairCache cache(growth);
	long reused = 0, partial = 0, full = 0;
	for (int round = 0; round < 14; ++round) {
		volumes.boxes.clear();
		for (const Eigen::AlignedBox3d& box : volumes.tight) {
			Eigen::AlignedBox3d widened = box;
			widened.min().array() -= d0;
			widened.max().array() += d0;
			volumes.boxes.push_back(widened);
		}
		BroadPhaseStatistics stats;
		cache.update(volumes, blocks, stats);
		std::vector<ItemPair> found;
		for (const ItemPair& p : cache.pairs())
			if (volumes.boxes[p.first].intersects(volumes.boxes[p.second])) found.push_back(p);
		ASSERT_EQ(found, volumes.bruteForce(volumes.boxes)) << "round " << round;
		reused += stats.broadPhaseSkipped && stats.blocksResearched == 0;
		partial += stats.broadPhaseSkipped && stats.blocksResearched > 0;
		full += stats.blocksResearched == n;
		// Free blocks drift by up to 0.3 d0 per coordinate; rounds 2, 5, 8:
		// every 5th jumps by up to 3 d0; round 10: most jump; round 12: one is freed.
		if (round == 12) blocks[7].fixed = false;
		for (int b = 0; b < n; ++b) {
			if (blocks[b].fixed || round == 0 || round == 3) continue;
			const bool jump = (round % 3 == 2 && b % 5 == 1) || (round == 10 && b % 4 != 0);
			const Vector3 shift = (jump ? 6.0 : 0.3) * d0 * Vector3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
			for (int s = volumes.first(b); s < volumes.end(b); ++s)
				volumes.tight[s] = Eigen::AlignedBox3d(volumes.tight[s].min() + shift, volumes.tight[s].max() + shift);
		}
	}
	EXPECT_GE(reused, 1);
	EXPECT_GE(partial, 3);
	EXPECT_GE(full, 3);  // the first call, round 10's and the freed block's
	EXPECT_EQ(volumes.searches, full);
}

}  // namespace

TEST(SharedPairCache, CachedPairsAreTheBruteForcePairsWithEitherGrowth) {
	runRounds(PairCache::Growth::Doubling);
	runRounds(PairCache::Growth::Eighths);
}

TEST(SharedPairCache, WithoutReuseTheCacheIsDropped) {
	PairCache cache(PairCache::Growth::Doubling);
	EXPECT_TRUE(cache.reuse());
	cache.setReuse(false);
	EXPECT_FALSE(cache.reuse());
	EXPECT_EQ(cache.memoryBytes(), 0u);
}
