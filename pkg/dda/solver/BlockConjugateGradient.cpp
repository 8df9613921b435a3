#include "BlockConjugateGradient.hpp"

#include "BlockKernels.hpp"

#include "dda/core/CapacityBytes.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace dda {

namespace {

// Dot products sum chunks of this many blocks, then the chunks in order: the
// same bits for any thread count.
constexpr int kChunkBlocks = 256;

}  // namespace

bool BlockConjugateGradient::threaded() const {
#ifdef _OPENMP
	return matrix_.blocks >= threadsFrom_ && omp_get_max_threads() > 1 && !omp_in_parallel();
#else
	return false;
#endif
}

bool BlockConjugateGradient::prepare(const Matrix& matrix, int threadsFrom, int coarseFrom) {
	matrix_ = matrix;
	threadsFrom_ = threadsFrom;
	const int n = matrix.blocks;
	// Rows: both triangles' blocks, by counting (links are sorted by (lo, hi),
	// so a row's upper neighbours come in ascending order; its lower ones,
	// the lo of links whose hi it is, also ascend with the link order).
	rowStart_.assign(n + 1, 0);
	for (int l = 0; l < matrix.linkCount; ++l) {
		++rowStart_[matrix.links[l].first + 1];
		++rowStart_[matrix.links[l].second + 1];
	}
	for (int k = 0; k < n; ++k) rowStart_[k + 1] += rowStart_[k];
	neighbour_.resize(rowStart_[n]);
	link_.resize(rowStart_[n]);
	std::vector<int> lower(n), upper(n);
	// Lower neighbours first: count them to place the upper ones after.
	std::vector<int> lowerCount(n, 0);
	for (int l = 0; l < matrix.linkCount; ++l) ++lowerCount[matrix.links[l].second];
	for (int k = 0; k < n; ++k) {
		lower[k] = rowStart_[k];
		upper[k] = rowStart_[k] + lowerCount[k];
	}
	for (int l = 0; l < matrix.linkCount; ++l) {
		const auto [lo, hi] = matrix.links[l];
		neighbour_[upper[lo]] = hi;
		link_[upper[lo]++] = l;
		neighbour_[lower[hi]] = lo;
		link_[lower[hi]++] = l;
	}
	rigid_.resize(n);
	for (int k = 0; k < n; ++k) rigid_[k] = matrix.sizes[k] != kBlockDofs;

	// |K| (infinity norm: the largest absolute row sum, restricted rows).
	normK_ = 0;
	for (int k = 0; k < n; ++k) {
		Vector12 sums = Matrix12(matrix.diagonal[k].selfadjointView<Eigen::Lower>()).cwiseAbs().rowwise().sum();
		for (int e = rowStart_[k]; e < rowStart_[k + 1]; ++e) {
			const Matrix12& m = matrix.offDiagonal[link_[e]];
			if (neighbour_[e] > k)
				sums += m.cwiseAbs().rowwise().sum();
			else
				sums += m.cwiseAbs().colwise().sum().transpose();
		}
		if (rigid_[k]) sums.tail<kBlockDofs - kRigidBlockDofs>().setZero();
		normK_ = std::max(normK_, sums.maxCoeff());
	}

	diagonalInverse_.resize(n);
	bool positive = true;
#pragma omp parallel for schedule(static) reduction(&& : positive) if (threaded())
	for (int k = 0; k < n; ++k) {
		Matrix12 d = matrix.diagonal[k].selfadjointView<Eigen::Lower>();
		if (rigid_[k]) {
			d.block<6, 6>(6, 0).setZero();
			d.block<6, 6>(0, 6).setZero();
			d.block<6, 6>(6, 6).setIdentity();
		}
		// Applied as the inverse itself: one 12x12 product instead of two
		// triangular solves.
		const Eigen::LLT<Matrix12> factor(d);
		positive = positive && factor.info() == Eigen::Success;
		diagonalInverse_[k] = factor.solve(Matrix12::Identity());
	}
	coarseOn_ = positive && matrix.centroids && coarseFrom > 0 && n >= coarseFrom && prepareCoarse();
	r_.resize(n);
	z_.resize(n);
	p_.resize(n);
	q_.resize(n);
	partial_.resize((n + kChunkBlocks - 1) / kChunkBlocks);
	return positive;
}

bool BlockConjugateGradient::prepareCoarse() {
	return coarse_.prepare(AffineCoarseSpace::Fine{matrix_, rowStart_.data(), neighbour_.data()});
}

void BlockConjugateGradient::restrictRigid(std::vector<Vector12>& v) const {
	for (int k = 0; k < matrix_.blocks; ++k)
		if (rigid_[k]) v[k].tail<kBlockDofs - kRigidBlockDofs>().setZero();
}

