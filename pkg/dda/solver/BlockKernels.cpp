#include "BlockKernels.hpp"

#include <cstring>

namespace dda {

namespace {

// GCC's vector types of 2 and 4 doubles, loaded and stored unaligned.
typedef double Packet2 __attribute__((vector_size(16), aligned(8)));
typedef double Packet4 __attribute__((vector_size(32), aligned(8)));

// C -= A B^T on column-major 12x12 arrays, in packets of W doubles: for each
// column k of C, its 12 / W packets stay in registers while the 12 columns
// of A, scaled by B(k, m), are subtracted in order m = 0 .. 11.
template <class Packet, int W>
__attribute__((always_inline)) inline void subtractProducts(double* __restrict c, const double* __restrict a,
                                                            const double* __restrict b) {
	constexpr int kPackets = 12 / W;
	for (int k = 0; k < 12; ++k) {
		double* column = c + 12 * k;
		Packet sum[kPackets];
#pragma GCC unroll 6
		for (int r = 0; r < kPackets; ++r) std::memcpy(&sum[r], column + W * r, sizeof(Packet));
#pragma GCC unroll 12
		for (int m = 0; m < 12; ++m) {
			const double scale = b[k + 12 * m];
			const double* am = a + 12 * m;
#pragma GCC unroll 6
			for (int r = 0; r < kPackets; ++r) {
				Packet x;
				std::memcpy(&x, am + W * r, sizeof(Packet));
				sum[r] -= x * scale;
			}
		}
#pragma GCC unroll 6
		for (int r = 0; r < kPackets; ++r) std::memcpy(column + W * r, &sum[r], sizeof(Packet));
	}
}

__attribute__((target("avx2"), noinline)) void subtractAvx2(double* c, const double* a, const double* b) {
	subtractProducts<Packet4, 4>(c, a, b);
}

__attribute__((noinline)) void subtractSse2(double* c, const double* a, const double* b) {
	subtractProducts<Packet2, 2>(c, a, b);
}

const bool kAvx2 = __builtin_cpu_supports("avx2");

}  // namespace

void subtractProductTransposed(Matrix12& c, const Matrix12& a, const Matrix12& b) {
	if (kAvx2)
		subtractAvx2(c.data(), a.data(), b.data());
	else
		subtractSse2(c.data(), a.data(), b.data());
}

void subtractProductTransposedSse2(Matrix12& c, const Matrix12& a, const Matrix12& b) {
	subtractSse2(c.data(), a.data(), b.data());
}

void subtractProductTransposedScalar(Matrix12& c, const Matrix12& a, const Matrix12& b) {
	for (int k = 0; k < 12; ++k)
		for (int m = 0; m < 12; ++m)
			for (int i = 0; i < 12; ++i) c(i, k) -= a(i, m) * b(k, m);
}

bool blockKernelsUseAvx2() { return kAvx2; }

}  // namespace dda
