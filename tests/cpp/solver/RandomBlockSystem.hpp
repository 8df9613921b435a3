// Fixtures of the coupled solve's tests (test_refinement.cpp,
// test_iterative_solve.cpp): random symmetric positive definite block
// systems with their dense solution, and a settling stack of crossed beams
// that forms one dense component.
#pragma once

#include "dda/collider/Collider.hpp"
#include "dda/core/StateStream.hpp"
#include "dda/solver/CoupledSystem.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace dda::testing {

inline Matrix12 randomMatrix(std::mt19937& rng, double scale) {
	std::uniform_real_distribution<double> u(-1, 1);
	Matrix12 m;
	for (int i = 0; i < 144; ++i) m(i / 12, i % 12) = scale * u(rng);
	return m;
}

// A coupled system of `blocks` blocks (a chain plus links of probability
// `density`), its matrix and forces kept here as well to build the dense
// reference: diagonals symmetric and dominant.
struct RandomSystem {
	int blocks;
	std::vector<std::pair<int, int>> links;
	std::vector<int> unknowns;
	std::vector<BlockSystem> own;
	std::vector<Matrix12> offDiagonal;  // per link, K[lo][hi]

	RandomSystem(std::mt19937& rng, int n, double density, double rigidShare) : blocks(n) {
		std::uniform_real_distribution<double> unit(0, 1), u(-1, 1);
		std::set<std::pair<int, int>> set;
		for (int a = 0; a + 1 < n; ++a) set.emplace(a, a + 1);
		for (int a = 0; a < n; ++a)
			for (int b = a + 2; b < n; ++b)
				if (unit(rng) < density) set.emplace(a, b);
		links.assign(set.begin(), set.end());
		std::vector<int> degree(n, 0);
		for (auto [a, b] : links) {
			offDiagonal.push_back(randomMatrix(rng, 1));
			++degree[a];
			++degree[b];
		}
		for (int k = 0; k < n; ++k) {
			const Matrix12 r = randomMatrix(rng, 1);
			BlockSystem b;
			b.stiffness = r * r.transpose() + (12.0 * degree[k] + 1) * Matrix12::Identity();
			for (int i = 0; i < 12; ++i) b.force(i) = u(rng);
			own.push_back(b);
			unknowns.push_back(unit(rng) < rigidShare ? kRigidBlockDofs : kBlockDofs);
		}
	}

	// Adds w v v^T, v random on the 24 unknowns of link l's two blocks.
	void addRankOne(std::mt19937& rng, int l, double w) {
		std::uniform_real_distribution<double> u(-1, 1);
		Vector12 vi, vj;
		for (int i = 0; i < 12; ++i) {
			vi(i) = u(rng);
			vj(i) = u(rng);
		}
		const auto [a, b] = links[l];
		own[a].stiffness += w * vi * vi.transpose();
		own[b].stiffness += w * vj * vj.transpose();
		offDiagonal[l] += w * vi * vj.transpose();
	}

	void load(CoupledSystem& system) const {
		std::vector<int> systemOf(blocks);
		for (int k = 0; k < blocks; ++k) systemOf[k] = k;
		system.reset(own, systemOf);
		for (std::size_t l = 0; l < links.size(); ++l) {
			bool transposed;
			Matrix12& m = system.offDiagonal(links[l].first, links[l].second, transposed);
			m = transposed ? Matrix12(offDiagonal[l].transpose()) : offDiagonal[l];
		}
	}

	// The normwise backward error of x, |b - K x| / (|K| |x| + |b|) in
	// infinity norms, over the unknowns a rigid block keeps.
	double backwardError(const std::vector<Vector12>& x) const {
		std::vector<Vector12> r(blocks), rowSums(blocks);
		for (int k = 0; k < blocks; ++k) {
			r[k] = own[k].force - own[k].stiffness * x[k];
			rowSums[k] = own[k].stiffness.cwiseAbs().rowwise().sum();
		}
		for (std::size_t l = 0; l < links.size(); ++l) {
			const auto [lo, hi] = links[l];
			r[lo] -= offDiagonal[l] * x[hi];
			r[hi] -= offDiagonal[l].transpose() * x[lo];
			rowSums[lo] += offDiagonal[l].cwiseAbs().rowwise().sum();
			rowSums[hi] += offDiagonal[l].cwiseAbs().colwise().sum().transpose();
		}
		double residual = 0, normK = 0, normX = 0, normB = 0;
		for (int k = 0; k < blocks; ++k) {
			const int m = unknowns[k];
			residual = std::max(residual, r[k].head(m).cwiseAbs().maxCoeff());
			normK = std::max(normK, rowSums[k].head(m).maxCoeff());
			normX = std::max(normX, x[k].head(m).cwiseAbs().maxCoeff());
			normB = std::max(normB, own[k].force.head(m).cwiseAbs().maxCoeff());
		}
		return residual / (normK * normX + normB);
	}

