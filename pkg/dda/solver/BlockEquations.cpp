#include "BlockEquations.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dda {

Vector12 restForce(const Block& block, const IntegratorSettings& settings) {
	Vector12 force = Vector12::Zero();
	if (!block.rigid) force.segment<6>(6) -= block.volume * block.stress;
	force.head<3>() += block.mass * settings.gravity;
	for (const FixedPoint& point : block.fixedPoints) {
		const Matrix3x12 T = displacementMatrix(point.position - block.centroid);
		force.noalias() += fixedPointStiffness(point, block, settings) * T.transpose() * (point.anchor - point.position);
	}
	for (const PointLoad& load : block.loads)
		force.noalias() += displacementMatrix(load.position - block.centroid).transpose() * load.force;
	if (block.rigid) force.tail<6>().setZero();
	return force;
}

Vector12 accelerationOf(const Block& block, const Vector12& force) {
	Vector12 a = Vector12::Zero();
	if (block.rigid)
		a.head<6>() = rigidMassMatrix(block.density(), block.volume, block.secondMoment).llt().solve(force.head<6>());
	else
		a = massMatrix(block.density(), block.volume, block.secondMoment).llt().solve(force);
	return a;
}

namespace {
// Newmark's inertia: K += (1 / (beta dt^2)) M, F += M (v0 / (beta dt) +
// (1 / (2 beta) - 1) a0); Shi's (beta = 1/2) written as before, (2/dt^2) M
// and (2/dt) M v0, so that its results stay bitwise those of earlier versions.
template <typename Mass, typename Stiffness, typename Force, typename Rates>
void addInertia(const Mass& mass, const Rates& v0, const Rates& a0, const IntegratorSettings& settings, double dt,
                Stiffness&& stiffness, Force&& force) {
	if (settings.shiScheme()) {
		stiffness.noalias() = (2 / (dt * dt)) * mass;
		force.noalias() = (2 / dt) * (mass * v0);
		return;
	}
	const double beta = settings.newmarkBeta;
	stiffness.noalias() = (1 / (beta * dt * dt)) * mass;
	force.noalias() = mass * ((1 / (beta * dt)) * v0 + (0.5 / beta - 1) * a0);
}
}  // namespace

void assembleBlock(const Block& block, const IntegratorSettings& settings, double dt, const Vector12& a0,
                   BlockSystem& system) {
	if (block.rigid) {
		assembleRigidBlock(block, settings, dt, a0, system);
		return;
	}
	const Vector12 v0 = startVelocity(block, settings);
	const Matrix12 mass = massMatrix(block.density(), block.volume, block.secondMoment);
	addInertia(mass, v0, a0, settings, dt, system.stiffness, system.force);

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

void assembleRigidBlock(const Block& block, const IntegratorSettings& settings, double dt, const Vector12& a0,
                        BlockSystem& system) {
	// Only the translation-rotation rows and columns are computed; the strain
	// part of the 12x12 system is zero and never read (solveBlock and
	// CoupledSystem take the first 6 unknowns of a rigid block).
	const Vector6 v0 = startVelocity(block, settings).head<6>();
	const Vector6 a06 = a0.head<6>();
	const Matrix6 mass = rigidMassMatrix(block.density(), block.volume, block.secondMoment);
	system.stiffness.setZero();
	system.force.setZero();
	auto stiffness = system.stiffness.topLeftCorner<6, 6>();
	auto force = system.force.head<6>();
	addInertia(mass, v0, a06, settings, dt, stiffness, force);
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

Vector12 endVelocity(const Vector12& D, const Vector12& v0, double dt) {
	// v0 + dt ((1 - gamma) a0 + gamma a1) with beta = gamma/2 is exactly this
	// (the positions follow the trapezoidal rule, D = dt (v0 + v1)/2).
	return (2 / dt) * D - v0;
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

void applyStep(Block& block, const Vector12& D, const Vector12& velocity) {
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
		block.velocity.head<6>() = velocity.head<6>();
		block.velocity.tail<6>().setZero();
		return;
	}

	// An affine map x -> c' + L (x - c) maps the centroid to c' and scales
	// volume by det L; the second moments transform as det(L) L J L^T (exact).
	const double jacobian = deformation.determinant();
	block.volume *= jacobian;
	block.secondMoment = jacobian * deformation * block.secondMoment * deformation.transpose();

	// End velocity of the step; tensors follow the block's rotation.
	block.velocity = velocity;
	const Matrix3 strainRate = rotation * strainTensor(velocity.segment<6>(6)) * rotation.transpose();
	block.velocity.segment<6>(6) = strainVoigt(strainRate);

	const Vector6 strainIncrement = D.segment<6>(6);
	block.stress = stressVoigt(rotation * stressTensor(block.stress) * rotation.transpose()) + block.elasticity() * strainIncrement;
	block.strain = strainVoigt(rotation * strainTensor(block.strain) * rotation.transpose()) + strainIncrement;
	block.unsyncedStrain += strainIncrement.norm();
}

}  // namespace dda
