// Preconditioned conjugate gradients on a symmetric positive definite matrix
// of 12x12 blocks, one block row and column per DDA block: the iterative
// path of a large connected component of the coupled system
// (CoupledSystem.hpp), whose direct factorisation fills in.
//
// Why it converges in a bounded number of iterations. The dynamic DDA system
// is K = 2M/dt^2 + K_contacts + K_elastic. Scaled by its block diagonal D (the
// block-Jacobi preconditioner), every eigenvalue of D^-1 K lies in (0, 1 + c)
// with c at most the number of a block's neighbours times the largest ratio
// of a contact's stiffness to its blocks' mass term 2m/dt^2, and above a
// floor set by the mass term; neither grows with the number of blocks, so
// the iterations to a given backward error do not either (measured in
// bench/solver.py: 35 iterations a solve at 155 free blocks, 50 from 372
// to 1,674).
//
// Preconditioner: block Jacobi, z_i = K_ii^-1 r_i with each diagonal
// block's inverse formed once per matrix (one 12x12 product per block, rows
// independent, so threaded). A symmetric block Gauss-Seidel sweep took 2.2
// times fewer iterations on jointed masses (22 against 54 at 155 free blocks,
// 34 against 75 at 746) but costs about twice as much per iteration, so the
// same time on one thread, and its sweeps are sequential.
//
// Stopping rule: the normwise backward error of the true residual,
// |b - K x| / (|K| |x| + |b|) (infinity norms), at most the tolerance: the
// solution is the exact one of a system whose entries differ by that
// fraction. The recurrence's residual decides when to compute the true one.
//
// Determinism: every block row's product sums its terms in a fixed order
// (the diagonal block, then its neighbours in ascending order), and the dot
// products sum fixed chunks of blocks in order, so the iterates are bitwise
// the same for any thread count.
//
// Rigid blocks (6 unknowns) keep the 12-layout: their strain rows and
// columns are those of the identity with no coupling and a zero right-hand
// side (the restricted system, as BlockCholesky factorises it); their
// iterates' strain parts stay exactly zero.
#pragma once

#include "AffineCoarseSpace.hpp"
#include "BlockSparseMatrix.hpp"

#include "dda/block/Displacement.hpp"

#include <cstddef>
#include <utility>
#include <vector>

namespace dda {

class BlockConjugateGradient {
public:
	// The matrix (BlockSparseMatrix.hpp).
	using Matrix = BlockSparseMatrix;

	// Takes the matrix and inverts its diagonal blocks (the preconditioner);
	// false when one is not positive definite. Rows are threaded when there
	// are at least `threadsFrom` blocks (and more than one thread). With
	// centroids and at least `coarseFrom` blocks (coarseFrom > 0), the
	// preconditioner adds the coarse level (AffineCoarseSpace.hpp).
	bool prepare(const Matrix& matrix, int threadsFrom, int coarseFrom = 0);

	// Solves K x = b; x holds the first iterate on entry (a rigid block's
	// strain part is ignored) and the solution on return. Returns whether the
	// backward error reached `tolerance` within `maxIterations` iterations.
	bool solve(const Vector12* b, Vector12* x, double tolerance, int maxIterations);

	// The last solve's iterations and the backward error of its result.
	int iterations() const { return iterations_; }
	double backwardError() const { return backwardError_; }
	// Aggregates of the coarse level (0 without one).
	int coarseAggregates() const { return coarseOn_ ? coarse_.aggregates() : 0; }
	// Heap held [bytes].
	std::size_t memoryBytes() const;

private:
	// y = K x.
	void multiply(const std::vector<Vector12>& x, std::vector<Vector12>& y) const;
	// z = M^-1 r.
	void precondition(const std::vector<Vector12>& r, std::vector<Vector12>& z) const;
	double dot(const std::vector<Vector12>& a, const std::vector<Vector12>& b) const;
	double largest(const std::vector<Vector12>& a) const;
	void restrictRigid(std::vector<Vector12>& v) const;
	// The coarse level of the prepared matrix; false when its matrix is not
	// positive definite (then block Jacobi alone).
	bool prepareCoarse();
	bool threaded() const;

	Matrix matrix_;
	int threadsFrom_ = 0;
	double normK_ = 0;
	// Per block row, its off-diagonal blocks in ascending column order:
	// neighbour_[e], link_[e] (transposed when the row is the link's hi).
	std::vector<int> rowStart_, neighbour_, link_;
	std::vector<char> rigid_;
	std::vector<Matrix12> diagonalInverse_;
	AffineCoarseSpace coarse_;
	bool coarseOn_ = false;
	std::vector<Vector12> r_, z_, p_, q_;
	mutable std::vector<double> partial_;
	int iterations_ = 0;
	double backwardError_ = 0;
};

}  // namespace dda
