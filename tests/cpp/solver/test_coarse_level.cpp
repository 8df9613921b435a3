// The iterative path's coarse level (AffineCoarseSpace.hpp). Oracles: a
// field affine over the whole system lies in the coarse space, so the coarse
// correction of its residual K x returns x itself (exact up to round-off);
// the dense solution of a static lattice of elastic blocks joined by penalty
// springs (the system of a settling step, no mass term); bitwise equality
// across thread counts. Seeds are in the test names' loops.
#include "dda/solver/AffineCoarseSpace.hpp"
#include "dda/solver/BlockConjugateGradient.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cstring>
#include <random>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace dda;

namespace {

// Blocks on an nx x ny x nz grid of spacing h (centroids jittered by up to
// `jitter`), each linked to its face neighbours. K: each block's elastic
// stiffness V C on its strains (E = 1e9 Pa, nu = 0.25), a penalty spring
// p = 40 E h in every direction at four points of each shared face, and the
// same springs to the ground under the bottom layer. No mass term: the
// system of a static step, whose block-Jacobi conditioning grows with the
// grid's size.
struct Lattice {
	int blocks = 0;
	std::vector<Vector3> centroids;
	std::vector<int> sizes;
	std::vector<Matrix12> diagonal, offDiagonal;
	std::vector<std::pair<int, int>> links;

	Lattice(int nx, int ny, int nz, double h, double jitter, double rigidShare, unsigned seed) {
		std::mt19937 rng(seed);
		std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
		auto index = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
		blocks = nx * ny * nz;
		const double young = 1e9, penalty = 40 * young * h;
		Matrix12 elastic = Matrix12::Zero();
		elastic.bottomRightCorner<6, 6>() = h * h * h * elasticityMatrix(young, 0.25);
		for (int k = 0; k < nz; ++k)
			for (int j = 0; j < ny; ++j)
				for (int i = 0; i < nx; ++i) {
					centroids.push_back(Vector3(i, j, k) * h + jitter * Vector3(u(rng), u(rng), u(rng)));
					sizes.push_back(unit(rng) < rigidShare ? kRigidBlockDofs : kBlockDofs);
					diagonal.push_back(elastic);
				}
		// Springs at the four corners (inset by 0.4 h) of the face whose
		// centre is `face` and normal axis `axis`, between block a and block
		// b (b < 0: the ground).
		auto springs = [&](int a, int b, const Vector3& face, int axis) {
			for (int corner = 0; corner < 4; ++corner) {
				Vector3 point = face;
				point((axis + 1) % 3) += (corner & 1 ? 0.4 : -0.4) * h;
				point((axis + 2) % 3) += (corner & 2 ? 0.4 : -0.4) * h;
				const Matrix3x12 ta = displacementMatrix(point - centroids[a]);
				diagonal[a] += penalty * ta.transpose() * ta;
				if (b < 0) continue;
				const Matrix3x12 tb = displacementMatrix(point - centroids[b]);
				diagonal[b] += penalty * tb.transpose() * tb;
				offDiagonal.back() -= penalty * ta.transpose() * tb;
			}
		};
		for (int k = 0; k < nz; ++k)
			for (int j = 0; j < ny; ++j)
				for (int i = 0; i < nx; ++i) {
					const int a = index(i, j, k);
					if (k == 0) springs(a, -1, centroids[a] - 0.5 * h * Vector3::UnitZ(), 2);
					const int next[3] = {i + 1 < nx ? index(i + 1, j, k) : -1, j + 1 < ny ? index(i, j + 1, k) : -1,
					                     k + 1 < nz ? index(i, j, k + 1) : -1};
					for (int axis = 0; axis < 3; ++axis) {
						if (next[axis] < 0) continue;
						links.emplace_back(a, next[axis]);
						offDiagonal.push_back(Matrix12::Zero());
						springs(a, next[axis], 0.5 * (centroids[a] + centroids[next[axis]]), axis);
					}
				}
		// Sorted by (lo, hi), as the solver takes them.
		std::vector<int> order(links.size());
		for (std::size_t l = 0; l < order.size(); ++l) order[l] = static_cast<int>(l);
		std::sort(order.begin(), order.end(), [&](int x, int y) { return links[x] < links[y]; });
		std::vector<std::pair<int, int>> sortedLinks;
		std::vector<Matrix12> sortedBlocks;
		for (int l : order) {
			sortedLinks.push_back(links[l]);
			sortedBlocks.push_back(offDiagonal[l]);
		}
		links.swap(sortedLinks);
		offDiagonal.swap(sortedBlocks);
	}

