// Broad phases against the all-pairs oracle: on random scenes of slender,
// slanted, touching, fixed and free blocks, every collider proposes every pair
// whose narrow phase finds a contact, so all of them end with exactly the
// contact set of AllPairsCollider.
#include "dda/collider/Collider.hpp"
#include "dda/collider/ColliderFactory.hpp"
#include "dda/collider/MSCCollider.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <memory>
#include <random>
#include <set>
#include <tuple>

using namespace dda;
using namespace dda::testing;

namespace {

// The contact set (TestScenes.hpp), with the candidate count.
ContactSet contactSet(Collider& collider, const std::vector<Block>& blocks, double d0, long* candidates) {
	BroadPhaseStatistics stats;
	ContactSet out = dda::testing::contactSet(collider, blocks, d0, &stats);
	*candidates = stats.candidatePairs;
	return out;
}

}  // namespace

TEST(Colliders, EveryStrategyFindsTheAllPairsContactSet) {
	for (unsigned seed : {1u, 2u, 3u}) {
		const std::vector<Block> blocks = blocksOf(randomScene(120, seed));
		for (double d0 : {0.0, 0.05, 0.5}) {
			AllPairsCollider all;
			long allCandidates = 0;
			const ContactSet reference = contactSet(all, blocks, d0, &allCandidates);
			ASSERT_GT(reference.size(), 10u) << "the scene should have contacts";
			DESSCollider dess;
			NBSCollider nbs;
			long dessCandidates = 0, nbsCandidates = 0;
			EXPECT_TRUE(contactSet(dess, blocks, d0, &dessCandidates) == reference) << "seed " << seed << " d0 " << d0;
			const ContactSet fromNbs = contactSet(nbs, blocks, d0, &nbsCandidates);
			EXPECT_TRUE(fromNbs == reference) << "seed " << seed << " d0 " << d0;
			for (const auto& c : reference)
				if (!fromNbs.count(c)) ADD_FAILURE() << "NBS misses " << std::get<0>(c) << "-" << std::get<1>(c);
			for (const auto& c : fromNbs)
				if (!reference.count(c)) ADD_FAILURE() << "NBS adds " << std::get<0>(c) << "-" << std::get<1>(c);
			// The point of a broad phase: fewer candidates than all pairs (NBS
			// is poor with 15 m blocks among 1 m ones: its cells are 15 m wide).
			EXPECT_LT(dessCandidates, allCandidates / 2);
			EXPECT_LE(nbsCandidates, allCandidates);
		}
	}
}

TEST(Colliders, FixedPairsAreNeverProposed) {
	World world;
	Material material;
	const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
	world.addBlock(orientedBox(Vector3(0, 0, 0), Vector3(0.5, 0.5, 0.5), I), material, true);
	world.addBlock(orientedBox(Vector3(1, 0, 0), Vector3(0.5, 0.5, 0.5), I), material, true);
	world.addBlock(orientedBox(Vector3(0, 1, 0), Vector3(0.5, 0.5, 0.5), I), material, false);
	const std::vector<Block> blocks = blocksOf(world);
	std::unique_ptr<Collider> colliders[] = {std::make_unique<AllPairsCollider>(), std::make_unique<DESSCollider>(),
	                                         std::make_unique<NBSCollider>(), std::make_unique<MSCCollider>()};
	for (auto& collider : colliders) {
		std::vector<std::pair<int, int>> pairs;
		BroadPhaseStatistics stats;
		collider->findPairs(blocks, 0.1, pairs, stats);
		const std::vector<std::pair<int, int>> expected{{0, 2}, {1, 2}};
		EXPECT_EQ(pairs, expected) << collider->name();
	}
}

TEST(Colliders, EveryColliderIsMadeByItsName) {
	ASSERT_EQ(colliderNames(), (std::vector<std::string>{"DESS", "NBS", "AllPairs", "MSC"}));
	for (const std::string& name : colliderNames()) EXPECT_EQ(makeCollider(name)->name(), name);
	EXPECT_EQ(makeCollider("Octree"), nullptr);
	EXPECT_EQ(colliderList(), "DESS, NBS, AllPairs, MSC");
}
