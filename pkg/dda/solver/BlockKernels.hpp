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

// Whether subtractProductTransposed runs its AVX2 variant on this machine.
bool blockKernelsUseAvx2();

}  // namespace dda
