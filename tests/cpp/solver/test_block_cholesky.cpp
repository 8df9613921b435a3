// BlockCholesky (the coupled system's sparse factorisation) against a dense
// Cholesky of the same matrix: random block patterns (seeds printed by the
// failure messages), from chains to dense clusters, with rigid blocks whose
// strain unknowns are struck out of the dense reference; a matrix that is not
// positive definite is refused; the factor depends on the values alone.
#include "dda/solver/BlockCholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>
#include <set>
#include <utility>
#include <vector>

using namespace dda;

namespace {

struct Problem {
	int blocks = 0;
	std::vector<std::pair<int, int>> links;
	std::vector<Matrix12> diagonal, offDiagonal;
	std::vector<int> sizes;
	std::vector<Vector12> rhs;
};

// A random SPD block matrix: links with probability `density`, plus a chain
// through every block (one component); symmetric, diagonally dominant.
Problem randomProblem(unsigned seed, int blocks, double density, double rigidShare) {
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
	Problem p;
	p.blocks = blocks;
	std::set<std::pair<int, int>> links;
	for (int a = 0; a + 1 < blocks; ++a) links.emplace(a, a + 1);
	for (int a = 0; a < blocks; ++a)
		for (int b = a + 2; b < blocks; ++b)
			if (unit(rng) < density) links.emplace(a, b);
	p.links.assign(links.begin(), links.end());
	std::shuffle(p.links.begin(), p.links.end(), rng);   // any link order
	std::vector<double> degree(blocks, 0);
	for (auto [a, b] : p.links) {
		Matrix12 m;
		for (int i = 0; i < 144; ++i) m(i / 12, i % 12) = u(rng);
		p.offDiagonal.push_back(m);
		degree[a] += 12;
		degree[b] += 12;
	}
	for (int k = 0; k < blocks; ++k) {
		Matrix12 r;
		for (int i = 0; i < 144; ++i) r(i / 12, i % 12) = u(rng);
		p.diagonal.push_back(r * r.transpose() + (degree[k] + 1) * Matrix12::Identity());
		p.sizes.push_back(unit(rng) < rigidShare ? kRigidBlockDofs : kBlockDofs);
		Vector12 f;
		for (int i = 0; i < 12; ++i) f(i) = u(rng);
		p.rhs.push_back(f);
	}
	return p;
}

// The dense solution of the system restricted to the free unknowns (a rigid
// block's strain unknowns struck out), per block (struck ones zero).
std::vector<Vector12> denseSolution(const Problem& p) {
	std::vector<int> free;
	for (int k = 0; k < p.blocks; ++k)
		for (int i = 0; i < p.sizes[k]; ++i) free.push_back(12 * k + i);
	const int n = 12 * p.blocks, m = static_cast<int>(free.size());
	Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
	for (int k = 0; k < p.blocks; ++k) K.block<12, 12>(12 * k, 12 * k) = p.diagonal[k];
	for (std::size_t l = 0; l < p.links.size(); ++l) {
		const auto [lo, hi] = p.links[l];
		K.block<12, 12>(12 * lo, 12 * hi) = p.offDiagonal[l];
		K.block<12, 12>(12 * hi, 12 * lo) = p.offDiagonal[l].transpose();
	}
	Eigen::MatrixXd Kr(m, m);
	Eigen::VectorXd Fr(m);
	for (int i = 0; i < m; ++i) {
		Fr(i) = p.rhs[free[i] / 12](free[i] % 12);
		for (int j = 0; j < m; ++j) Kr(i, j) = K(free[i], free[j]);
	}
	const Eigen::VectorXd x = Kr.llt().solve(Fr);
	std::vector<Vector12> out(p.blocks, Vector12::Zero());
	for (int i = 0; i < m; ++i) out[free[i] / 12](free[i] % 12) = x(i);
	return out;
}

}  // namespace

TEST(BlockCholesky, SolvesRandomBlockSystemsAsADenseCholesky) {
	const struct {
		int blocks;
		double density, rigidShare;
	} cases[] = {{2, 0, 0}, {5, 0, 0.5}, {12, 0.1, 0}, {30, 0.05, 0.3}, {49, 0.37, 0}, {40, 0.8, 0.2}, {60, 0.02, 1.0}};
	unsigned seed = 100;
	for (const auto& c : cases) {
		for (int trial = 0; trial < 3; ++trial, ++seed) {
			const Problem p = randomProblem(seed, c.blocks, c.density, c.rigidShare);
			BlockCholesky cholesky;
			cholesky.analyse(p.blocks, p.links);
			ASSERT_TRUE(cholesky.factorize(p.diagonal.data(), p.offDiagonal.data(), p.sizes.data())) << "seed " << seed;
			std::vector<Vector12> x = p.rhs;
			cholesky.solve(x.data());
			const std::vector<Vector12> expected = denseSolution(p);
			double scale = 0;
			for (const Vector12& e : expected) scale = std::max(scale, e.cwiseAbs().maxCoeff());
			for (int k = 0; k < p.blocks; ++k) {
				EXPECT_LE((x[k] - expected[k]).cwiseAbs().maxCoeff(), 1e-12 * scale) << "seed " << seed << " block " << k;
				if (p.sizes[k] == kRigidBlockDofs)
					EXPECT_EQ(Vector6(x[k].tail<6>().cwiseAbs()), Vector6::Zero()) << "seed " << seed << " block " << k;
			}
		}
	}
}

TEST(BlockCholesky, RefactorisingGivesBitwiseTheFreshFactor) {
	// One analysis, many value sets (what CoupledSystem's kept analyses do):
	// each solve equals that of a fresh analysis of the same matrix, bit for bit.
	BlockCholesky kept;
	const Problem first = randomProblem(7, 25, 0.2, 0.2);
	kept.analyse(first.blocks, first.links);
	for (unsigned seed = 7; seed < 12; ++seed) {
		Problem p = randomProblem(seed, 25, 0.2, 0.2);
		p.links = first.links;   // same pattern, new values
		p.offDiagonal.resize(p.links.size(), Matrix12::Identity() * 0.01);
		p.sizes = first.sizes;
		BlockCholesky fresh;
		fresh.analyse(p.blocks, p.links);
		ASSERT_TRUE(kept.factorize(p.diagonal.data(), p.offDiagonal.data(), p.sizes.data()));
		ASSERT_TRUE(fresh.factorize(p.diagonal.data(), p.offDiagonal.data(), p.sizes.data()));
		std::vector<Vector12> x = p.rhs, y = p.rhs;
		kept.solve(x.data());
		fresh.solve(y.data());
		for (int k = 0; k < p.blocks; ++k) EXPECT_EQ(x[k], y[k]) << "seed " << seed << " block " << k;
	}
}

TEST(BlockCholesky, RefusesAMatrixThatIsNotPositiveDefinite) {
	Problem p = randomProblem(3, 6, 0.5, 0);
	// Block 4's diagonal made indefinite after its neighbours' updates: a
	// large coupling to block 3 with a small diagonal.
	p.diagonal[4] = Matrix12::Identity() * 1e-3;
	BlockCholesky cholesky;
	cholesky.analyse(p.blocks, p.links);
	EXPECT_FALSE(cholesky.factorize(p.diagonal.data(), p.offDiagonal.data(), p.sizes.data()));
	p.diagonal[2](5, 5) = -1;   // and one that is not even positive on its diagonal
	EXPECT_FALSE(cholesky.factorize(p.diagonal.data(), p.offDiagonal.data(), p.sizes.data()));
}
