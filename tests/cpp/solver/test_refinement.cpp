// Refinement of the open-close iteration's later solves (CoupledSystem.hpp):
// conjugate gradients preconditioned with the attempt's earlier factor of the
// same blocks. Oracles: a dense Cholesky of the new matrix (random SPD block
// systems changed by random rank-one terms, seeds in the messages); the
// iteration count bound of a rank-r change (r + 1 in exact arithmetic); a
// step of a settling pile taken with and without refinement from the same
// saved state. Also the 12x12 update kernel against the scalar loop, bitwise.
#include "dda/collider/Collider.hpp"
#include "dda/solver/BlockKernels.hpp"
#include "dda/solver/CoupledSystem.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"
#include "solver/RandomBlockSystem.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <set>
#include <utility>
#include <vector>

using namespace dda;
using namespace dda::testing;

// Rank-r changes of a factorised system are refined in at most r + 2
// iterations (r + 1 in exact arithmetic) to the dense solution; a new
// attempt factorises again; a change the budget cannot absorb falls back to
// a factorisation, whose solution is bitwise the direct one.
TEST(Refinement, RankOneChangesConvergeToTheDenseSolution) {
	for (unsigned seed : {3u, 11u, 29u}) {
		std::mt19937 rng(seed);
		RandomSystem sys(rng, 40, 0.5, seed == 11 ? 0.3 : 0.0);
		const std::vector<char> springs(sys.blocks, 1);
		CoupledSystem system, direct;
		system.build(sys.blocks, sys.links, springs, sys.unknowns);
		direct.build(sys.blocks, sys.links, springs, sys.unknowns);
		system.beginAttempt(true);
		direct.beginAttempt(false);
		std::vector<Vector12> x(sys.blocks, Vector12::Zero()), y = x;
		sys.load(system);
		system.solve(x, 1 << 30);
		EXPECT_EQ(system.refinedComponents(), 0) << "seed " << seed << ": an attempt's first solve factorises";
		EXPECT_LE(largestError(x, sys.denseSolution()), 1e-12) << "seed " << seed;
		std::uniform_int_distribution<int> link(0, static_cast<int>(sys.links.size()) - 1);
		// Each later solve is preconditioned with the attempt's first factor,
		// so the change it sees is the sum of the changes so far: rank 1, 4, 9
		// (within the budget of these systems, 11 iterations or more).
		int rank = 0;
		for (int added : {1, 3, 5}) {
			for (int r = 0; r < added; ++r) sys.addRankOne(rng, link(rng), 20.0);
			rank += added;
			sys.load(system);
			system.solve(x, 1 << 30);
			ASSERT_EQ(system.refinedComponents(), 1) << "seed " << seed << " rank " << rank << ": "
			                                         << system.refineIterations() << " iterations, "
			                                         << system.refineFallbacks() << " fallbacks";
			EXPECT_LE(system.refineIterations(), rank + 2) << "seed " << seed << " rank " << rank;
			EXPECT_LE(largestError(x, sys.denseSolution()), 1e-11) << "seed " << seed << " rank " << rank;
		}
		// A new attempt: factorised.
		system.beginAttempt(true);
		sys.load(system);
		system.solve(x, 1 << 30);
		EXPECT_EQ(system.refinedComponents(), 0) << "seed " << seed;
		// A matrix far from the factor's: the budget runs out and the
		// component is factorised, exactly as without refinement.
		for (int k = 0; k < sys.blocks; ++k) {
			const Matrix12 r = randomMatrix(rng, 30);
			sys.own[k].stiffness += r * r.transpose();
		}
		sys.load(system);
		system.solve(x, 1 << 30);
		EXPECT_EQ(system.refinedComponents(), 0) << "seed " << seed;
		EXPECT_EQ(system.refineFallbacks(), 1) << "seed " << seed;
		sys.load(direct);
		direct.solve(y, 1 << 30);
		for (int k = 0; k < sys.blocks; ++k) EXPECT_EQ(x[k], y[k]) << "seed " << seed << " block " << k;
	}
}

