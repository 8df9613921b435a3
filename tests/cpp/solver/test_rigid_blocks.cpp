// Rigid blocks: 6 unknowns (translation, rotation) instead of 12. The mass
// matrix, the variable-size coupled solve against an independent dense solve of
// the restricted system, a free rigid block against closed forms, and bad input.
#include "dda/block/Displacement.hpp"
#include "dda/solver/CoupledSystem.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace dda;
using dda::testing::boxPoints;

TEST(RigidBlocks, RigidMassMatrixIsTheTranslationRotationBlockOfTheMassMatrix) {
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> u(-1, 1);
	for (int trial = 0; trial < 10; ++trial) {
		Matrix3 A;
		for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = u(rng);
		const Matrix3 J = A * A.transpose() + 0.1 * Matrix3::Identity();
		const Matrix12 M = massMatrix(2600, 1.7, J);
		const Matrix6 M6 = rigidMassMatrix(2600, 1.7, J);
		// Bitwise: the rigid path must not change a trajectory by round-off.
		EXPECT_EQ(Matrix6(M.topLeftCorner<6, 6>()), M6);
		// Closed form of the rotational inertia: rho (tr(J) I - J).
		const Matrix3 inertia = 2600 * (J.trace() * Matrix3::Identity() - J);
		EXPECT_LT((M6.block<3, 3>(3, 3) - inertia).norm(), 1e-12 * inertia.norm());
	}
}

// Four blocks: rigid, deformable, rigid joined in one component (sparse
// path) and a lone rigid block with springs (dense 6x6 path). The solution
// must be that of the dense system restricted to the free unknowns (the
// rigid blocks' strain rows and columns struck out), with the rigid blocks'
// strain unknowns exactly zero.
TEST(RigidBlocks, CoupledSolveLeavesOutTheStrainUnknownsOfRigidBlocks) {
	std::mt19937 rng(5);
	std::uniform_real_distribution<double> u(-1, 1);
	const int blocks = 4, n = 12 * blocks;
	Eigen::MatrixXd B(n, n);
	for (int i = 0; i < n * n; ++i) B(i / n, i % n) = u(rng);
	Eigen::MatrixXd K = B * B.transpose() + n * Eigen::MatrixXd::Identity(n, n);
	// Block 3 is joined to no other block.
	K.block(36, 0, 12, 36).setZero();
	K.block(0, 36, 36, 12).setZero();
	Eigen::VectorXd F(n);
	for (int i = 0; i < n; ++i) F(i) = u(rng);

	const std::vector<int> unknowns = {6, 12, 6, 6};
	CoupledSystem system;
	system.build(blocks, {{0, 1}, {1, 2}, {0, 2}}, {1, 1, 1, 1}, unknowns);
	std::vector<BlockSystem> own(blocks);
	for (int k = 0; k < blocks; ++k) {
		own[k].stiffness = K.block<12, 12>(12 * k, 12 * k);
		own[k].force = F.segment<12>(12 * k);
	}
	system.reset(own, {0, 1, 2, 3});
	for (auto [a, b] : {std::pair{0, 1}, std::pair{1, 2}, std::pair{2, 0}}) {
		bool transposed;
		Matrix12& m = system.offDiagonal(a, b, transposed);
		m = transposed ? Matrix12(K.block<12, 12>(12 * b, 12 * a)) : Matrix12(K.block<12, 12>(12 * a, 12 * b));
	}
	std::vector<Vector12> solutions(blocks, Vector12::Constant(7.0));  // garbage that must be overwritten
	system.solve(solutions, 1 << 30);
	EXPECT_EQ(system.solvedUnknowns(), 6 + 12 + 6 + 6);

	std::vector<int> free;
	for (int k = 0; k < blocks; ++k)
		for (int i = 0; i < unknowns[k]; ++i) free.push_back(12 * k + i);
	const int m = static_cast<int>(free.size());
	Eigen::MatrixXd Kr(m, m);
	Eigen::VectorXd Fr(m);
	for (int i = 0; i < m; ++i) {
		Fr(i) = F(free[i]);
		for (int j = 0; j < m; ++j) Kr(i, j) = K(free[i], free[j]);
	}
	const Eigen::VectorXd expected = Kr.llt().solve(Fr);
	for (int i = 0; i < m; ++i) EXPECT_NEAR(solutions[free[i] / 12](free[i] % 12), expected(i), 1e-12) << "unknown " << free[i];
	for (int k : {0, 2, 3}) EXPECT_EQ(solutions[k].tail<6>(), Vector6::Zero()) << "rigid block " << k;
}

