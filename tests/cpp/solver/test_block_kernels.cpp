// The 12x12 helpers of BlockKernels.hpp against Eigen's general products and
// against their algebra: the outer product bitwise as Eigen makes it, the
// products within round-off of Eigen's, the symmetric product reading only
// the lower triangle, the triangular solve leaving a residual at round-off.
// Random matrices, seed printed.
#include "dda/solver/BlockKernels.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

namespace dda {
namespace {

constexpr unsigned kSeed = 1126;

Matrix12 randomMatrix(std::mt19937& rng, double scale) {
	std::uniform_real_distribution<double> u(-1, 1);
	Matrix12 m;
	for (int i = 0; i < 144; ++i) m.data()[i] = scale * u(rng);
	return m;
}

Vector12 randomVector(std::mt19937& rng, double scale) {
	std::uniform_real_distribution<double> u(-1, 1);
	Vector12 v;
	for (int i = 0; i < 12; ++i) v[i] = scale * u(rng);
	return v;
}

// |a - b| within `ulps` round-offs of the sizes the entries are made of.
void expectClose(const Vector12& a, const Vector12& b, double size, const char* what, int trial) {
	for (int i = 0; i < 12; ++i)
		ASSERT_LE(std::abs(a[i] - b[i]), 64 * std::numeric_limits<double>::epsilon() * size)
		    << what << " entry " << i << " trial " << trial;
}

TEST(BlockKernels, ProductsAgreeWithEigen) {
	std::printf("seed %u\n", kSeed);
	std::mt19937 rng(kSeed);
	for (int trial = 0; trial < 500; ++trial) {
		const double scale = std::pow(10.0, static_cast<int>(rng() % 13) - 6);
		const Matrix12 m = randomMatrix(rng, scale);
		const Vector12 x = randomVector(rng, 1 / scale), y0 = randomVector(rng, 3);
		// Every product's entries are sums of 12 terms of size <= 1 (scale x 1/scale).
		const double size = 12 + 3;
		Vector12 y = y0;
		subtractProduct(y, m, x);
		expectClose(y, y0 - m * x, size, "y -= M x", trial);
		y = y0;
		addProduct(y, m, x);
		expectClose(y, y0 + m * x, size, "y += M x", trial);
		y = y0;
		subtractTransposedProduct(y, m, x);
		expectClose(y, y0 - m.transpose() * x, size, "y -= M^T x", trial);
		y = y0;
		addTransposedProduct(y, m, x);
		expectClose(y, y0 + m.transpose() * x, size, "y += M^T x", trial);
		// Symmetric from the lower triangle: the upper one holds NaN and is
		// never read.
		Matrix12 lower = m;
		for (int k = 1; k < 12; ++k)
			for (int i = 0; i < k; ++i) lower(i, k) = std::numeric_limits<double>::quiet_NaN();
		const Matrix12 full = m.selfadjointView<Eigen::Lower>();
		symmetricLowerProduct(y, lower, x);
		expectClose(y, full * x, 2 * size, "y = S x", trial);
		// The outer product: the same bits as Eigen's.
		Matrix12 outer = m, eigen = m;
		const Vector12 s = randomVector(rng, 5), v = randomVector(rng, 0.2);
		addOuterProduct(outer, s.data(), v.data());
		eigen.noalias() += s * v.transpose();
		for (int i = 0; i < 144; ++i) ASSERT_EQ(outer.data()[i], eigen.data()[i]) << "outer, trial " << trial;
	}
}

// X L^T = A to round-off for well and badly conditioned L (an LLT's factor of
// an SPD matrix whose diagonal spans `spread` decades), and the same X as
// Eigen's triangular solve to within the conditioning.
TEST(BlockKernels, TriangularSolveOnTheRightLeavesRoundoffResidual) {
	std::mt19937 rng(kSeed + 1);
	for (const double spread : {0.0, 4.0, 8.0})
		for (int trial = 0; trial < 100; ++trial) {
			const Matrix12 r = randomMatrix(rng, 1);
			Matrix12 spd = r * r.transpose();
			for (int i = 0; i < 12; ++i) spd(i, i) += std::pow(10.0, spread * i / 11.0);
			const Eigen::LLT<Matrix12> llt(spd);
			ASSERT_EQ(llt.info(), Eigen::Success);
			const Matrix12 a = randomMatrix(rng, 100);
			Matrix12 x = a;
			solveTransposedLowerOnTheRight(x, llt.matrixLLT());
			const Matrix12 l = llt.matrixL();
			const double residual = (x * l.transpose() - a).cwiseAbs().maxCoeff();
			const double size = (x.cwiseAbs() * l.transpose().cwiseAbs()).maxCoeff() + a.cwiseAbs().maxCoeff();
			ASSERT_LE(residual, 64 * std::numeric_limits<double>::epsilon() * size)
			    << "spread " << spread << " trial " << trial;
			Matrix12 eigen = a;
			llt.matrixU().solveInPlace<Eigen::OnTheRight>(eigen);
			const double condition = std::pow(10.0, 0.5 * spread) * 1e3;
			ASSERT_LE((x - eigen).cwiseAbs().maxCoeff(),
			          condition * std::numeric_limits<double>::epsilon() * eigen.cwiseAbs().maxCoeff())
			    << "spread " << spread << " trial " << trial;
		}
}

}  // namespace
}  // namespace dda
