// A free block's steps (pkg/dda/solver: World::step, BlockEquations), against
// closed forms: free fall exact for any time step, the step cut by the
// displacement bound, and the finite-strain stress update and rate transport.
// (Moved from test_block_kinematics.cpp, whose BlockKinematics suite held them.)
#include "dda/block/Displacement.hpp"
#include "dda/solver/BlockEquations.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

using namespace dda;
using dda::testing::boxPoints;
using dda::testing::randomUnknowns;

TEST(TimeIntegration, FreeFallIsExactForAnyTimeStep) {
	World world;
	const int b = world.addBlock(boxPoints(Vector3(0, 0, 10), Vector3(1, 2, 13)), Material{2600, 4e6, 0.25}, false);
	const Vector3 v0(1.5, -0.5, 4.0), g(0, 0, -9.81);
	world.setVelocity(b, v0, Vector3::Zero());
	const Vector3 c0 = world.block(b).centroid;
	IntegratorSettings settings;
	settings.gravity = g;
	settings.maxDisplacement = 1e9;  // no step cuts
	double t = 0;
	const double steps[] = {1e-3, 0.01, 0.137, 1e-4};
	for (int i = 0; i < 40; ++i) {
		settings.maxTimeStep = steps[i % 4];
		t += world.step(settings);
	}
	const Vector3 expected = c0 + v0 * t + 0.5 * g * t * t;
	EXPECT_LT((world.block(b).centroid - expected).norm(), 1e-12 * expected.norm());
	EXPECT_LT((world.block(b).velocity.head<3>() - (v0 + g * t)).norm(), 1e-12 * (v0 + g * t).norm());
	EXPECT_LT(world.block(b).velocity.tail<9>().norm(), 1e-12);
}

TEST(TimeIntegration, TimeStepIsCutWhenDisplacementExceedsTheBound) {
	World world;
	const int b = world.addBlock(boxPoints(Vector3(0, 0, 0), Vector3(1, 1, 1)), Material{2600, 4e6, 0.25}, false);
	world.setVelocity(b, Vector3(10, 0, 0), Vector3::Zero());
	IntegratorSettings settings;
	settings.maxTimeStep = 0.01;  // 0.1 m per step at 10 m/s
	settings.maxDisplacement = 0.02;
	const double dt = world.step(settings);
	EXPECT_GT(world.lastStep().stepCuts, 0);
	EXPECT_LE(world.lastStep().maxDisplacement, 0.02);
	EXPECT_NEAR(world.block(b).centroid.x() - 0.5, 10 * dt, 1e-12);
	EXPECT_THROW({ settings.maxTimeStep = 0; world.step(settings); }, InputError);
}

// A block falling at the displacement bound: the first dt each step tries
// follows the last step's motion (TimeStepControl::stepTaken), so steps are
// not redone one after another (growing dt by 1.3 regardless made every step
// overshoot and be cut); every step stays within the bound, and the fall is
// the closed form (exact for any sequence of dt).
TEST(TimeIntegration, FallingAtTheBoundIsNotRedoneEveryStep) {
	World world;
	const int b = world.addBlock(boxPoints(Vector3(0, 0, 0), Vector3(1, 1, 1)), Material{2600, 4e6, 0.25}, false);
	const Vector3 g(0, 0, -9.81);
	const Vector3 c0 = world.block(b).centroid;
	IntegratorSettings settings;
	settings.gravity = g;
	settings.maxTimeStep = 0.01;
	settings.maxDisplacement = 0.002;  // reached at 0.2 m/s, after 2 steps
	// A redo is expected only while the motion of one step grows by more
	// than 1 / timeStepSafety over the next: (v + g dt) / v > 1 / 0.9 with
	// dt = 0.9 a / v, i.e. below v = sqrt(8.1 g a) = 0.4 m/s.
	double t = 0;
	int cuts = 0, lateCuts = 0, boundSteps = 0;
	for (int step = 0; step < 400; ++step) {
		const double speed = world.block(b).velocity.head<3>().norm();
		t += world.step(settings);
		const StepStatistics& s = world.lastStep();
		cuts += s.stepCuts;
		if (speed > 0.5) lateCuts += s.stepCuts;
		boundSteps += s.dt < settings.maxTimeStep;
		ASSERT_LE(s.maxDisplacement, settings.maxDisplacement) << "step " << step;
	}
	std::printf("%d redos in 400 steps, %d above 0.5 m/s; fell to %.2f m/s\n", cuts, lateCuts,
	            world.block(b).velocity.head<3>().norm());
	EXPECT_GT(boundSteps, 390);  // the bound decided the steps
	EXPECT_EQ(lateCuts, 0);      // not one redo per step (the old rule: every step)
	const Vector3 expected = c0 + 0.5 * g * t * t;
	EXPECT_LT((world.block(b).centroid - expected).norm(), 1e-10 * expected.norm());
	EXPECT_LT((world.block(b).velocity.head<3>() - g * t).norm(), 1e-10 * (g * t).norm());
}

