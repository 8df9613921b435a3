// The coupled system's iterative path (CoupledSystem.hpp,
// BlockConjugateGradient.hpp): block-Jacobi preconditioned conjugate
// gradients on components of at least iterativeSolveBlocks blocks. Oracles:
// the backward error computed here from the dense matrix, the dense
// Cholesky's solution (random SPD block systems, seeds in the messages),
// bitwise equality across thread counts, and a settling stack stepped with
// and without the iterative path from the same saved states.
#include "dda/solver/BlockConjugateGradient.hpp"
#include "dda/solver/CoupledSystem.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"
#include "solver/RandomBlockSystem.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace dda;
using namespace dda::testing;

namespace {

// Solves `sys` once with the iterative path from `fromBlocks` blocks.
std::vector<Vector12> solveOnce(const RandomSystem& sys, int fromBlocks, double tolerance, CoupledSystem& system) {
	const std::vector<char> springs(sys.blocks, 1);
	system.build(sys.blocks, sys.links, springs, sys.unknowns);
	system.beginAttempt(false);
	system.setIterative(fromBlocks, tolerance);
	std::vector<Vector12> x(sys.blocks, Vector12::Zero());
	sys.load(system);
	system.solve(x, 1 << 30);
	return x;
}

bool bitwiseEqual(const std::vector<Vector12>& a, const std::vector<Vector12>& b) {
	for (std::size_t k = 0; k < a.size(); ++k)
		if (std::memcmp(a[k].data(), b[k].data(), sizeof(Vector12)) != 0) return false;
	return true;
}

}  // namespace

// The solution's backward error, computed from the dense matrix, is within
// the tolerance asked, at 1e-8 and 1e-13; its error against the dense
// Cholesky within the tolerance times these well-conditioned systems'
// conditioning; a rigid block's strain part exactly zero.
TEST(IterativeSolve, ReachesTheBackwardErrorAsked) {
	for (unsigned seed : {3u, 17u, 41u}) {
		std::mt19937 rng(seed);
		RandomSystem sys(rng, 90, 0.05, 0.2);
		const std::vector<Vector12> dense = sys.denseSolution();
		for (double tolerance : {1e-8, 1e-13}) {
			CoupledSystem system;
			const std::vector<Vector12> x = solveOnce(sys, 64, tolerance, system);
			ASSERT_EQ(system.iterativeComponents(), 1) << "seed " << seed;
			EXPECT_EQ(system.iterativeFallbacks(), 0) << "seed " << seed;
			EXPECT_GT(system.iterativeIterations(), 0) << "seed " << seed;
			// The solver's residual and this one round differently: a few u.
			EXPECT_LE(sys.backwardError(x), tolerance + 1e-15) << "seed " << seed << " tolerance " << tolerance;
			EXPECT_LE(largestError(x, dense), 100 * tolerance) << "seed " << seed << " tolerance " << tolerance;
			for (int k = 0; k < sys.blocks; ++k)
				if (sys.unknowns[k] == kRigidBlockDofs)
					EXPECT_TRUE(x[k].tail<6>().isZero(0)) << "seed " << seed << " rigid block " << k;
			std::printf("seed %u tolerance %.0e: %d iterations, backward error %.2e\n", seed, tolerance,
			            system.iterativeIterations(), sys.backwardError(x));
		}
	}
}

// Components below the threshold are factorised: bitwise the solution with
// the iterative path off.
TEST(IterativeSolve, SmallComponentsAreFactorised) {
	std::mt19937 rng(7);
	RandomSystem sys(rng, 40, 0.2, 0.1);
	CoupledSystem on, off;
	const std::vector<Vector12> x = solveOnce(sys, 41, 1e-10, on), y = solveOnce(sys, 0, 1e-10, off);
	EXPECT_EQ(on.iterativeComponents(), 0);
	EXPECT_TRUE(bitwiseEqual(x, y));
	CoupledSystem at;
	solveOnce(sys, 40, 1e-10, at);
	EXPECT_EQ(at.iterativeComponents(), 1);
}

// The rows are threaded (from 128 blocks): one thread and two give bitwise
// the same iterates, on a cold solve and on a warm one after a change.
TEST(IterativeSolve, BitwiseTheSameForAnyThreadCount) {
#ifndef _OPENMP
	GTEST_SKIP() << "built without OpenMP: one thread only";
#else
	const int before = omp_get_max_threads();
	std::mt19937 rng(23);
	RandomSystem sys(rng, 400, 0.01, 0.1);
	std::vector<std::vector<Vector12>> results;
	std::vector<int> iterations;
	for (int threads : {1, 2}) {
		omp_set_num_threads(threads);
		RandomSystem changed = sys;
		std::mt19937 changes(5);
		CoupledSystem system;
		std::vector<Vector12> x = solveOnce(changed, 64, 1e-12, system);
		iterations.push_back(system.iterativeIterations());
		for (int r = 0; r < 4; ++r) changed.addRankOne(changes, 3 * r, 50.0);
		changed.load(system);
		system.solve(x, 1 << 30);
		ASSERT_EQ(system.iterativeComponents(), 1);
		iterations.push_back(system.iterativeIterations());
		results.push_back(x);
	}
	omp_set_num_threads(before);
	EXPECT_EQ(iterations[0], iterations[2]);
	EXPECT_EQ(iterations[1], iterations[3]);
	EXPECT_TRUE(bitwiseEqual(results[0], results[1]));
#endif
}

