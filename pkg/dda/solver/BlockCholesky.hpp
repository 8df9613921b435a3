// A sparse Cholesky factorisation K = L L^T of a symmetric positive definite
// matrix made of 12x12 blocks, one block row and column per DDA block: the
// coupled system of a group of blocks that closed contacts join
// (CoupledSystem.hpp). It works on whole 12x12 blocks, so its inner loop is
// a fixed-size 12x12 product (about 5 GFlop/s here, three times what a
// scalar sparse Cholesky reaches on the same matrices: 16.2 against 4.95 ms
// for 49 blocks with 37 % of the pairs joined, measured when this replaced
// Eigen's SimplicialLLT).
//
// Analysis (pattern only): a fill-reducing order of the block graph (Eigen's
// AMD on the blocks), then the block elimination tree and each block
// column's rows: a column's rows are its own links below the diagonal and
// its children's rows, less itself (the classic symbolic factorisation, on
// blocks). The update targets of the numeric factorisation are listed once.
//
// Numeric factorisation (right-looking, column by column in elimination
// order): L_jj = chol(A_jj); L_ij = A_ij L_jj^-T for the rows i of column j;
// then A_ik -= L_ij L_kj^T for every pair of rows i >= k of column j. The
// arithmetic is sequential and fixed by the pattern: the same matrix gives
// bitwise the same factor, whatever the thread count.
//
// Rigid blocks (6 unknowns) keep the 12x12 layout: their strain rows and
// columns are replaced by those of the identity, with no coupling, and their
// right-hand side's strain part by zero. That is exactly the restricted
// system (the identity rows decouple; the factor's strain rows and columns
// stay exactly zero, as every update adds products with a zero factor), and
// its strain solution is exactly zero.
#pragma once

#include "dda/block/Displacement.hpp"

#include <Eigen/Cholesky>

#include <cstddef>
#include <utility>
#include <vector>

namespace dda {

class BlockCholesky {
public:
	// The pattern: `blocks` block rows, joined by `links` (lo, hi), lo < hi,
	// no duplicates, in the order factorize's off-diagonal blocks come in.
	void analyse(int blocks, const std::vector<std::pair<int, int>>& links);
	// K from diagonal[k] (k < blocks), offDiagonal[l] = K[lo][hi] of link l
	// (rows of lo, columns of hi), sizes[k] = 12, or 6 for a rigid block.
	// False when K is not positive definite.
	bool factorize(const Matrix12* diagonal, const Matrix12* offDiagonal, const int* sizes);
	// Solves K x = b in place (x: b on entry, per block; the strain part of a
	// rigid block's b is ignored and its solution's is zero).
	void solve(Vector12* x) const;

	int blocks() const { return static_cast<int>(inverse_.size()); }
	// The factor's off-diagonal 12x12 blocks, and the 12x12 products a
	// factorisation makes (its cost; a solve costs about twice the blocks).
	long factorBlocks() const { return static_cast<long>(rows_.size()); }
	long factorProducts() const { return static_cast<long>(updateTarget_.size() + rows_.size()); }
	std::size_t memoryBytes() const;

private:
	std::vector<int> inverse_;   // per block: its place in elimination order
	std::vector<int> columnStart_, rows_;  // per column (place), its rows (places) below the diagonal, ascending
	std::vector<int> linkTarget_;          // per link: its entry of factor_ (signed: -1 - entry when transposed)
	std::vector<int> updateTarget_;        // per (column j, row i, row k < i of j): the entry of L_ik
	std::vector<int> sizes_;               // per place
	std::vector<Matrix12> factor_;         // L_ij, per entry of rows_
	std::vector<Matrix12> diagonal_;       // per place: A_jj, then L_jj
	std::vector<Eigen::LLT<Matrix12>> pivots_;  // per place: the LLT of A_jj
};

}  // namespace dda
