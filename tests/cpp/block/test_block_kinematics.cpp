// Block kinematics: the displacement function, the mass and elasticity
// matrices, and one implicit step of a free block, against closed forms.
#include "dda/block/Displacement.hpp"
#include "dda/solver/BlockEquations.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace dda;
using dda::testing::boxPoints;

namespace {
Vector12 randomUnknowns(std::mt19937& rng) {
	std::uniform_real_distribution<double> u(-1, 1);
	Vector12 D;
	for (int i = 0; i < 12; ++i) D(i) = u(rng);
	return D;
}

}  // namespace

TEST(BlockKinematics, DisplacementMatrixMatchesFieldAndEquation3) {
	std::mt19937 rng(3);
	for (int trial = 0; trial < 20; ++trial) {
		const Vector12 D = randomUnknowns(rng);
		const Vector3 d = randomUnknowns(rng).head<3>();
		EXPECT_LT((displacementMatrix(d) * D - displacementAt(d, D)).norm(), 1e-14);
		// Eq. (3) of Wu et al. written out for u: u0 + dz r2 - dy r3 + dx ex + dy gxy/2 + dz gzx/2
		const double u = D(0) + d.z() * D(4) - d.y() * D(5) + d.x() * D(6) + d.y() * D(9) / 2 + d.z() * D(11) / 2;
		const double v = D(1) - d.z() * D(3) + d.x() * D(5) + d.y() * D(7) + d.x() * D(9) / 2 + d.z() * D(10) / 2;
		const double w = D(2) + d.y() * D(3) - d.x() * D(4) + d.z() * D(8) + d.y() * D(10) / 2 + d.x() * D(11) / 2;
		EXPECT_NEAR((displacementMatrix(d) * D - Vector3(u, v, w)).norm(), 0, 1e-14);
	}
}

TEST(BlockKinematics, MassMatrixEqualsGaussQuadratureOfTTransposeT) {
	// rho * integral of T^T T over a box: T^T T is quadratic in d, so 2-point
	// Gauss-Legendre per axis integrates it exactly.
	const Vector3 half(0.5, 1.0, 1.5);
	const double density = 2600, volume = 8 * half.prod();
	Matrix3 J = Matrix3::Zero();
	for (int k = 0; k < 3; ++k) J(k, k) = volume * half(k) * half(k) / 3;
	Matrix12 quadrature = Matrix12::Zero();
	const double g = 1 / std::sqrt(3.0);
	for (int i = 0; i < 8; ++i) {
		const Vector3 d((i & 1 ? g : -g) * half.x(), (i & 2 ? g : -g) * half.y(), (i & 4 ? g : -g) * half.z());
		const Matrix3x12 T = displacementMatrix(d);
		quadrature += (volume / 8) * density * T.transpose() * T;
	}
	EXPECT_LT((massMatrix(density, volume, J) - quadrature).norm(), 1e-9 * quadrature.norm());
}

TEST(BlockKinematics, ElasticityMatrixGivesUniaxialStress) {
	const double E = 4e6, nu = 0.25, strain = 1e-3;
	Vector6 eps = Vector6::Zero();
	eps << strain, -nu * strain, -nu * strain, 0, 0, 0;
	const Vector6 sigma = elasticityMatrix(E, nu) * eps;
	EXPECT_NEAR(sigma(0), E * strain, 1e-9 * E * strain);
	EXPECT_NEAR(sigma(1), 0, 1e-9 * E * strain);
	EXPECT_NEAR(sigma(2), 0, 1e-9 * E * strain);
	Vector6 shear = Vector6::Zero();
	shear(4) = strain;
	EXPECT_NEAR((elasticityMatrix(E, nu) * shear)(4), E / (2 * (1 + nu)) * strain, 1e-9 * E * strain);
}

TEST(BlockKinematics, ExactRotationIsOrthonormalAndKeepsItsAxis) {
	const Vector3 r(0.3, -1.2, 2.0);
	const Matrix3 R = rotationFromVector(r);
	EXPECT_LT((R * R.transpose() - Matrix3::Identity()).norm(), 1e-15);
	EXPECT_NEAR(R.determinant(), 1, 1e-15);
	EXPECT_LT((R * r - r).norm(), 1e-14);
	// small rotations agree with the linear part of T to second order
	const Vector3 small = 1e-6 * r, d(1, 2, 3);
	EXPECT_LT(((rotationFromVector(small) - Matrix3::Identity()) * d - small.cross(d)).norm(), 1e-11);
}

TEST(BlockKinematics, FreeFallIsExactForAnyTimeStep) {
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

TEST(BlockKinematics, TimeStepIsCutWhenDisplacementExceedsTheBound) {
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

// Finite strain (BlockEquations.hpp): the accepted step's stress update and the
// transport of the rates to the new configuration, against their definitions,
// for random steps far beyond small strain (strain increments up to 0.3,
// rotations up to 1 rad) on a block with a random stress.
TEST(BlockKinematics, FiniteStrainStepChangesTheStrainEnergyByTheElasticWork) {
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

TEST(BlockKinematics, TransportedRatesTurnASpinWithTheBlock) {
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
