// The coarse level of the iterative path's preconditioner
// (BlockConjugateGradient.hpp): groups of neighbouring blocks that move
// together by one affine field.
//
// Why. Block Jacobi sees one block at a time: its iterations grow with the
// spread of the scaled system's eigenvalues, whose small end is the slow
// collective motions of many blocks. In a dynamic step the mass term
// 2M/dt^2 bounds the spread; a static step (start from rest) has none, and
// the spread grows with the mass's width in blocks: 171 iterations a solve
// at 150 free blocks, 316 at 810 (the 6 and 10 m orthogonal stacks of
// tests/py/rockmass_scenes.py while they settle). A coarse space that holds
// the collective motions takes them out of the iteration (two-level
// additive Schwarz, with aggregates as in aggregation multigrid): 107 and
// 130 iterations, and the 10 m stack settles in 60 s instead of 107.
//
// The space. The blocks of the component are grouped into aggregates by
// their links (closed contacts): greedily in block order, a block whose
// neighbours are all still free starts an aggregate with them; a block left
// over joins the aggregate of its first grouped neighbour. While there are
// more than kMaxAggregates aggregates, the aggregates are grouped again the
// same way on their own graph. An aggregate a moves by one affine field with
// 12 parameters A_a, written like a block's unknowns at the aggregate's
// mean centroid X_a. The DDA displacement function is affine, u(x) =
// T(x - c) D with T(d) = [I | B(d)] and B linear, so block i of aggregate a
// moves exactly by D_i = R_i A_a with R_i = [[I, B(c_i - X_a)], [0, I]]
// (the field's translation at the block's centroid, the same rotation and
// strain). A rigid block's strain rows of R_i are zero (its restricted
// unknowns); an aggregate of rigid blocks only has the 6 rigid-body
// parameters (its strain columns could be dependent), one with a deformable
// block all 12 (R_i of that block is invertible, so P has full column rank
// and the coarse matrix is positive definite when K is).
//
// The coarse matrix Kc = P^T K P, block-sparse like K (an aggregate per
// block row, a link per pair of aggregates joined by a fine link), is
// factorised by BlockCholesky. The preconditioner adds its correction to
// block Jacobi's: z = D^-1 r + P Kc^-1 P^T r, symmetric positive definite.
// It is formed anew for every solve, from that solve's matrix (at 392 blocks
// 1.2 ms to form, 0.4 ms to factorise: a few iterations' worth).
//
// Not kept: smoothing the prolongator, P = (I - w D^-1 K) P (smoothed
// aggregation), took 104 instead of 130 iterations at 810 blocks, but its
// P maps a block to about six aggregates, so an iteration cost more than
// the iterations saved. The symmetric multiplicative form (balancing,
// P_BNN) conditions better (365 against 603 at 150 blocks, computed
// densely) but takes two more products with K an iteration; not tried in
// the solver.
//
// Determinism: aggregation follows the block order, the coarse matrix sums
// the fine blocks in link order, a restriction sums an aggregate's blocks in
// ascending order, and the coarse factorisation is sequential, so the
// preconditioner's bits do not depend on the thread count.
#pragma once

#include "BlockCholesky.hpp"
#include "BlockSparseMatrix.hpp"

#include "dda/block/Displacement.hpp"

#include <cstddef>
#include <utility>
#include <vector>

namespace dda {

class AffineCoarseSpace {
public:
	// The fine matrix (its centroids set) and its rows: rows[k] ..
	// rows[k+1]-1 index neighbours[], block k's linked blocks, ascending.
	struct Fine {
		BlockSparseMatrix matrix;
		const int* rows = nullptr;
		const int* neighbours = nullptr;
	};

	// Aggregates the blocks and factorises the coarse matrix; false when it
	// is not positive definite (the preconditioner is then block Jacobi alone).
	bool prepare(const Fine& fine);
	// z += P Kc^-1 P^T r (rigid blocks' strain parts of r ignored, of the
	// correction zero). `threaded`: the per-block loops in parallel.
	void addCorrection(const std::vector<Vector12>& r, std::vector<Vector12>& z, bool threaded) const;

	int aggregates() const { return static_cast<int>(aggregateStart_.size()) - 1; }
	std::size_t memoryBytes() const;

private:
	// Groups the blocks; aggregateOf_, aggregateStart_, members_, reference_.
	void aggregate(const Fine& fine);
	// R_i's 3x9 part B(c_i - X_a) and its strain scale (0 for a rigid block).
	void formMaps(const Fine& fine);
	// Kc = P^T K P (coarseDiagonal_, coarseLinks_, coarseOffDiagonal_).
	void formCoarseMatrix(const Fine& fine);

	std::vector<int> aggregateOf_;      // per block
	std::vector<int> aggregateStart_;   // aggregate a's blocks: members_[aggregateStart_[a] ..]
	std::vector<int> members_;          // blocks, by aggregate, ascending within one
	std::vector<Vector3> reference_;    // per aggregate: X_a [m]
	std::vector<int> coarseSizes_;      // per aggregate: 12, or 6 when all its blocks are rigid
	std::vector<Eigen::Matrix<double, 3, 9>> maps_;  // per block: B(c_i - X_a)
	std::vector<char> rigid_;           // per block
	std::vector<Matrix12> coarseDiagonal_, coarseOffDiagonal_;
	std::vector<std::pair<int, int>> coarseLinks_;
	BlockCholesky cholesky_;
	bool ready_ = false;
	mutable std::vector<Vector12> coarse_;
};

}  // namespace dda
