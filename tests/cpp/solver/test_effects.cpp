// Effects on demand in the solver: work skipped must leave results unchanged.
// No friction terms without friction, no body force without gravity, static
// analysis (velocityRatio = 0); no stored system for blocks without springs;
// sparse analyses and contact terms kept between solves. Counters, not
// timings. (The broad phase's, DESS's pair cache and fixed blocks never
// searched, are in collider/test_pair_cache.cpp.)
#include "dda/collider/Collider.hpp"
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
void expectSolverReuseBitwise(int layers, IntegratorSettings settings, int steps) {
	// Refinement changes solutions at the level of its tolerance (it has its
	// own tests); what is compared here is the reuse that must be exact.
	settings.refineSolves = false;
	World reused = cubePile(std::make_unique<DESSCollider>(), layers, 0.3);
	World fresh = cubePile(std::make_unique<DESSCollider>(), layers, 0.3);
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