	// The dense solution, a rigid block's strain unknowns struck out.
	std::vector<Vector12> denseSolution() const {
		std::vector<int> free;
		for (int k = 0; k < blocks; ++k)
			for (int i = 0; i < unknowns[k]; ++i) free.push_back(12 * k + i);
		const int n = 12 * blocks, m = static_cast<int>(free.size());
		Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
		for (int k = 0; k < blocks; ++k) K.block<12, 12>(12 * k, 12 * k) = own[k].stiffness;
		for (std::size_t l = 0; l < links.size(); ++l) {
			const auto [lo, hi] = links[l];
			K.block<12, 12>(12 * lo, 12 * hi) = offDiagonal[l];
			K.block<12, 12>(12 * hi, 12 * lo) = offDiagonal[l].transpose();
		}
		Eigen::MatrixXd Kr(m, m);
		Eigen::VectorXd Fr(m);
		for (int i = 0; i < m; ++i) {
			Fr(i) = own[free[i] / 12].force(free[i] % 12);
			for (int j = 0; j < m; ++j) Kr(i, j) = K(free[i], free[j]);
		}
		const Eigen::VectorXd x = Kr.llt().solve(Fr);
		std::vector<Vector12> out(blocks, Vector12::Zero());
		for (int i = 0; i < m; ++i) out[free[i] / 12](free[i] % 12) = x(i);
		return out;
	}
};

// A fixed floor and `layers` layers of `perLayer` beams (4 x 0.4 x 0.4 m),
// alternate layers crossing, 1 cm apart and slightly turned (seed 9): each
// beam lands across every beam of the layer below, so the settling stack is
// one dense component (as the paper's hexahedra drop), where refinement pays.
// Friction angle `frictionDeg` [deg].
inline World crossedBeams(int layers, int perLayer, double frictionDeg = 30) {
	const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
	World world;
	world.setCollider(std::make_unique<DESSCollider>());
	Material rock;
	rock.frictionAngle = frictionDeg * M_PI / 180;
	world.addBlock(orientedBox(Vector3(0, 0, -0.5), Vector3(4, 4, 0.5), I), rock, true);
	std::mt19937 rng(9);
	std::uniform_real_distribution<double> tilt(-0.01, 0.01);
	for (int layer = 0; layer < layers; ++layer)
		for (int k = 0; k < perLayer; ++k) {
			const Eigen::Matrix3d R = Eigen::AngleAxisd(tilt(rng), Vector3::UnitZ()).toRotationMatrix() *
			                          Eigen::AngleAxisd(tilt(rng), Vector3::UnitX()).toRotationMatrix();
			const double across = -1.5 + 3.0 * k / (perLayer - 1), z = 0.21 + 0.41 * layer;
			const bool alongX = layer % 2 == 0;
			world.addBlock(orientedBox(alongX ? Vector3(0, across, z) : Vector3(across, 0, z),
			                           alongX ? Vector3(2, 0.2, 0.2) : Vector3(0.2, 2, 0.2), R),
			               rock, false);
		}
	return world;
}

// One step of `world` with `settings` and of a copy of it (saved and read
// back: the same state, bitwise) with `twinSettings`; `twin` holds the copy
// after its step. Returns the largest distance between the two's vertices
// and sets `moved` to the largest centroid move of `world` in the step [m].
inline double stepWithTwin(World& world, const IntegratorSettings& settings, World& twin,
                           const IntegratorSettings& twinSettings, double& moved) {
	StateWriter out;
	world.writeState(out);
	const std::string saved = out.bytes();
	StateReader in(saved);
	twin.readState(in);
	std::vector<Vector3> before;
	for (int k = 0; k < world.blockCount(); ++k) before.push_back(world.block(k).centroid);
	world.step(settings);
	twin.step(twinSettings);
	double difference = 0;
	moved = 0;
	for (int k = 0; k < world.blockCount(); ++k) {
		const Block &a = world.block(k), &b = twin.block(k);
		for (std::size_t v = 0; v < a.vertices.size(); ++v)
			difference = std::max(difference, (a.vertices[v] - b.vertices[v]).norm());
		moved = std::max(moved, (a.centroid - before[k]).norm());
	}
	return difference;
}

inline double largestError(const std::vector<Vector12>& x, const std::vector<Vector12>& expected) {
	double error = 0, scale = 0;
	for (std::size_t k = 0; k < x.size(); ++k) {
		error = std::max(error, (x[k] - expected[k]).cwiseAbs().maxCoeff());
		scale = std::max(scale, expected[k].cwiseAbs().maxCoeff());
	}
	return error / scale;
}

}  // namespace dda::testing
