#include "BlockEquations.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace dda {

namespace {
// The block's own loads in its first N unknowns (N = 12, or 6 for a rigid
// block's system) [N, N m, N m]: gravity, the fixed-point springs' pull
// toward their anchors and the point loads; with `stiffness` given, the
// springs' stiffness k T^T T [N/m] too. One definition for restForce and both
// assemblies, so the rest force is the assembled force at D = 0 without
// inertia by construction; the terms are added in one order (gravity,
// springs, loads) everywhere.
template <int N, typename Force, typename Stiffness>
void addOwnLoads(const Block& block, const IntegratorSettings& settings, Force&& force, Stiffness* stiffness) {
	if (!settings.gravity.isZero()) force.template head<3>() += block.mass * settings.gravity;
	for (const FixedPoint& point : block.fixedPoints) {
		const Eigen::Matrix<double, 3, N> T = displacementMatrix(point.position - block.centroid).template leftCols<N>();
		const double k = fixedPointStiffness(point, block, settings);
		if (stiffness) stiffness->noalias() += k * T.transpose() * T;
		force.noalias() += k * T.transpose() * (point.anchor - point.position);
	}
	for (const PointLoad& load : block.loads)
		force.noalias() +=
		    displacementMatrix(load.position - block.centroid).template leftCols<N>().transpose() * load.force;
}
}  // namespace

double strainViscosity(const Block& block, double zeta) {
	if (zeta <= 0 || block.rigid) return 0;
	// The second moments' largest eigenvalue (3x3, closed form) per unit volume [m^2].
	Eigen::SelfAdjointEigenSolver<Matrix3> moments;
	moments.computeDirect(block.secondMoment, Eigen::EigenvaluesOnly);
	const double j = moments.eigenvalues()(2) / block.volume;
	const double shearModulus = block.material.young / (2 * (1 + block.material.poisson));
	const double omega = std::sqrt(2 * shearModulus / (block.density() * j));
	return 2 * zeta / omega;
}

Vector12 restForce(const Block& block, const IntegratorSettings& settings) {
	Vector12 force = Vector12::Zero();
	if (!block.rigid) force.segment<6>(6) -= block.volume * block.stress;
	addOwnLoads<12>(block, settings, force, static_cast<Matrix12*>(nullptr));
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

	system.stiffness.block<6, 6>(6, 6).noalias() += block.referenceVolume() * block.elasticity();
	if (settings.strainDamping > 0)
		system.stiffness.block<6, 6>(6, 6).noalias() +=
		    (strainViscosity(block, settings.strainDamping) / (settings.newmarkGamma * dt) * block.referenceVolume()) *
		    block.elasticity();
	system.force.segment<6>(6).noalias() -= block.volume * block.stress;

	addOwnLoads<12>(block, settings, system.force, &system.stiffness);
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
	addOwnLoads<6>(block, settings, force, &stiffness);
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
	return largestVertexDisplacement(block.vertices, block.centroid, D);
}

double largestVertexDisplacement(const std::vector<Vector3>& vertices, const Vector3& centroid, const Vector12& D) {
	// A non-finite solution is an unbounded displacement: +inf, never NaN,
	// which std::max and OpenMP's max reduction would silently drop (a NaN
	// solution then passed the step's finiteness check as 0 and wrote NaN
	// into every block; found with dt = 1e-300 s).
	constexpr double unbounded = std::numeric_limits<double>::infinity();
	if (!D.allFinite()) return unbounded;
	double largest = 0;
	for (const Vector3& x : vertices) {
		const double d = displacementAt(x - centroid, D).squaredNorm();
		if (std::isnan(d)) return unbounded;
		largest = std::max(largest, d);
	}
	return std::sqrt(largest);
}

BlockMotion blockMotion(const Block& block, const Vector12& D) {
	BlockMotion motion;
	motion.rotation = rotationFromVector(D.segment<3>(3));
	motion.deformation =
	    block.rigid ? motion.rotation : Matrix3(motion.rotation * (Matrix3::Identity() + strainTensor(D.segment<6>(6))));
	motion.oldCentroid = block.centroid;
	motion.newCentroid = block.centroid + D.head<3>();
	return motion;
}