// A rigid cube thrown and spinning under gravity: its centroid follows the
// parabola, it turns by |w| t about w (a cube's inertia is isotropic, so the
// spin is torque-free and steady), its vertices move rigidly, and its
// strain, stress, strain rates and volume stay exactly as they were.
TEST(RigidBlocks, FreeRigidCubeFallsAndSpinsWithoutStrain) {
	World world;
	const int b = world.addBlock(boxPoints(Vector3(0, 0, 10), Vector3(1, 1, 11)), Material{2600, 4e6, 0.25}, false, true);
	const Vector3 v0(1.5, -0.5, 4.0), w0(0.3, -1.2, 2.0), g(0, 0, -9.81);
	world.setVelocity(b, v0, w0);
	const Block start = world.block(b);
	IntegratorSettings settings;
	settings.gravity = g;
	settings.maxDisplacement = 1e9;  // no step cuts
	double t = 0;
	const double steps[] = {1e-3, 0.01, 0.037, 1e-4};
	for (int i = 0; i < 40; ++i) {
		settings.maxTimeStep = steps[i % 4];
		t += world.step(settings);
		const StepStatistics& s = world.lastStep();
		EXPECT_EQ(s.unknowns, 6);
		EXPECT_EQ(s.solvedUnknowns, 6);
		EXPECT_EQ(s.strainUnknowns, 0);
		EXPECT_EQ(s.rigidBlocks, 1);
	}
	const Block& end = world.block(b);
	const Vector3 expected = start.centroid + v0 * t + 0.5 * g * t * t;
	EXPECT_LT((end.centroid - expected).norm(), 1e-12 * expected.norm());
	EXPECT_LT((end.velocity.head<3>() - (v0 + g * t)).norm(), 1e-12 * (v0 + g * t).norm());
	EXPECT_LT((end.velocity.segment<3>(3) - w0).norm(), 1e-12 * w0.norm());
	const Matrix3 R = Eigen::AngleAxisd(w0.norm() * t, w0.normalized()).toRotationMatrix();
	for (std::size_t k = 0; k < end.vertices.size(); ++k)
		EXPECT_LT((end.vertices[k] - (end.centroid + R * (start.vertices[k] - start.centroid))).norm(), 1e-11);
	EXPECT_EQ(end.strain, Vector6::Zero());
	EXPECT_EQ(end.stress, Vector6::Zero());
	EXPECT_EQ(end.velocity.tail<6>(), Vector6::Zero());
	EXPECT_EQ(end.volume, start.volume);
	EXPECT_EQ(end.mass, start.mass);
	EXPECT_LT((end.secondMoment - R * start.secondMoment * R.transpose()).norm(), 1e-12 * start.secondMoment.norm());
}

TEST(RigidBlocks, InitialStressOnARigidBlockIsAnErrorNamingIt) {
	World world;
	world.addBlock(boxPoints(Vector3(0, 0, 0), Vector3(1, 1, 1)), Material{}, false, false);
	const int rigid = world.addBlock(boxPoints(Vector3(2, 0, 0), Vector3(3, 1, 1)), Material{}, false, true);
	Vector6 stress;
	stress << -1e5, 0, 0, 0, 0, 0;
	world.setStress(0, stress);  // a deformable block may carry it
	try {
		world.setStress(rigid, stress);
		FAIL() << "a rigid block accepted an initial stress";
	} catch (const InputError& error) {
		EXPECT_NE(std::string(error.what()).find("block 1 is rigid"), std::string::npos) << error.what();
	}
	EXPECT_EQ(world.block(rigid).stress, Vector6::Zero());
	world.setStress(rigid, Vector6::Zero());  // zero stress is no stress
}