void BlockConjugateGradient::multiply(const std::vector<Vector12>& x, std::vector<Vector12>& y) const {
	const int n = matrix_.blocks;
#pragma omp parallel for schedule(static) if (threaded())
	for (int k = 0; k < n; ++k) {
		Vector12 sum;
		symmetricLowerProduct(sum, matrix_.diagonal[k], x[k]);
		for (int e = rowStart_[k]; e < rowStart_[k + 1]; ++e) {
			const Matrix12& m = matrix_.offDiagonal[link_[e]];
			if (neighbour_[e] > k)
				addProduct(sum, m, x[neighbour_[e]]);
			else
				addTransposedProduct(sum, m, x[neighbour_[e]]);
		}
		if (rigid_[k]) sum.tail<kBlockDofs - kRigidBlockDofs>().setZero();
		y[k] = sum;
	}
}

void BlockConjugateGradient::precondition(const std::vector<Vector12>& r, std::vector<Vector12>& z) const {
	const int n = matrix_.blocks;
#pragma omp parallel for schedule(static) if (threaded())
	for (int k = 0; k < n; ++k) z[k].noalias() = diagonalInverse_[k].lazyProduct(r[k]);
	if (coarseOn_) coarse_.addCorrection(r, z, threaded());
}

double BlockConjugateGradient::dot(const std::vector<Vector12>& a, const std::vector<Vector12>& b) const {
	const int n = matrix_.blocks, chunks = static_cast<int>(partial_.size());
#pragma omp parallel for schedule(static) if (threaded())
	for (int c = 0; c < chunks; ++c) {
		double sum = 0;
		for (int k = c * kChunkBlocks, last = std::min(n, k + kChunkBlocks); k < last; ++k) sum += a[k].dot(b[k]);
		partial_[c] = sum;
	}
	double sum = 0;
	for (double s : partial_) sum += s;
	return sum;
}

double BlockConjugateGradient::largest(const std::vector<Vector12>& a) const {
	double m = 0;
	for (int k = 0; k < matrix_.blocks; ++k) m = std::max(m, a[k].lpNorm<Eigen::Infinity>());
	return m;
}

bool BlockConjugateGradient::solve(const Vector12* bIn, Vector12* xInOut, double tolerance, int maxIterations) {
	const int n = matrix_.blocks;
	std::vector<Vector12> b(bIn, bIn + n), x(xInOut, xInOut + n);
	restrictRigid(b);
	restrictRigid(x);
	for (int k = 0; k < n; ++k)
		if (!x[k].allFinite()) x[k].setZero();
	const double normB = largest(b);
	iterations_ = 0;
	backwardError_ = 0;
	auto bound = [&]() { return normK_ * largest(x) + normB; };
	// The true residual r = b - K x and whether its backward error is within the tolerance.
	auto residual = [&]() {
		multiply(x, q_);
		for (int k = 0; k < n; ++k) r_[k] = b[k] - q_[k];
		const double scale = bound();
		backwardError_ = scale > 0 ? largest(r_) / scale : 0;
		return backwardError_ <= tolerance;
	};
	bool converged = residual();
	if (!converged) {
		precondition(r_, z_);
		p_ = z_;
		double rz = dot(r_, z_);
		while (iterations_ < maxIterations) {
			++iterations_;
			multiply(p_, q_);
			const double pq = dot(p_, q_);
			if (!(pq > 0) || !std::isfinite(pq)) break;
			const double alpha = rz / pq;
			for (int k = 0; k < n; ++k) {
				x[k] += alpha * p_[k];
				r_[k] -= alpha * q_[k];
			}
			if (largest(r_) <= tolerance * bound()) {
				// The recurrence's residual drifts from the true one: check
				// it, and go on from the true residual if it is not there.
				if (residual()) {
					converged = true;
					break;
				}
			}
			precondition(r_, z_);
			const double rzNext = dot(r_, z_);
			const double beta = rzNext / rz;
			rz = rzNext;
			for (int k = 0; k < n; ++k) p_[k] = z_[k] + beta * p_[k];
		}
		if (!converged) residual();
	}
	std::copy(x.begin(), x.end(), xInOut);
	return converged;
}

std::size_t BlockConjugateGradient::memoryBytes() const {
	return capacityBytes(rowStart_) + capacityBytes(neighbour_) + capacityBytes(link_) + capacityBytes(rigid_) +
	       capacityBytes(diagonalInverse_) + capacityBytes(r_) + capacityBytes(z_) + capacityBytes(p_) +
	       capacityBytes(q_) + capacityBytes(partial_) + (coarseOn_ ? coarse_.memoryBytes() : 0);
}

}  // namespace dda