void movePart(Block& part, const Block& body, const BlockMotion& move, const Vector12& D) {
	for (Vector3& x : part.vertices) x = move(x);
	part.centroid = move(part.centroid);
	part.rotation = body.rotation;
	// As applyStep moves the body's mass properties (a rigid block: R J R^T,
	// the volume kept).
	const double jacobian = body.rigid ? 1.0 : move.deformation.determinant();
	part.volume *= jacobian;
	part.secondMoment = jacobian * move.deformation * part.secondMoment * move.deformation.transpose();
	if (!body.rigid) part.unsyncedStrain += D.segment<6>(6).norm();
}

Vector12 transportedRates(const Vector12& velocity, const Matrix3& rotation, const Matrix3& stretch) {
	// Within a step the block's points move as x = c + A(t) y, y their
	// offsets at the step's start, A = I + [r]x + S linear in the unknowns,
	// so the rates' kinetic energy 1/2 tr(A' J A'^T) (J the mass-weighted
	// second moments at the start) is the step's mass matrix exactly. The
	// accepted step maps y to y' = R U y (U = I + S); the velocity gradient
	// L' = R A' U^-1 R^T at the new offsets y' gives
	//   tr(L' J' L'^T) = tr(R A' U^-1 R^T R U J U^T R^T R U^-T A'^T R^T) = tr(A' J A'^T),
	// J' = R U J U^T R^T the new second moments: the kinetic energy carries
	// over exactly. Without strain (U = I) it turns the spin and strain rates
	// with the block (a spin about a fixed axis is unchanged).
	Matrix3 rate = strainTensor(velocity.segment<6>(6));
	const Vector3 w = velocity.segment<3>(3);
	rate(0, 1) -= w.z(); rate(1, 0) += w.z();
	rate(0, 2) += w.y(); rate(2, 0) -= w.y();
	rate(1, 2) -= w.x(); rate(2, 1) += w.x();
	const Matrix3 L = rotation * stretch.transpose().partialPivLu().solve(rate.transpose()).transpose() * rotation.transpose();
	Vector12 carried = velocity;
	carried.segment<3>(3) = 0.5 * Vector3(L(2, 1) - L(1, 2), L(0, 2) - L(2, 0), L(1, 0) - L(0, 1));
	carried.segment<6>(6) = strainVoigt(0.5 * (L + L.transpose()));
	return carried;
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
		// which is not applied), the second moments turn with the block, and
		// so does its angular velocity (transportedRates); stress, strain and
		// strain rates stay exactly zero.
		block.secondMoment = rotation * block.secondMoment * rotation.transpose();
		block.velocity.head<3>() = velocity.head<3>();
		block.velocity.segment<3>(3) = rotation * velocity.segment<3>(3);
		block.velocity.tail<6>().setZero();
		return;
	}

	// An affine map x -> c' + L (x - c) maps the centroid to c' and scales
	// volume by det L; the second moments transform as det(L) L J L^T (exact).
	const double startVolume = block.volume;
	const double jacobian = deformation.determinant();
	block.volume *= jacobian;
	block.secondMoment = jacobian * deformation * block.secondMoment * deformation.transpose();

	// End velocity of the step, carried to the block's new configuration.
	block.velocity = transportedRates(velocity, rotation, Matrix3::Identity() + strainTensor(D.segment<6>(6)));

	// Kirchhoff stress tau = (V / V0) sigma: tau1 = R (tau0 + E eps) R^T
	// ("Finite strain" in BlockEquations.hpp); the state keeps sigma1 = (V0 /
	// V1) tau1. The strain increment is added in the start frame, then turned.
	const Vector6 strainIncrement = D.segment<6>(6);
	const double referenceVolume = block.referenceVolume();
	const Vector6 kirchhoff = (startVolume / referenceVolume) * block.stress + block.elasticity() * strainIncrement;
	block.stress = (referenceVolume / block.volume) * stressVoigt(rotation * stressTensor(kirchhoff) * rotation.transpose());
	block.strain = strainVoigt(rotation * strainTensor(block.strain + strainIncrement) * rotation.transpose());
	block.unsyncedStrain += strainIncrement.norm();
}

}  // namespace dda
