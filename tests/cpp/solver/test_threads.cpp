// World::step on 1 and 2 threads gives bitwise the same world: every block,
// every contact in store order with its history, the entrances, the energy
// account and the step's counters. The scene is large enough for every threaded loop of the
// step to run threaded (kMinBlocksForThreads blocks, pairs and MSC's frame
// tests; kMinContactsForThreads contacts), so a loop whose result depended on
// how its items were split, or on the order threads finish, shows here; a
// smaller one runs the narrow phase alone threaded (kMinPairsForThreads).
#include "TestScenes.hpp"
#include "dda/collider/ColliderFactory.hpp"
#include "dda/core/StateStream.hpp"
#include "dda/solver/StepClock.hpp"

#include <gtest/gtest.h>

#include <string>

namespace dda::testing {
namespace {

// Stacks of two slender boxes (6:1:1, three MSC shells each), the upper one
// across the lower, 0.5 mm apart and turned a little at random (seeded), on
// a fixed floor, the stacks apart: they land with friction, some sliding
// sideways, as components of two blocks (a pile of touching blocks would be
// one component, whose solve takes minutes). A third of the stacks have bond
// strength (their pairs' contact areas are computed).
World crossedStacks(const std::string& collider, int stacks) {
	std::mt19937 rng(21);
	std::uniform_real_distribution<double> tilt(-0.01, 0.01);
	World world;
	Material rock;
	rock.young = 1e8;
	rock.frictionAngle = 0.5;
	Material bonded = rock;
	bonded.cohesion = 1e4;
	bonded.tensileStrength = 1e4;
	const int perRow = 28;
	const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
	const Eigen::Matrix3d across = Eigen::AngleAxisd(0.5 * M_PI, Vector3::UnitZ()).toRotationMatrix();
	world.addBlock(orientedBox(Vector3(21, 21, -0.5), Vector3(23, 23, 0.5), I), rock, true);
	for (int k = 0; k < stacks; ++k) {
		const Vector3 centre(1.5 * (k % perRow), 1.5 * (k / perRow), 0.1005);
		for (int level = 0; level < 2; ++level) {
			const Eigen::Matrix3d R = (Eigen::AngleAxisd(tilt(rng), Vector3::UnitX()) *
			                           Eigen::AngleAxisd(tilt(rng), Vector3::UnitY()) *
			                           Eigen::AngleAxisd(tilt(rng), Vector3::UnitZ()))
			                              .toRotationMatrix() *
			                          (level ? across : I);
			const int b = world.addBlock(orientedBox(centre + Vector3(0, 0, 0.2005 * level), Vector3(0.6, 0.1, 0.1), R),
			                             k % 3 ? rock : bonded, false);
			world.setVelocity(b, Vector3(0.02 * (k % 4) * level, 0, -0.05), Vector3::Zero());
		}
	}
	world.setCollider(makeCollider(collider));
	return world;
}

IntegratorSettings settingsFor(int threads) {
	IntegratorSettings s;
	s.gravity = Vector3(0, 0, -9.81);
	s.maxDisplacement = 0.002;
	s.threads = threads;
	return s;
}

// The world's saved state without the last step's statistics (they hold
// wall times): counters, time and next dt, then everything from the blocks on.
std::string physicsOf(const World& world) {
	StateWriter out;
	world.writeState(out);
	const std::string state = out.bytes();
	return state.substr(0, 60) + state.substr(state.find("BLKS"));
}

void expectSameCounters(const StepStatistics& one, const StepStatistics& two, int step) {
	EXPECT_EQ(one.candidatePairs, two.candidatePairs) << "step " << step;
	EXPECT_EQ(one.contactPairs, two.contactPairs) << "step " << step;
	EXPECT_EQ(one.contacts, two.contacts) << "step " << step;
	EXPECT_EQ(one.frictionContacts, two.frictionContacts) << "step " << step;
	EXPECT_EQ(one.closedContacts, two.closedContacts) << "step " << step;
	EXPECT_EQ(one.subUnitTests, two.subUnitTests) << "step " << step;
	EXPECT_EQ(one.fullSearchPairs, two.fullSearchPairs) << "step " << step;
	EXPECT_EQ(one.shellPairs, two.shellPairs) << "step " << step;
	EXPECT_EQ(one.shellTests, two.shellTests) << "step " << step;
	EXPECT_EQ(one.subUnitPairs, two.subUnitPairs) << "step " << step;
	EXPECT_EQ(one.blocksResearched, two.blocksResearched) << "step " << step;
}

// Steps the scene on 1 and on 2 threads side by side, comparing after each
// step. `stacks` 700: every threaded loop runs threaded; 200: the narrow
// phase alone (kMinPairsForThreads pairs, fewer than kMinBlocksForThreads
// blocks and kMinContactsForThreads contacts), a small dense scene's case.
void expectTwoThreadsStepAsOne(const std::string& collider, int stacks = 700) {
	World one = crossedStacks(collider, stacks);
	World two = crossedStacks(collider, stacks);
	long bondedContacts = 0;
	for (int step = 1; step <= 12; ++step) {
		one.step(settingsFor(1));
		two.step(settingsFor(2));
		const StepStatistics& s = one.lastStep();
		ASSERT_GE(s.candidatePairs, kMinPairsForThreads) << "the narrow phase would run on one thread";
		if (stacks >= 700) {
			ASSERT_GE(s.candidatePairs, kMinBlocksForThreads);
			ASSERT_GE(s.contacts, kMinContactsForThreads) << "the per-contact loops would run on one thread";
		} else {
			ASSERT_LT(one.blockCount(), kMinBlocksForThreads) << "meant as a small scene";
		}
		expectSameCounters(s, two.lastStep(), step);
		ASSERT_TRUE(physicsOf(one) == physicsOf(two)) << collider << ": 2 threads differ from 1 at step " << step;
		const EnergyAccount energyOne = one.energy(), energyTwo = two.energy();
		for (auto term : {&EnergyAccount::contact, &EnergyAccount::friction, &EnergyAccount::damping,
		                  &EnergyAccount::contactChanges, &EnergyAccount::kinetic})
			EXPECT_EQ(energyOne.*term, energyTwo.*term) << "step " << step;
		bondedContacts += s.bondedContacts;
	}
	EXPECT_GT(bondedContacts, 0);
}

}  // namespace

TEST(ThreadCount, MSCStepsBitwiseAsOnOneThread) { expectTwoThreadsStepAsOne("MSC"); }

TEST(ThreadCount, DESSStepsBitwiseAsOnOneThread) { expectTwoThreadsStepAsOne("DESS"); }

TEST(ThreadCount, SmallSceneNarrowPhaseBitwiseAsOnOneThread) { expectTwoThreadsStepAsOne("MSC", 200); }

}  // namespace dda::testing
