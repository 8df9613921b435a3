// Effects on demand in the broad phase: work skipped must leave results
// unchanged. DESS's candidate-pair cache against a search without it and
// against AllPairs on every step (settling pile, a block arriving at a resting
// pile, a resting stack); fixed-fixed pairs never searched and MSC shells of
// fixed blocks built once. Counters, not timings. (The solver's effects are in
// solver/test_effects.cpp.)
#include "dda/collider/Collider.hpp"
#include "dda/collider/MSCCollider.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"

#include <gtest/gtest.h>

#include <memory>

using namespace dda;
using namespace dda::testing;

namespace {

const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();

// Every sub-contact of the two worlds' last steps: same identity, structural
// type, start-of-step geometry and end state, to the last bit.
void expectSameContacts(const World& a, const World& b, int step) {
	const std::vector<Contact>& ca = a.contacts();
	const std::vector<Contact>& cb = b.contacts();
	ASSERT_EQ(ca.size(), cb.size()) << "step " << step;
	for (std::size_t k = 0; k < ca.size(); ++k) {
		ASSERT_TRUE(ca[k].key == cb[k].key) << "step " << step << " contact " << k;
		EXPECT_EQ(ca[k].pairType, cb[k].pairType) << "step " << step;
		EXPECT_EQ(ca[k].geometry.gap, cb[k].geometry.gap) << "step " << step;
		EXPECT_EQ(ca[k].geometry.normal, cb[k].geometry.normal) << "step " << step;
		EXPECT_EQ(ca[k].geometry.pointI, cb[k].geometry.pointI) << "step " << step;
		EXPECT_EQ(ca[k].history.state, cb[k].history.state) << "step " << step;
		EXPECT_EQ(ca[k].history.normalForce, cb[k].history.normalForce) << "step " << step;
	}
}

struct CacheRun {
	long skipped = 0, researched = 0, reused = 0, steps = 0, arrivingContacts = 0;
};

// Steps a pile with DESS's cache, DESS without it and AllPairs in lockstep,
// comparing every step.
CacheRun compareWithFullSearch(int layers, double dropHeight, int steps) {
	World cached = cubePile(std::make_unique<DESSCollider>(), layers, dropHeight);
	World uncached = cubePile(std::make_unique<DESSCollider>(), layers, dropHeight);
	World oracle = cubePile(std::make_unique<AllPairsCollider>(), layers, dropHeight);
	const IntegratorSettings with = gravitySettings(true), without = gravitySettings(false);
	const int arriving = cached.blockCount() - 1;
	CacheRun run;
	for (int step = 0; step < steps; ++step) {
		cached.step(with);
		uncached.step(without);
		oracle.step(without);
		const StepStatistics& s = cached.lastStep();
		EXPECT_EQ(s.candidatePairs, uncached.lastStep().candidatePairs) << "step " << step;
		EXPECT_EQ(uncached.lastStep().broadPhaseSkipped, 0);
		expectSameContacts(cached, uncached, step);
		expectSameContacts(cached, oracle, step);
		if (::testing::Test::HasFailure()) return run;
		run.skipped += s.broadPhaseSkipped;
		run.researched += s.blocksResearched;
		run.reused += s.pairsReused;
		++run.steps;
		if (dropHeight > 0)
			for (const Contact& c : cached.contacts())
				run.arrivingContacts += c.key.blockI == arriving || c.key.blockJ == arriving;
	}
	for (int b = 0; b < cached.blockCount(); ++b)
		for (std::size_t v = 0; v < cached.block(b).vertices.size(); ++v)
			EXPECT_EQ(cached.block(b).vertices[v], oracle.block(b).vertices[v]) << "block " << b;
	return run;
}

}  // namespace

TEST(PairCache, SettlingPileHasTheFullSearchContactsEveryStep) {
	const CacheRun run = compareWithFullSearch(2, 0, 150);
	EXPECT_GT(run.skipped, 0);  // the cache was used while the pile settled
}

TEST(PairCache, NoticesABlockArrivingAtARestingPile) {
	// The cube falls 0.6 m (about 0.35 s) onto a settled pile of 8.
	const CacheRun run = compareWithFullSearch(2, 0.6, 300);
	EXPECT_GT(run.arrivingContacts, 0) << "the cube should have landed";
	EXPECT_GT(run.skipped, run.steps / 2);
	// While it falls the cube alone leaves its allowance: re-searched alone.
	EXPECT_LT(run.researched, run.steps * 9 / 4);
	EXPECT_GT(run.researched, 0);
}

