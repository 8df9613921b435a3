// Effects on demand: work skipped must leave results unchanged. DESS's
// candidate-pair cache against a search without it and against AllPairs on
// every step (settling pile, a block arriving at a resting pile, a resting
// stack); fixed-fixed pairs never searched and MSC shells of fixed blocks
// built once; no friction terms without friction, no body force without
// gravity, static analysis (velocityRatio = 0); no stored system for blocks
// without springs; sparse analyses and contact terms kept between solves.
// Counters, not timings.
#include "dda/collider/Collider.hpp"
#include "dda/collider/MSCCollider.hpp"
#include "dda/solver/CoupledSystem.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

using namespace dda;
using namespace dda::testing;

namespace {

const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();

// A fixed floor and 2 x 2 x `layers` unit cubes, slightly turned, 5 cm
// apart, dropped from a few cm; optionally one more cube `dropHeight` [m]
// above the pile (it arrives while the pile rests).
World pile(std::unique_ptr<Collider> collider, int layers, double dropHeight, double frictionDeg = 30) {
	World world;
	world.setCollider(std::move(collider));
	Material rock;
	rock.frictionAngle = frictionDeg * M_PI / 180;
	world.addBlock(orientedBox(Vector3(0, 0, -0.5), Vector3(3, 3, 0.5), I3), rock, true);
	std::mt19937 rng(7);
	std::uniform_real_distribution<double> tilt(-0.03, 0.03);
	for (int layer = 0; layer < layers; ++layer)
		for (int k = 0; k < 4; ++k) {
			const Eigen::Matrix3d R = Eigen::AngleAxisd(tilt(rng), Vector3::UnitZ()).toRotationMatrix() *
			                          Eigen::AngleAxisd(tilt(rng), Vector3::UnitX()).toRotationMatrix();
			const Vector3 centre(-0.55 + 1.1 * (k % 2), -0.55 + 1.1 * (k / 2), 0.55 + 1.08 * layer);
			world.addBlock(orientedBox(centre, Vector3(0.5, 0.5, 0.5), R), rock, false);
		}
	if (dropHeight > 0)
		world.addBlock(orientedBox(Vector3(-0.3, -0.2, 0.55 + 1.08 * layers + dropHeight), Vector3(0.5, 0.5, 0.5), I3),
		               rock, false);
	return world;
}

IntegratorSettings gravitySettings(bool reuse) {
	IntegratorSettings settings;
	settings.gravity = Vector3(0, 0, -9.81);
	settings.maxTimeStep = 2e-3;
	settings.reuseCandidatePairs = reuse;
	return settings;
}

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
	World cached = pile(std::make_unique<DESSCollider>(), layers, dropHeight);
	World uncached = pile(std::make_unique<DESSCollider>(), layers, dropHeight);
	World oracle = pile(std::make_unique<AllPairsCollider>(), layers, dropHeight);
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

namespace {
// A unit cube on a fixed floor, launched along x at 1 m/s.
World launchedCube(double frictionDeg) {
	World world;
	Material rock;
	rock.frictionAngle = frictionDeg * M_PI / 180;
	world.addBlock(orientedBox(Vector3(0, 0, -0.5), Vector3(10, 3, 0.5), I3), rock, true);
	world.addBlock(orientedBox(Vector3(0, 0, 0.5), Vector3(0.5, 0.5, 0.5), I3), rock, false);
	world.setVelocity(1, Vector3(1, 0, 0), Vector3::Zero());
	return world;
}
}  // namespace

TEST(Effects, FrictionlessContactsAssembleNoFrictionTerms) {
	World frictionless = launchedCube(0), rough = launchedCube(20);
	const IntegratorSettings settings = gravitySettings(true);
	long frictionTerms = 0, normalTerms = 0, roughFrictionTerms = 0;
	for (int step = 0; step < 100; ++step) {
		frictionless.step(settings);
		rough.step(settings);
		frictionTerms += frictionless.lastStep().frictionTerms;
		normalTerms += frictionless.lastStep().normalTerms;
		EXPECT_EQ(frictionless.lastStep().frictionContacts, 0);
		roughFrictionTerms += rough.lastStep().frictionTerms;
	}
	EXPECT_EQ(frictionTerms, 0);
	EXPECT_GT(normalTerms, 0);
	EXPECT_GT(roughFrictionTerms, 0);
	// Without friction the horizontal speed is kept (closed form: 1 m/s);
	// with it the cube decelerates by g tan(phi).
	EXPECT_NEAR(frictionless.block(1).velocity.x(), 1.0, 1e-6);
	EXPECT_LT(rough.block(1).velocity.x(), 1.0 - 0.5 * 9.81 * std::tan(20 * M_PI / 180) * frictionless.time());
}

TEST(Effects, NoBodyForceWithoutGravityAndStaticAnalysis) {
	World world;
	Material rock;
	world.addBlock(orientedBox(Vector3(0, 0, 0), Vector3(0.5, 0.5, 0.5), I3), rock, false);
	world.setVelocity(0, Vector3(0.5, 0, 0), Vector3::Zero());
	IntegratorSettings settings;
	settings.maxTimeStep = 1e-2;
	for (int step = 0; step < 10; ++step) {
		world.step(settings);
		EXPECT_EQ(world.lastStep().bodyForceBlocks, 0);
		EXPECT_FALSE(world.lastStep().staticAnalysis);
	}
	// constant velocity (closed form x = v t)
	EXPECT_NEAR(world.block(0).centroid.x(), 0.5 * world.time(), 1e-12);
	settings.gravity = Vector3(0, 0, -9.81);
	world.step(settings);
	EXPECT_EQ(world.lastStep().bodyForceBlocks, 1 + world.lastStep().stepCuts);
	// Static analysis: velocities do not carry over, an unloaded block stays put.
	settings.gravity.setZero();
	settings.velocityRatio = 0;
	const Vector3 before = world.block(0).centroid;
	world.step(settings);
	EXPECT_TRUE(world.lastStep().staticAnalysis);
	EXPECT_EQ(world.block(0).centroid, before);
}

TEST(Effects, FreeBlocksKeepNoStoredSystem) {
	// A block without closed contacts or fixed points is solved alone, from a
	// system assembled where it is solved: the solver keeps a solution and a
	// motion for it, no 12x12 block (before, it kept two: its own system and
	// the coupled system's copy).
	World world;
	Material rock;
	const int blocks = 50;
	for (int k = 0; k < blocks; ++k) world.addBlock(orientedBox(Vector3(3.0 * k, 0, 0), Vector3(0.5, 0.5, 0.5), I3), rock, false);
	IntegratorSettings settings;
	settings.maxTimeStep = 1e-3;
	settings.gravity = Vector3(0, 0, -9.81);
	world.step(settings);
	EXPECT_EQ(world.lastStep().components, blocks);
	EXPECT_EQ(world.lastStep().solvedUnknowns, blocks * kBlockDofs);
	const std::size_t solver = world.memoryUse().solver;
	EXPECT_GE(solver, blocks * (sizeof(Vector12) + sizeof(BlockMotion)));
	EXPECT_LT(solver, blocks * sizeof(Matrix12));
	// Free fall (closed form z = -g t^2 / 2).
	EXPECT_NEAR(world.block(0).centroid.z(), -0.5 * 9.81 * world.time() * world.time(), 1e-12);
}

// The coupled system keeps each sparse component's analysis (AMD ordering,
// elimination tree, value map) per pattern and refactorises only the values
// (CoupledSystem.hpp): the solutions must be bitwise those of a fresh
// analysis. Random SPD block systems: components of several patterns, equal
// patterns in one build (each gets its own analysis), structures swapped back
// and forth (A, B, A: A's analysis is kept), rigid members (6 unknowns).
TEST(Effects, SparseAnalysisReuseGivesBitwiseTheFreshSolutions) {
	std::mt19937 rng(17);
	std::uniform_real_distribution<double> u(-1, 1);
	const int blocks = 14;
	std::vector<int> unknowns(blocks, kBlockDofs);
	unknowns[3] = unknowns[9] = kRigidBlockDofs;
	// Structure A: a chain 0-4, a triangle 5-7 and two equal pairs 8-9, 10-11
	// (block 9 rigid, so 10-11 differs), 12-13 like 10-11; B: one ring of all.
	std::vector<std::pair<int, int>> A = {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {5, 6}, {6, 7}, {5, 7},
	                                      {8, 9}, {10, 11}, {12, 13}};
	std::vector<std::pair<int, int>> B;
	for (int k = 0; k < blocks; ++k) B.emplace_back(k, (k + 1) % blocks);
	B.emplace_back(0, 7);
	const std::vector<char> springs(blocks, 1);
	CoupledSystem reused, fresh;
	fresh.setAnalysisReuse(false);
	std::vector<int> systemOf(blocks);
	for (int k = 0; k < blocks; ++k) systemOf[k] = k;
	long reusedCount = 0;
	for (int solve = 0; solve < 12; ++solve) {
		const std::vector<std::pair<int, int>>& links = (solve / 3) % 2 ? B : A;
		if (solve % 3 == 0) {
			reused.build(blocks, links, springs, unknowns);
			fresh.build(blocks, links, springs, unknowns);
		}
		std::vector<BlockSystem> own(blocks);
		for (BlockSystem& b : own) {
			Matrix12 R;
			for (int i = 0; i < 144; ++i) R(i / 12, i % 12) = u(rng);
			b.stiffness = R * R.transpose() + 40 * Matrix12::Identity();
			for (int i = 0; i < 12; ++i) b.force(i) = u(rng);
		}
		reused.reset(own, systemOf);
		fresh.reset(own, systemOf);
		for (auto [a, b] : links) {
			Matrix12 m;
			for (int i = 0; i < 144; ++i) m(i / 12, i % 12) = 0.5 * u(rng);
			bool transposed;
			reused.offDiagonal(a, b, transposed) = m;
			fresh.offDiagonal(a, b, transposed) = m;
		}
		std::vector<Vector12> x(blocks, Vector12::Zero()), y(blocks, Vector12::Zero());
		reused.solve(x, 1 << 30);
		fresh.solve(y, 1 << 30);
		for (int k = 0; k < blocks; ++k) EXPECT_EQ(x[k], y[k]) << "solve " << solve << " block " << k;
		EXPECT_EQ(reused.solvedUnknowns(), fresh.solvedUnknowns());
		EXPECT_EQ(fresh.reusedAnalyses(), 0);
		reusedCount += reused.reusedAnalyses();
		if (solve % 3 == 0 && solve >= 6)
			EXPECT_EQ(reused.newAnalyses(), 0) << "solve " << solve << ": the swapped-back structure is kept";
	}
	// 36 sparse solves (A: 5 components x 6 solves, B: 1 x 6), of which only
	// the first of A's and of B's 6 analyses were new.
	EXPECT_EQ(reusedCount, 30);
}

namespace {
// Steps two copies of a pile, one with and one without the work the solver
// keeps between solves, and compares every step bitwise (vertices,
// velocities and the iteration's counts).
void expectSolverReuseBitwise(int layers, const IntegratorSettings& settings, int steps) {
	World reused = pile(std::make_unique<DESSCollider>(), layers, 0.3);
	World fresh = pile(std::make_unique<DESSCollider>(), layers, 0.3);
	fresh.setSolverReuse(false);
	int coupledSteps = 0, laterSolves = 0, searches = 0;
	for (int step = 0; step < steps; ++step) {
		reused.step(settings);
		fresh.step(settings);
		const StepStatistics &a = reused.lastStep(), &b = fresh.lastStep();
		ASSERT_EQ(a.openCloseIterationsTotal, b.openCloseIterationsTotal) << "step " << step;
		ASSERT_EQ(a.stepCuts, b.stepCuts) << "step " << step;
		ASSERT_EQ(a.lineSearches, b.lineSearches) << "step " << step;
		coupledSteps += a.largestComponent > 1;
		laterSolves += a.openCloseIterationsTotal - (a.stepCuts + 1);
		searches += a.lineSearches;
		for (int k = 0; k < reused.blockCount(); ++k) {
			ASSERT_EQ(reused.block(k).velocity, fresh.block(k).velocity) << "step " << step << " block " << k;
			for (std::size_t v = 0; v < reused.block(k).vertices.size(); ++v)
				ASSERT_EQ(reused.block(k).vertices[v], fresh.block(k).vertices[v]) << "step " << step;
		}
	}
	EXPECT_GT(coupledSteps, 100);  // the sparse path was taken
	EXPECT_GT(laterSolves, 100);   // solves after an attempt's first, which add kept terms
	EXPECT_GT(searches, 0);        // line searches, certified in `reused`
	EXPECT_GT(reused.memoryUse().solver, fresh.memoryUse().solver);  // terms and analyses were kept
	std::printf("%d steps: %d coupled, %d later solves, %d line searches\n", steps, coupledSteps, laterSolves,
	            searches);
}
}  // namespace

// The same on a settling pile: every step bitwise the same with and without
// the work the solver keeps between solves (the sparse analyses, the terms
// of contacts that neither slip nor carry a secant force, the certified line
// search).
TEST(Effects, SolverReuseLeavesAPileBitwiseTheSame) { expectSolverReuseBitwise(5, gravitySettings(true), 300); }

// And under average acceleration (beta 1/4, gamma 1/2), where every closed
// contact's normal force is the secant's (not kept) and the line search's
// bound covers the secant term: 29 cubes.
TEST(Effects, SolverReuseLeavesAPileBitwiseTheSameUnderAverageAcceleration) {
	IntegratorSettings settings = gravitySettings(true);
	settings.newmarkBeta = 0.25;
	settings.newmarkGamma = 0.5;
	expectSolverReuseBitwise(7, settings, 300);
}
