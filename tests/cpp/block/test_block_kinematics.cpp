// Block kinematics (pkg/dda/block): the displacement function, the mass and
// elasticity matrices and the exact rotation, against closed forms. A free
// block's steps are in solver/test_time_integration.cpp.
#include "dda/block/Displacement.hpp"
#include "TestScenes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

using namespace dda;
using dda::testing::randomUnknowns;

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

// The closed form of (s T(d))^T g equals Eigen's product of the matrices
// entry by entry (the same products in the same order; == also takes -0 for
// +0), and is the virtual work: g . T(d) D = ((1 T(d))^T g) . D for any D.
TEST(BlockKinematics, DisplacementTransposeTimesIsTheMatrixProduct) {
	const unsigned seed = 11;
	std::printf("seed %u\n", seed);
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> scale(-3, 3);
	for (int trial = 0; trial < 2000; ++trial) {
		const Vector3 d = std::pow(10.0, scale(rng)) * randomUnknowns(rng).head<3>();
		const Vector3 g = std::pow(10.0, scale(rng)) * randomUnknowns(rng).head<3>();
		const double s = std::pow(10.0, scale(rng)) * (trial % 2 ? 1 : -1);
		const Vector12 closed = displacementTransposeTimes(d, g, s);
		const Vector12 eigen = (s * displacementMatrix(d).transpose()) * g;
		for (int i = 0; i < 12; ++i) ASSERT_EQ(closed(i), eigen(i)) << "entry " << i << " trial " << trial;
		const Vector12 D = randomUnknowns(rng);
		EXPECT_NEAR(displacementTransposeTimes(d, g, 1.0).dot(D), g.dot(displacementMatrix(d) * D),
		            1e-13 * g.norm() * (1 + d.norm()) * D.norm());
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