TEST(PairCache, RestingStackIsNotSearchedAgain) {
	// Three cubes resting exactly on each other on a floor.
	const auto stack = [] {
		World world;
		Material rock;
		rock.frictionAngle = 0.5;
		world.addBlock(orientedBox(Vector3(0, 0, -0.5), Vector3(3, 3, 0.5), I3), rock, true);
		for (int k = 0; k < 3; ++k) world.addBlock(orientedBox(Vector3(0, 0, 0.5 + k), Vector3(0.5, 0.5, 0.5), I3), rock, false);
		return world;
	};
	World cached = stack(), uncached = stack();
	long skipped = 0, researched = 0, reused = 0;
	const int steps = 100;
	// As placed: settling (startFromRest) would make the first search before
	// the first step's.
	IntegratorSettings withCache = gravitySettings(true), withoutCache = gravitySettings(false);
	withCache.startFromRest = withoutCache.startFromRest = false;
	for (int step = 0; step < steps; ++step) {
		cached.step(withCache);
		uncached.step(withoutCache);
		expectSameContacts(cached, uncached, step);
		skipped += cached.lastStep().broadPhaseSkipped;
		researched += cached.lastStep().blocksResearched;
		reused += cached.lastStep().pairsReused;
	}
	EXPECT_EQ(skipped, steps - 1);      // one search, at the first step
	EXPECT_EQ(researched, 4);           // its 4 blocks
	EXPECT_EQ(reused, 3 * (steps - 1));  // floor-0, 0-1, 1-2
}

TEST(PairCache, DisabledOrDifferentCollidersReturnTheSamePairs) {
	// Moving the blocks of a random scene by random amounts, up to twice the
	// skin: the cached DESS returns exactly the pairs of a fresh DESS.
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> unit(-1, 1);
	std::vector<Block> blocks = blocksOf(randomScene(120, 5));
	const double d0 = 0.1;
	DESSCollider cached, fresh;
	fresh.setPairReuse(false);
	long skipped = 0, partial = 0;
	for (int round = 0; round < 40; ++round) {
		std::vector<std::pair<int, int>> a, b;
		BroadPhaseStatistics sa, sb;
		cached.findPairs(blocks, d0, a, sa);
		fresh.findPairs(blocks, d0, b, sb);
		ASSERT_EQ(a, b) << "round " << round;
		skipped += sa.broadPhaseSkipped;
		partial += sa.broadPhaseSkipped && sa.blocksResearched > 0;
		// A few blocks move by up to 2 x skin; the others by round-off.
		for (Block& block : blocks) {
			if (block.fixed) continue;
			const bool mover = unit(rng) > 0.9;
			const Vector3 shift = mover ? Vector3(Vector3(unit(rng), unit(rng), unit(rng)) * 2 * d0) : Vector3(Vector3::Constant(1e-12));
			for (Vector3& x : block.vertices) x += shift;
		}
	}
	EXPECT_GT(skipped, 10);
	EXPECT_GT(partial, 5);
}

TEST(FixedBlocks, FixedPairsNeverSearchedAndMscShellsBuiltOnce) {
	// 200 fixed cubes side by side (a 10 x 20 floor) and 2 falling ones.
	for (int strategy = 0; strategy < 4; ++strategy) {
		World world;
		std::unique_ptr<Collider> colliders[] = {std::make_unique<DESSCollider>(), std::make_unique<NBSCollider>(),
		                                         std::make_unique<AllPairsCollider>(), std::make_unique<MSCCollider>()};
		world.setCollider(std::move(colliders[strategy]));
		Material rock;
		for (int i = 0; i < 10; ++i)
			for (int j = 0; j < 20; ++j) world.addBlock(orientedBox(Vector3(i, j, -0.5), Vector3(0.5, 0.5, 0.5), I3), rock, true);
		world.addBlock(orientedBox(Vector3(4.3, 8.2, 0.53), Vector3(0.5, 0.5, 0.5), I3), rock, false);
		world.addBlock(orientedBox(Vector3(6.3, 12.2, 0.6), Vector3(0.5, 0.5, 0.5), I3), rock, false);
		IntegratorSettings settings = gravitySettings(true);
		settings.startFromRest = false;  // the first step builds the shells (not a settling step)
		long shellUpdatesAfterFirst = 0;
		for (int step = 0; step < 30; ++step) {
			world.step(settings);
			const StepStatistics& s = world.lastStep();
			EXPECT_EQ(s.fixedPairsSearched, 0) << world.collider().name();
			EXPECT_EQ(s.fixedBlocks, 200);
			// AllPairs: each moving cube with every block, none of the 19,900
			// fixed pairs; the others: the floor cubes near each (NBS's
			// spheres reach the 5 x 5 around it)
			if (strategy == 2) EXPECT_EQ(s.candidatePairs, 2 * 200 + 1);
			else EXPECT_LE(s.candidatePairs, 2 * 25) << world.collider().name();
			if (step > 0) shellUpdatesAfterFirst += s.shellUpdates;
			if (strategy == 3 && step == 0) EXPECT_EQ(s.shellUpdates, s.shells);
		}
		if (strategy == 3) EXPECT_EQ(shellUpdatesAfterFirst, 2 * 29);  // one shell per moving cube per step
	}
}
