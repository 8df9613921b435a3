// The 12x12 block product of the sparse Cholesky's updates (BlockCholesky),
// C -= A B^T, written so that its result does not depend on the machine.
//
// Eigen sends a fixed-size 12x12 product through its general matrix product
// (packing both operands, then a blocked kernel): about 10 GFlop/s here,
// with packing a quarter of the factorisation's time. This kernel keeps a
// column of C in registers and subtracts A's columns scaled by B's entries,
// one at a time, in a fixed order: every entry of C sees exactly the scalar
// sequence c -= a_m b_m for m = 0 .. 11, whatever the vector width. So the
// SSE2 build (any x86-64) and the AVX2 one, chosen at run time on machines
// that have it, give bitwise the same factor (tested against the scalar
// loop); no fused multiply-add is used (the AVX2 variant is compiled for
// AVX2 alone, so the compiler cannot contract the two roundings into one).
// Measured on one 12x12 product, warm cache: AVX2 22 GFlop/s, SSE2 11,
// Eigen's product 10.
#pragma once

#include "dda/block/Displacement.hpp"

namespace dda {

// C -= A B^T.
void subtractProductTransposed(Matrix12& c, const Matrix12& a, const Matrix12& b);

// The same by the SSE2 variant whatever the machine has, and by the plain
// scalar loop (the references the tests compare with).
void subtractProductTransposedSse2(Matrix12& c, const Matrix12& a, const Matrix12& b);
void subtractProductTransposedScalar(Matrix12& c, const Matrix12& a, const Matrix12& b);

// Small 12x12 helpers, inline, by Eigen's fixed-size column operations (its
// own SSE2 packets, not the general product's run-time dispatch, which the
// profile showed for each 12x12 product).

// M += s v^T (s, v: 12 doubles each): every entry m_ik += s_i v_k, one
// product and one sum, as Eigen's outer product computes it (the same bits).
inline void addOuterProduct(Matrix12& m, const double* s, const double* v) {
	const Eigen::Map<const Vector12> column(s);
	for (int k = 0; k < 12; ++k) m.col(k) += column * v[k];
}

// y -= M x and y += M x (coefficient-based: each entry a sum over k).
inline void subtractProduct(Vector12& y, const Matrix12& m, const Vector12& x) { y.noalias() -= m.lazyProduct(x); }
inline void addProduct(Vector12& y, const Matrix12& m, const Vector12& x) { y.noalias() += m.lazyProduct(x); }

// y -= M^T x and y += M^T x.
inline void subtractTransposedProduct(Vector12& y, const Matrix12& m, const Vector12& x) {
	y.noalias() -= m.transpose().lazyProduct(x);
}
inline void addTransposedProduct(Vector12& y, const Matrix12& m, const Vector12& x) {
	y.noalias() += m.transpose().lazyProduct(x);
}

// y = S x, S symmetric, given by its lower triangle (the upper one is not read).
inline void symmetricLowerProduct(Vector12& y, const Matrix12& lower, const Vector12& x) {
	y.noalias() = lower.selfadjointView<Eigen::Lower>() * x;
}

// X <- X L^-T, L lower triangular with a non-zero diagonal (an LLT's factor;
// the upper triangle is not read): column by column, X(:, c) = (X(:, c) -
// sum_k<c X(:, k) L(c, k)) / L(c, c), the Cholesky's L_ij = A_ij L_jj^-T.
inline void solveTransposedLowerOnTheRight(Matrix12& x, const Matrix12& lower) {
	for (int c = 0; c < 12; ++c) {
		for (int k = 0; k < c; ++k) x.col(c) -= x.col(k) * lower(c, k);
		x.col(c) /= lower(c, c);
	}
}

// Whether subtractProductTransposed runs its AVX2 variant on this machine.
bool blockKernelsUseAvx2();

}  // namespace dda