	BlockConjugateGradient::Matrix matrix() const {
		BlockConjugateGradient::Matrix m;
		m.blocks = blocks;
		m.diagonal = diagonal.data();
		m.offDiagonal = offDiagonal.data();
		m.links = links.data();
		m.linkCount = static_cast<int>(links.size());
		m.sizes = sizes.data();
		m.centroids = centroids.data();
		return m;
	}

	// y = K x, restricted (a rigid block's strain rows zero).
	std::vector<Vector12> times(const std::vector<Vector12>& x) const {
		std::vector<Vector12> y(blocks);
		for (int k = 0; k < blocks; ++k) y[k] = diagonal[k] * x[k];
		for (std::size_t l = 0; l < links.size(); ++l) {
			const auto [lo, hi] = links[l];
			y[lo] += offDiagonal[l] * x[hi];
			y[hi] += offDiagonal[l].transpose() * x[lo];
		}
		for (int k = 0; k < blocks; ++k)
			if (sizes[k] != kBlockDofs) y[k].tail<6>().setZero();
		return y;
	}

	// Block k's unknowns for the field of unknowns `field` at `origin`: the
	// field's translation at its centroid, the same rotation and strain.
	Vector12 affine(int k, const Vector12& field, const Vector3& origin) const {
		Vector12 d = field;
		d.head<3>() = displacementMatrix(centroids[k] - origin) * field;
		if (sizes[k] != kBlockDofs) d.tail<6>().setZero();
		return d;
	}
};

AffineCoarseSpace::Fine fineOf(const Lattice& lattice, std::vector<int>& rows, std::vector<int>& neighbours) {
	std::vector<std::vector<int>> adjacent(lattice.blocks);
	for (auto [lo, hi] : lattice.links) {
		adjacent[lo].push_back(hi);
		adjacent[hi].push_back(lo);
	}
	rows.assign(1, 0);
	neighbours.clear();
	for (auto& a : adjacent) {
		std::sort(a.begin(), a.end());
		neighbours.insert(neighbours.end(), a.begin(), a.end());
		rows.push_back(static_cast<int>(neighbours.size()));
	}
	AffineCoarseSpace::Fine fine;
	fine.matrix = lattice.matrix();
	fine.rows = rows.data();
	fine.neighbours = neighbours.data();
	return fine;
}

double largestRelativeError(const std::vector<Vector12>& x, const std::vector<Vector12>& expected) {
	double error = 0, scale = 0;
	for (std::size_t k = 0; k < x.size(); ++k) {
		error = std::max(error, (x[k] - expected[k]).lpNorm<Eigen::Infinity>());
		scale = std::max(scale, expected[k].lpNorm<Eigen::Infinity>());
	}
	return error / scale;
}

}  // namespace

// P Kc^-1 P^T K x = x for every x in the coarse space; a field affine over
// the whole lattice is in it, whatever the grouping. Deformable blocks: any
// affine field; with rigid blocks (a third of them): rigid-body motions
// (their strains are not unknowns). The largest lattice has more first
// groups than the coarse system may hold, so its groups are grouped again.
TEST(CoarseLevel, ReproducesAffineFieldsExactly) {
	struct Case {
		int nx, ny, nz;
		double rigidShare;
		unsigned seed;
	};
	for (const Case c : {Case{6, 5, 4, 0.0, 1u}, Case{7, 6, 5, 0.35, 2u}, Case{20, 20, 10, 0.0, 3u}}) {
		SCOPED_TRACE("lattice " + std::to_string(c.nx) + "x" + std::to_string(c.ny) + "x" + std::to_string(c.nz) +
		             ", seed " + std::to_string(c.seed));
		const Lattice lattice(c.nx, c.ny, c.nz, 1.0, 0.2, c.rigidShare, c.seed);
		std::vector<int> rows, neighbours;
		AffineCoarseSpace coarse;
		ASSERT_TRUE(coarse.prepare(fineOf(lattice, rows, neighbours)));
		EXPECT_GT(coarse.aggregates(), 1);
		EXPECT_LE(coarse.aggregates(), 400);
		std::mt19937 rng(c.seed);
		std::uniform_real_distribution<double> u(-1, 1);
		Vector12 field;
		for (int i = 0; i < 12; ++i) field(i) = 1e-3 * u(rng);
		if (c.rigidShare > 0) field.tail<6>().setZero();
		const Vector3 origin(u(rng), u(rng), u(rng));
		std::vector<Vector12> x(lattice.blocks);
		for (int k = 0; k < lattice.blocks; ++k) x[k] = lattice.affine(k, field, origin);
		std::vector<Vector12> z(lattice.blocks, Vector12::Zero());
		coarse.addCorrection(lattice.times(x), z, false);
		EXPECT_LT(largestRelativeError(z, x), 1e-8);
	}
}

