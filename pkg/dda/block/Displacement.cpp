#include "Displacement.hpp"

#include <array>

namespace dda {

namespace {
using Matrix9 = Eigen::Matrix<double, 9, 9>;
// With B_k = dB/dd_k (the 3x9 rotation-and-strain columns of T for d = e_k),
// the rotation-strain block of the mass matrix is sum_kl J_kl B_k^T B_l. J is
// symmetric, so six constant matrices suffice: P_kk = B_k^T B_k and
// P_kl = B_k^T B_l + B_l^T B_k for k < l, in the order xx, yy, zz, xy, yz, zx.
const std::array<Matrix9, 6>& secondMomentCoefficients() {
	static const std::array<Matrix9, 6> coefficients = [] {
		std::array<Eigen::Matrix<double, 3, 9>, 3> B;
		for (int k = 0; k < 3; ++k) B[k] = displacementMatrix(Vector3::Unit(k)).block<3, 9>(0, 3);
		std::array<Matrix9, 6> P;
		for (int k = 0; k < 3; ++k) P[k] = B[k].transpose() * B[k];
		const int pairs[3][2] = {{0, 1}, {1, 2}, {2, 0}};
		for (int p = 0; p < 3; ++p) {
			const int k = pairs[p][0], l = pairs[p][1];
			P[3 + p] = B[k].transpose() * B[l] + B[l].transpose() * B[k];
		}
		return P;
	}();
	return coefficients;
}
}  // namespace

Matrix12 massMatrix(double density, double volume, const Matrix3& J) {
	const auto& P = secondMomentCoefficients();
	Matrix12 M = Matrix12::Zero();
	M.block<3, 3>(0, 0).diagonal().setConstant(density * volume);
	M.block<9, 9>(3, 3) = density * (J(0, 0) * P[0] + J(1, 1) * P[1] + J(2, 2) * P[2] + J(0, 1) * P[3] +
	                                 J(1, 2) * P[4] + J(2, 0) * P[5]);
	return M;
}

Matrix6 rigidMassMatrix(double density, double volume, const Matrix3& J) {
	// The same sum as massMatrix, over the rotation rows and columns only
	// (each P_k's top-left 3x3), so the two agree to the last bit.
	const auto& P = secondMomentCoefficients();
	Matrix6 M = Matrix6::Zero();
	M.block<3, 3>(0, 0).diagonal().setConstant(density * volume);
	M.block<3, 3>(3, 3) = density * (J(0, 0) * P[0].topLeftCorner<3, 3>() + J(1, 1) * P[1].topLeftCorner<3, 3>() +
	                                 J(2, 2) * P[2].topLeftCorner<3, 3>() + J(0, 1) * P[3].topLeftCorner<3, 3>() +
	                                 J(1, 2) * P[4].topLeftCorner<3, 3>() + J(2, 0) * P[5].topLeftCorner<3, 3>());
	return M;
}

Matrix6 elasticityMatrix(double young, double poisson) {
	const double lambda = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
	const double shear = young / (2 * (1 + poisson));
	Matrix6 E = Matrix6::Zero();
	E.block<3, 3>(0, 0).setConstant(lambda);
	for (int i = 0; i < 3; ++i) {
		E(i, i) = lambda + 2 * shear;
		E(i + 3, i + 3) = shear;
	}
	return E;
}

}  // namespace dda