// Within an attempt a later solve starts from the last solution: the same
// system again takes no iteration, a few rank-one changes fewer than a cold
// solve of the changed system; a new attempt starts cold again.
TEST(IterativeSolve, LaterSolvesStartFromTheLastSolution) {
	std::mt19937 rng(31);
	RandomSystem sys(rng, 120, 0.03, 0.0);
	CoupledSystem system;
	std::vector<Vector12> x = solveOnce(sys, 64, 1e-12, system);
	const int cold = system.iterativeIterations();
	sys.load(system);
	system.solve(x, 1 << 30);
	EXPECT_EQ(system.iterativeIterations(), 0);
	sys.addRankOne(rng, 5, 30.0);
	sys.addRankOne(rng, 50, 30.0);
	sys.load(system);
	system.solve(x, 1 << 30);
	const int warm = system.iterativeIterations();
	EXPECT_LE(sys.backwardError(x), 1e-12);
	CoupledSystem fresh;
	const std::vector<Vector12> y = solveOnce(sys, 64, 1e-12, fresh);
	std::printf("cold %d, warm after two rank-one changes %d, cold on the changed system %d iterations\n", cold, warm,
	            fresh.iterativeIterations());
	EXPECT_LT(warm, fresh.iterativeIterations());
	system.beginAttempt(false);
	sys.load(system);
	system.solve(x, 1 << 30);
	EXPECT_EQ(system.iterativeIterations(), fresh.iterativeIterations());
	EXPECT_TRUE(bitwiseEqual(x, y));
}

// A diagonal block that is not positive definite: the iteration refuses it,
// the Cholesky it falls back to fails, and the solve throws.
TEST(IterativeSolve, NotPositiveDefiniteThrows) {
	std::mt19937 rng(2);
	RandomSystem sys(rng, 70, 0.05, 0.0);
	sys.own[33].stiffness(4, 4) = -1.0;
	CoupledSystem system;
	EXPECT_THROW(solveOnce(sys, 64, 1e-10, system), std::runtime_error);
}

// An iteration budget too small to converge: solve() says so and reports
// the backward error reached, which is above the tolerance.
TEST(IterativeSolve, ReportsAnUnconvergedSolve) {
	std::mt19937 rng(13);
	RandomSystem sys(rng, 80, 0.05, 0.0);
	std::vector<std::pair<int, int>> links = sys.links;
	std::vector<Matrix12> diagonal;
	for (const BlockSystem& b : sys.own) diagonal.push_back(b.stiffness);
	std::vector<Vector12> b, x(sys.blocks, Vector12::Zero());
	for (const BlockSystem& own : sys.own) b.push_back(own.force);
	BlockConjugateGradient::Matrix matrix;
	matrix.blocks = sys.blocks;
	matrix.diagonal = diagonal.data();
	matrix.offDiagonal = sys.offDiagonal.data();
	matrix.links = links.data();
	matrix.linkCount = static_cast<int>(links.size());
	matrix.sizes = sys.unknowns.data();
	BlockConjugateGradient cg;
	ASSERT_TRUE(cg.prepare(matrix, 1 << 30));
	EXPECT_FALSE(cg.solve(b.data(), x.data(), 1e-14, 2));
	EXPECT_EQ(cg.iterations(), 2);
	EXPECT_GT(cg.backwardError(), 1e-14);
	EXPECT_NEAR(cg.backwardError(), sys.backwardError(x), 1e-3 * cg.backwardError());
	EXPECT_TRUE(cg.solve(b.data(), x.data(), 1e-14, 500));
	EXPECT_LE(sys.backwardError(x), 1e-14 + 1e-15);
}

// A settling stack of frictionless crossed beams stepped from the same
// saved states with the iterative path (from 2 blocks, the default
// tolerance 1e-10) and without: as many closed contacts, vertices within
// 1e-5 of the step's largest motion (measured: 4e-7; the normwise backward
// error weighs the beams' rotation rows, lever arms of 2 m, with their
// translations). Frictionless, because the open-close iteration
// accepts a pass once its friction limits move forces by at most 1e-3 of
// their blocks' scale: two solutions within the solver's tolerance can end
// a pass apart, and then differ by up to 2e-3 of a step's motion (measured
// with 30 deg of friction), the iteration's tolerance, not the solver's.
TEST(IterativeSolve, PileStepMatchesTheFactorisedStep) {
	World world = crossedBeams(4, 4, 0.0);
	IntegratorSettings direct = gravitySettings(true);
	direct.iterativeSolveBlocks = 0;
	IntegratorSettings iterative = direct;
	iterative.iterativeSolveBlocks = 2;
	int iterativeSteps = 0, compared = 0;
	double worst = 0;
	for (int step = 0; step < 150; ++step) {
		if (step % 10 == 9) {
			World copy;
			double moved = 0;
			const double difference = stepWithTwin(world, direct, copy, iterative, moved);
			const StepStatistics& s = copy.lastStep();
			iterativeSteps += s.iterativeComponents > 0;
			ASSERT_EQ(s.closedContacts, world.lastStep().closedContacts) << "step " << step;
			ASSERT_EQ(s.slidingContacts, world.lastStep().slidingContacts) << "step " << step;
			if (moved > 0) worst = std::max(worst, difference / moved);
			EXPECT_LE(difference, 1e-5 * moved) << "step " << step;
			++compared;
		} else {
			world.step(direct);
		}
	}
	std::printf("%d steps compared, %d solved iteratively; worst difference %.2e of the step's motion\n", compared,
	            iterativeSteps, worst);
	EXPECT_GT(iterativeSteps, 5);
}