// On static lattices (no mass term; 6x6x6 and 10x10x8 blocks, one with
// rigid blocks) the coarse level reaches the backward error asked in fewer
// than half block Jacobi's iterations, and both agree with the dense
// solution within the tolerance times the system's conditioning.
TEST(CoarseLevel, HalvesTheIterationsOfAStaticLattice) {
	struct Case {
		int n, nz;
		double rigidShare;
		unsigned seed;
	};
	for (const Case c : {Case{6, 6, 0.0, 4u}, Case{10, 8, 0.2, 5u}}) {
		SCOPED_TRACE("lattice seed " + std::to_string(c.seed));
		const Lattice lattice(c.n, c.n, c.nz, 1.0, 0.1, c.rigidShare, c.seed);
		std::mt19937 rng(c.seed);
		std::uniform_real_distribution<double> u(-1, 1);
		std::vector<Vector12> b(lattice.blocks);
		for (Vector12& v : b)
			for (int i = 0; i < 12; ++i) v(i) = 1e6 * u(rng);
		int iterations[2];
		std::vector<Vector12> x[2];
		for (int coarse : {0, 1}) {
			BlockConjugateGradient solver;
			ASSERT_TRUE(solver.prepare(lattice.matrix(), 1 << 30, coarse ? 2 : 0));
			EXPECT_EQ(solver.coarseAggregates() > 0, coarse == 1);
			x[coarse].assign(lattice.blocks, Vector12::Zero());
			ASSERT_TRUE(solver.solve(b.data(), x[coarse].data(), 1e-12, 5000));
			iterations[coarse] = solver.iterations();
		}
		EXPECT_LT(2 * iterations[1], iterations[0]) << iterations[1] << " against " << iterations[0];
		if (lattice.blocks <= 216) {
			// The dense solution of the restricted system.
			const int n = 12 * lattice.blocks;
			Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
			Eigen::VectorXd rhs(n);
			for (int k = 0; k < lattice.blocks; ++k) {
				dense.block<12, 12>(12 * k, 12 * k) = lattice.diagonal[k];
				rhs.segment<12>(12 * k) = b[k];
			}
			for (std::size_t l = 0; l < lattice.links.size(); ++l) {
				const auto [lo, hi] = lattice.links[l];
				dense.block<12, 12>(12 * lo, 12 * hi) = lattice.offDiagonal[l];
				dense.block<12, 12>(12 * hi, 12 * lo) = lattice.offDiagonal[l].transpose();
			}
			const Eigen::VectorXd solution = dense.llt().solve(rhs);
			std::vector<Vector12> expected(lattice.blocks);
			for (int k = 0; k < lattice.blocks; ++k) expected[k] = solution.segment<12>(12 * k);
			for (int coarse : {0, 1}) EXPECT_LT(largestRelativeError(x[coarse], expected), 1e-6);
		}
	}
}

// The coarse level's bits do not depend on the thread count: the same
// iterations and bitwise the same solution on one and two threads.
TEST(CoarseLevel, BitwiseTheSameForAnyThreadCount) {
#ifndef _OPENMP
	GTEST_SKIP() << "built without OpenMP: one thread only";
#else
	const int before = omp_get_max_threads();
	const Lattice lattice(9, 9, 6, 1.0, 0.2, 0.15, 6u);
	std::mt19937 rng(6);
	std::uniform_real_distribution<double> u(-1, 1);
	std::vector<Vector12> b(lattice.blocks);
	for (Vector12& v : b)
		for (int i = 0; i < 12; ++i) v(i) = 1e6 * u(rng);
	std::vector<std::vector<Vector12>> results;
	std::vector<int> iterations;
	for (int threads : {1, 2}) {
		omp_set_num_threads(threads);
		BlockConjugateGradient solver;
		ASSERT_TRUE(solver.prepare(lattice.matrix(), 1, 2));
		std::vector<Vector12> x(lattice.blocks, Vector12::Zero());
		ASSERT_TRUE(solver.solve(b.data(), x.data(), 1e-12, 5000));
		iterations.push_back(solver.iterations());
		results.push_back(x);
	}
	omp_set_num_threads(before);
	EXPECT_EQ(iterations[0], iterations[1]);
	for (int k = 0; k < lattice.blocks; ++k)
		EXPECT_EQ(std::memcmp(results[0][k].data(), results[1][k].data(), sizeof(Vector12)), 0) << "block " << k;
#endif
}
