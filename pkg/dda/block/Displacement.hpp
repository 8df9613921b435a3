// The first-order displacement function of a 3D DDA block (Shi; Wu et al. 2014,
// Eq. 1-3) and the block matrices that follow from it.
//
// Unknowns of one block, in this order (SI units):
//   D = (u0, v0, w0,  r1, r2, r3,  ex, ey, ez,  gxy, gyz, gzx)
//        translation  rotation     normal       engineering shear
//        of the       angles       strains      strains
//        centroid [m] [rad]        [-]          [-]
// A point at offset d = x - c from the centroid c moves by
//   u(d) = t + r x d + E(eps) d,
// where E(eps) is the symmetric strain tensor [[ex, gxy/2, gzx/2],
// [gxy/2, ey, gyz/2], [gzx/2, gyz/2, ez]]. So u = T(d) D with the 3x12 matrix
// T(d) = [ I | -[d]x | S(d) ]. Every column of T is linear in d, which makes the
// block's mass matrix a function of its volume and of the second moments
// J = integral of d d^T dV alone (see massMatrix).
#pragma once

#include "dda/core/Types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dda {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector12 = Eigen::Matrix<double, 12, 1>;
using Matrix12 = Eigen::Matrix<double, 12, 12>;
using Matrix3x12 = Eigen::Matrix<double, 3, 12>;

using Matrix3x6 = Eigen::Matrix<double, 3, 6>;

constexpr int kBlockDofs = 12;
constexpr int kRigidBlockDofs = 6;  // translation and rotation only (a rigid block)

// T(d): displacement of the point at offset d from the centroid per unit of each unknown.
inline Matrix3x12 displacementMatrix(const Vector3& d) {
	Matrix3x12 T = Matrix3x12::Zero();
	T.block<3, 3>(0, 0).setIdentity();
	// rotation r x d
	T(0, 4) = d.z();  T(0, 5) = -d.y();
	T(1, 3) = -d.z(); T(1, 5) = d.x();
	T(2, 3) = d.y();  T(2, 4) = -d.x();
	// normal strains
	T(0, 6) = d.x(); T(1, 7) = d.y(); T(2, 8) = d.z();
	// engineering shear strains: gxy, gyz, gzx
	T(0, 9) = 0.5 * d.y();  T(1, 9) = 0.5 * d.x();
	T(1, 10) = 0.5 * d.z(); T(2, 10) = 0.5 * d.y();
	T(0, 11) = 0.5 * d.z(); T(2, 11) = 0.5 * d.x();
	return T;
}

// (s T(d))^T g: what a point vector g (a force, a gap's gradient) at offset
// d from the centroid gives each unknown, scaled by s. The same as
// (s * displacementMatrix(d).transpose()) * g, each entry's products in the
// same order, with T's zero entries left out (a sum can then differ only in
// the sign of a zero).
inline Vector12 displacementTransposeTimes(const Vector3& d, const Vector3& g, double s) {
	const double x = s * d.x(), y = s * d.y(), z = s * d.z();
	const double hx = s * (0.5 * d.x()), hy = s * (0.5 * d.y()), hz = s * (0.5 * d.z());
	Vector12 out;
	out << s * g(0), s * g(1), s * g(2),
	       -z * g(1) + y * g(2), z * g(0) + -x * g(2), -y * g(0) + x * g(1),
	       x * g(0), y * g(1), z * g(2),
	       hy * g(0) + hx * g(1), hz * g(1) + hy * g(2), hz * g(0) + hx * g(2);
	return out;
}

// Displacement of the point at offset d for the unknowns D (same as T(d) D, cheaper).
inline Vector3 displacementAt(const Vector3& d, const Vector12& D) {
	const Vector3 t = D.segment<3>(0), r = D.segment<3>(3);
	Matrix3 strain;
	strain << D(6), 0.5 * D(9), 0.5 * D(11),
	          0.5 * D(9), D(7), 0.5 * D(10),
	          0.5 * D(11), 0.5 * D(10), D(8);
	return t + r.cross(d) + strain * d;
}

// Symmetric strain tensor from the Voigt vector (ex, ey, ez, gxy, gyz, gzx).
inline Matrix3 strainTensor(const Eigen::Ref<const Vector6>& e) {
	Matrix3 s;
	s << e(0), 0.5 * e(3), 0.5 * e(5),
	     0.5 * e(3), e(1), 0.5 * e(4),
	     0.5 * e(5), 0.5 * e(4), e(2);
	return s;
}

// Engineering-strain Voigt vector of a symmetric tensor (inverse of strainTensor).
inline Vector6 strainVoigt(const Matrix3& s) {
	Vector6 e;
	e << s(0, 0), s(1, 1), s(2, 2), 2 * s(0, 1), 2 * s(1, 2), 2 * s(2, 0);
	return e;
}

// Stress tensor from (sxx, syy, szz, sxy, syz, szx) [Pa] and back.
inline Matrix3 stressTensor(const Vector6& s) {
	Matrix3 t;
	t << s(0), s(3), s(5),
	     s(3), s(1), s(4),
	     s(5), s(4), s(2);
	return t;
}
inline Vector6 stressVoigt(const Matrix3& t) {
	Vector6 s;
	s << t(0, 0), t(1, 1), t(2, 2), t(0, 1), t(1, 2), t(2, 0);
	return s;
}

// Consistent mass matrix M = rho * integral of T^T T dV over the block
// [kg, kg m, kg m^2 in the respective blocks]. With T = [I | B(d)], B linear in d
// and the integral of d over the block zero (d is measured from the centroid):
//   M = rho [[V I, 0], [0, sum_kl J_kl B_k^T B_l]],  B_k = dB/dd_k.
Matrix12 massMatrix(double density, double volume, const Matrix3& secondMoment);

// The translation-rotation block of massMatrix (its top-left 6x6, computed
// alone and bitwise equal to it): rho [[V I, 0], [0, tr(J) I - J]], the mass
// matrix of a rigid block.
Matrix6 rigidMassMatrix(double density, double volume, const Matrix3& secondMoment);

// Isotropic linear elastic stiffness in Voigt form (engineering shear) [Pa].
// Requires young > 0 and -1 < poisson < 0.5 (checked by the caller).
Matrix6 elasticityMatrix(double young, double poisson);

// Exact rotation by the rotation vector r (angle |r| about r/|r|), Rodrigues.
inline Matrix3 rotationFromVector(const Vector3& r) {
	const double angle = r.norm();
	if (angle == 0) return Matrix3::Identity();
	return Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
}

}  // namespace dda