// Finite strain (BlockEquations.hpp): the accepted step's stress update and the
// transport of the rates to the new configuration, against their definitions,
// for random steps far beyond small strain (strain increments up to 0.3,
// rotations up to 1 rad) on a block with a random stress.
TEST(TimeIntegration, FiniteStrainStepChangesTheStrainEnergyByTheElasticWork) {
	std::mt19937 rng(20261126);
	std::uniform_real_distribution<double> u(-1, 1);
	World world;
	const int b = world.addBlock(boxPoints(Vector3(0, 0, 0), Vector3(1, 2, 0.5)), Material{2600, 1e6, 0.3}, false);
	const auto energy = [](const Block& block) {
		const double ratio = block.volume / block.referenceVolume();
		const Vector6 tau = ratio * block.stress;
		return 0.5 * block.referenceVolume() * tau.dot(block.elasticity().ldlt().solve(tau));
	};
	Block block = world.block(b);
	for (int trial = 0; trial < 200; ++trial) {
		Vector12 D = randomUnknowns(rng);
		D.segment<6>(6) *= 0.3;
		const Vector12 v = randomUnknowns(rng);
		for (int i = 0; i < 6; ++i) block.stress(i) = 3e5 * u(rng);
		const double startVolume = block.volume, V0 = block.referenceVolume();
		const Vector6 tau0 = (startVolume / V0) * block.stress;
		const Vector6 eps = D.segment<6>(6);
		const double work = V0 * (tau0.dot(eps) + 0.5 * eps.dot(block.elasticity() * eps));
		const double before = energy(block);
		const double kineticBefore = kineticEnergy(block, v);
		Block moved = block;
		applyStep(moved, D, v);
		EXPECT_NEAR(energy(moved) - before, work, 1e-12 * (before + std::abs(work))) << trial;
		EXPECT_NEAR(moved.volume, startVolume * (Matrix3::Identity() + strainTensor(eps)).determinant(), 1e-12 * startVolume);
		// The rates' kinetic energy carries over to the new configuration.
		EXPECT_NEAR(kineticEnergy(moved, moved.velocity), kineticBefore, 1e-12 * kineticBefore) << trial;
		if (moved.volume > 0.2 * V0 && moved.volume < 5 * V0) block = moved;  // walk on, within bounds
	}
}

TEST(TimeIntegration, TransportedRatesTurnASpinWithTheBlock) {
	// No strain: the spin and strain rates turn with the rotation; a spin about
	// the rotation's own axis is unchanged.
	std::mt19937 rng(7);
	for (int trial = 0; trial < 100; ++trial) {
		const Vector12 v = randomUnknowns(rng);
		const Vector3 r = randomUnknowns(rng).head<3>();
		const Matrix3 R = rotationFromVector(r);
		const Vector12 carried = transportedRates(v, R, Matrix3::Identity());
		EXPECT_LT((carried.head<3>() - v.head<3>()).norm(), 1e-15);
		EXPECT_LT((carried.segment<3>(3) - R * v.segment<3>(3)).norm(), 1e-14);
		EXPECT_LT((strainTensor(carried.segment<6>(6)) - R * strainTensor(v.segment<6>(6)) * R.transpose()).norm(), 1e-14);
		Vector12 spin = Vector12::Zero();
		spin.segment<3>(3) = 2.5 * r;
		EXPECT_LT((transportedRates(spin, R, Matrix3::Identity()) - spin).norm(), 1e-14 * spin.norm());
	}
}