// A structure change within the attempt (a link added, the same blocks) is
// refined with the earlier factor; a component of other blocks is not.
TEST(Refinement, NewLinkSameBlocksRefinedOtherBlocksFactorised) {
	std::mt19937 rng(5);
	RandomSystem sys(rng, 30, 0.3, 0.0);
	const std::vector<char> springs(sys.blocks, 1);
	CoupledSystem system;
	system.build(sys.blocks, sys.links, springs, sys.unknowns);
	system.beginAttempt(true);
	std::vector<Vector12> x(sys.blocks, Vector12::Zero());
	sys.load(system);
	system.solve(x, 1 << 30);
	// A new link (0, 29) carrying a small rank-one term.
	std::pair<int, int> added(0, sys.blocks - 1);
	ASSERT_TRUE(std::find(sys.links.begin(), sys.links.end(), added) == sys.links.end());
	sys.links.push_back(added);
	sys.offDiagonal.push_back(Matrix12::Zero());
	sys.addRankOne(rng, static_cast<int>(sys.links.size()) - 1, 5.0);
	system.build(sys.blocks, sys.links, springs, sys.unknowns);
	sys.load(system);
	system.solve(x, 1 << 30);
	EXPECT_EQ(system.refinedComponents(), 1);
	EXPECT_LE(largestError(x, sys.denseSolution()), 1e-11);
	// Block 29 split off (its links dropped): the other 29 blocks are not the
	// factorised set, so they are factorised.
	std::vector<std::pair<int, int>> kept;
	std::vector<Matrix12> keptBlocks;
	for (std::size_t l = 0; l < sys.links.size(); ++l)
		if (sys.links[l].second != sys.blocks - 1) {
			kept.push_back(sys.links[l]);
			keptBlocks.push_back(sys.offDiagonal[l]);
		}
	sys.links = kept;
	sys.offDiagonal = keptBlocks;
	system.build(sys.blocks, sys.links, springs, sys.unknowns);
	sys.load(system);
	system.solve(x, 1 << 30);
	EXPECT_EQ(system.refinedComponents(), 0);
	EXPECT_LE(largestError(x, sys.denseSolution()), 1e-12);
}

// One step of a settling stack of crossed beams from the same saved state,
// with and without refinement: the same contacts' states, and displacements
// equal to within 1e-7 of the step's largest displacement (refinement stops
// at a backward error of 1e-14; the difference is that times the system's
// conditioning), at 15 states of the settling.
TEST(Refinement, PileStepMatchesTheFactorisedStep) {
	World world = crossedBeams(4, 4);
	IntegratorSettings exact = gravitySettings(true);
	exact.refineSolves = false;
	IntegratorSettings refined = exact;
	refined.refineSolves = true;
	int refinedSteps = 0, iterations = 0, compared = 0;
	double worst = 0;
	for (int step = 0; step < 150; ++step) {
		if (step % 10 == 9) {
			World copy;
			double moved = 0;
			const double difference = stepWithTwin(world, exact, copy, refined, moved);
			const StepStatistics& s = copy.lastStep();
			refinedSteps += s.refinedComponents > 0;
			iterations += s.refineIterations;
			ASSERT_EQ(s.openCloseIterationsTotal, world.lastStep().openCloseIterationsTotal) << "step " << step;
			ASSERT_EQ(s.closedContacts, world.lastStep().closedContacts) << "step " << step;
			if (moved > 0) worst = std::max(worst, difference / moved);
			EXPECT_LE(difference, 1e-7 * moved) << "step " << step;
			++compared;
		} else {
			world.step(exact);
		}
	}
	std::printf("%d steps compared, %d refined (%d iterations); worst difference %.2e of the step's motion\n",
	            compared, refinedSteps, iterations, worst);
	EXPECT_GT(refinedSteps, 3);  // the refined path was taken
}

// The update kernel's result is the scalar loop's, bitwise, on the variant
// this machine runs and on the SSE2 one.
TEST(Refinement, UpdateKernelIsTheScalarLoopBitwise) {
	std::mt19937 rng(8);
	for (int trial = 0; trial < 200; ++trial) {
		const Matrix12 a = randomMatrix(rng, 1e3), b = randomMatrix(rng, 1e-3), c0 = randomMatrix(rng, 7);
		Matrix12 fast = c0, sse2 = c0, scalar = c0;
		subtractProductTransposed(fast, a, b);
		subtractProductTransposedSse2(sse2, a, b);
		subtractProductTransposedScalar(scalar, a, b);
		ASSERT_EQ(std::memcmp(fast.data(), scalar.data(), sizeof(Matrix12)), 0) << "trial " << trial;
		ASSERT_EQ(std::memcmp(sse2.data(), scalar.data(), sizeof(Matrix12)), 0) << "trial " << trial;
	}
	std::printf("kernel variant: %s\n", blockKernelsUseAvx2() ? "AVX2" : "SSE2");
}
