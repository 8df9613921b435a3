// A view of a symmetric matrix of 12x12 blocks, one block row and column per
// DDA block: the coupled system of a component as the iterative solve and
// its coarse level read it (BlockConjugateGradient.hpp, AffineCoarseSpace.hpp).
#pragma once

#include "dda/block/Displacement.hpp"

#include <utility>

namespace dda {

struct BlockSparseMatrix {
	// `blocks` block rows; diagonal[k] (its lower triangle is read),
	// offDiagonal[l] = K[lo][hi] of links[l] = (lo, hi), lo < hi, sorted, no
	// duplicates; sizes[k] = 12, or 6 for a rigid block. The arrays must
	// outlive the solves.
	int blocks = 0;
	const Matrix12* diagonal = nullptr;
	const Matrix12* offDiagonal = nullptr;
	const std::pair<int, int>* links = nullptr;
	int linkCount = 0;
	const int* sizes = nullptr;
	// Per block, the point its unknowns refer to [m] (its centroid at the
	// step's start): the coarse level's affine fields need it.
	const Vector3* centroids = nullptr;
};

}  // namespace dda
