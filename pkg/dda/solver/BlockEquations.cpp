#include "BlockEquations.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dda {

void assembleBlock(const Block& block, const IntegratorSettings& settings, double dt, BlockSystem& system) {
	if (block.rigid) {
		assembleRigidBlock(block, settings, dt, system);
		return;
	}
	const Vector12 v0 = startVelocity(block, settings);
	const Matrix12 mass = massMatrix(block.density(), block.volume, block.secondMoment);
	system.stiffness.noalias() = (2 / (dt * dt)) * mass;
	system.force.noalias() = (2 / dt) * (mass * v0);

	system.stiffness.block<6, 6>(6, 6).noalias() += block.volume * block.elasticity();
	system.force.segment<6>(6).noalias() -= block.volume * block.stress;

	if (!settings.gravity.isZero()) system.force.head<3>() += block.mass * settings.gravity;

	for (const FixedPoint& point : block.fixedPoints) {
		const Matrix3x12 T = displacementMatrix(point.position - block.centroid);
		const double stiffness = fixedPointStiffness(point, block, settings);
		system.stiffness.noalias() += stiffness * T.transpose() * T;
		system.force.noalias() += stiffness * T.transpose() * (point.anchor - point.position);
	}
	for (const PointLoad& load : block.loads)
		system.force.noalias() += displacementMatrix(load.position - block.centroid).transpose() * load.force;
}

void assembleRigidBlock(const Block& block, const IntegratorSettings& settings, double dt, BlockSystem& system) {
	// Only the translation-rotation rows and columns are computed; the strain
	// part of the 12x12 system is zero and never read (solveBlock and
	// CoupledSystem take the first 6 unknowns of a rigid block).
	const Vector6 v0 = startVelocity(block, settings).head<6>();
	const Matrix6 mass = rigidMassMatrix(block.density(), block.volume, block.secondMoment);
	system.stiffness.setZero();
	system.force.setZero();
	auto stiffness = system.stiffness.topLeftCorner<6, 6>();
	auto force = system.force.head<6>();
	stiffness.noalias() = (2 / (dt * dt)) * mass;
	force.noalias() = (2 / dt) * (mass * v0);
	if (!settings.gravity.isZero()) force.head<3>() += block.mass * settings.gravity;
	for (const FixedPoint& point : block.fixedPoints) {
		const Matrix3x6 T = displacementMatrix(point.position - block.centroid).leftCols<6>();
		const double k = fixedPointStiffness(point, block, settings);
		stiffness.noalias() += k * T.transpose() * T;
		force.noalias() += k * T.transpose() * (point.anchor - point.position);
	}
	for (const PointLoad& load : block.loads)
		force.noalias() += displacementMatrix(load.position - block.centroid).leftCols<6>().transpose() * load.force;
}

Vector12 solveBlock(const Block& block, const BlockSystem& system) {
	Vector12 D;
	if (block.rigid) {
		D.tail<6>().setZero();
		if (!block.fixedPoints.empty()) {
			D.head<6>() = system.stiffness.topLeftCorner<6, 6>().llt().solve(system.force.head<6>());
		} else {
			D.head<3>() = system.force.head<3>().cwiseQuotient(system.stiffness.diagonal().head<3>());
			D.segment<3>(3) = system.stiffness.block<3, 3>(3, 3).llt().solve(system.force.segment<3>(3));
		}
		return D;
	}
	if (!block.fixedPoints.empty()) return system.stiffness.llt().solve(system.force);
	D.head<3>() = system.force.head<3>().cwiseQuotient(system.stiffness.diagonal().head<3>());
	D.tail<9>() = system.stiffness.block<9, 9>(3, 3).llt().solve(system.force.tail<9>());
	return D;
}

double largestVertexDisplacement(const Block& block, const Vector12& D) {
	// A non-finite solution is an unbounded displacement: +inf, never NaN,
	// which std::max and OpenMP's max reduction would silently drop (a NaN
	// solution then passed the step's finiteness check as 0 and wrote NaN
	// into every block; found with dt = 1e-300 s).
	constexpr double unbounded = std::numeric_limits<double>::infinity();
	if (!D.allFinite()) return unbounded;
	double largest = 0;
	for (const Vector3& x : block.vertices) {
		const double d = displacementAt(x - block.centroid, D).squaredNorm();
		if (std::isnan(d)) return unbounded;
		largest = std::max(largest, d);
	}
	return std::sqrt(largest);
}

BlockMotion blockMotion(const Block& block, const Vector12& D) {
	BlockMotion motion;
	motion.rotation = rotationFromVector(D.segment<3>(3));
	motion.deformation =
	    block.rigid ? motion.rotation : Matrix3((Matrix3::Identity() + strainTensor(D.segment<6>(6))) * motion.rotation);
	motion.oldCentroid = block.centroid;
	motion.newCentroid = block.centroid + D.head<3>();
	return motion;
}

void applyStep(Block& block, const Vector12& D, const Vector12& v0, double dt) {
	const BlockMotion move = blockMotion(block, D);
	const Matrix3& rotation = move.rotation;
	const Matrix3& deformation = move.deformation;
	const Vector3 newCentroid = move.newCentroid;

	for (Vector3& x : block.vertices) x = move(x);
	for (FixedPoint& point : block.fixedPoints) point.position = move(point.position);
	for (PointLoad& load : block.loads) load.position = move(load.position);
	block.centroid = newCentroid;
	block.rotation = (Eigen::Quaterniond(rotation) * block.rotation).normalized();

	if (block.rigid) {
		// Rigid motion: the volume is unchanged (det R = 1 up to round-off,
		// which is not applied), the second moments turn with the block;
		// stress, strain and strain rates stay exactly zero.
		block.secondMoment = rotation * block.secondMoment * rotation.transpose();
		block.velocity.head<6>() = (2 / dt) * D.head<6>() - v0.head<6>();
		block.velocity.tail<6>().setZero();
		return;
	}

	// An affine map x -> c' + L (x - c) maps the centroid to c' and scales
	// volume by det L; the second moments transform as det(L) L J L^T (exact).
	const double jacobian = deformation.determinant();
	block.volume *= jacobian;
	block.secondMoment = jacobian * deformation * block.secondMoment * deformation.transpose();

	// End velocity of the step; tensors follow the block's rotation.
	Vector12 velocity = (2 / dt) * D - v0;
	const Matrix3 strainRate = rotation * strainTensor(velocity.segment<6>(6)) * rotation.transpose();
	velocity.segment<6>(6) = strainVoigt(strainRate);
	block.velocity = velocity;

	const Vector6 strainIncrement = D.segment<6>(6);
	block.stress = stressVoigt(rotation * stressTensor(block.stress) * rotation.transpose()) + block.elasticity() * strainIncrement;
	block.strain = strainVoigt(rotation * strainTensor(block.strain) * rotation.transpose()) + strainIncrement;
	block.unsyncedStrain += strainIncrement.norm();
}

}  // namespace dda
