#include "Displacement.hpp"

#include <array>

namespace dda {

namespace {
// B_k = dB/dd_k, the 3x9 rotation-and-strain columns of T for d = e_k.
const std::array<Eigen::Matrix<double, 3, 9>, 3>& strainRotationGradients() {
	static const std::array<Eigen::Matrix<double, 3, 9>, 3> gradients = [] {
		std::array<Eigen::Matrix<double, 3, 9>, 3> g;
		for (int k = 0; k < 3; ++k) g[k] = displacementMatrix(Vector3::Unit(k)).block<3, 9>(0, 3);
		return g;
	}();
	return gradients;
}
}  // namespace

Matrix12 massMatrix(double density, double volume, const Matrix3& secondMoment) {
	const auto& B = strainRotationGradients();
	Matrix12 M = Matrix12::Zero();
	M.block<3, 3>(0, 0) = (density * volume) * Matrix3::Identity();
	Eigen::Matrix<double, 9, 9> rotationStrain = Eigen::Matrix<double, 9, 9>::Zero();
	for (int k = 0; k < 3; ++k)
		for (int l = 0; l < 3; ++l) rotationStrain.noalias() += secondMoment(k, l) * B[k].transpose() * B[l];
	M.block<9, 9>(3, 3) = density * rotationStrain;
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
