// The global DDA system K D = F of the moving blocks, block-sparse: a 12x12
// diagonal block per moving block, and an off-diagonal block per pair of
// moving blocks joined by at least one closed contact (open contacts carry no
// terms; World rebuilds the structure when the open-close iteration opens or
// closes one). Blocks that no closed contact joins form independent
// components, each solved on its own:
//   - one block without contacts or fixed points: the block's own 3 + 9 solve
//     (BlockEquations.hpp), so a free block is not affected by the rest of
//     the scene, not even by round-off;
//   - one block with closed contacts (against fixed blocks) or fixed points: a dense
//     12x12 Cholesky;
//   - several blocks: a sparse Cholesky (Eigen's SimplicialLLT, AMD order).
// K is symmetric positive definite: the mass term is, and springs add
// positive semi-definite terms.
//
// Rigid blocks have 6 unknowns, not 12. Every block keeps the 12-layout in
// storage (contact terms are assembled as for any block), but a rigid block's
// strain rows and columns never enter a factorisation: its own solve is 3 + 3
// or 6x6, and in a sparse component the unknowns are numbered with variable
// block sizes (offsets), the strain rows and columns of its stored blocks
// skipped. Leaving them out is exactly the constraint strain = 0 (the
// restriction of the quadratic energy to the rigid subspace); its solution's
// strain part is set to zero.
#pragma once

#include "BlockEquations.hpp"

#include <Eigen/Sparse>

#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace dda {

class CoupledSystem {
public:
	// Sets the structure: `links` lists pairs of moving-block indices
	// (0 .. movingBlocks-1) joined by a closed contact; `hasSprings[k]` says
	// whether block k has closed contacts or fixed points (so needs the 12x12
	// solve); `unknowns[k]` is its number of unknowns (kBlockDofs, or
	// kRigidBlockDofs for a rigid block).
	void build(int movingBlocks, const std::vector<std::pair<int, int>>& links, const std::vector<char>& hasSprings,
	           const std::vector<int>& unknowns);

	// Starts an assembly from the blocks' own systems.
	void reset(const std::vector<BlockSystem>& blockSystems);
	Matrix12& diagonal(int k) { return diagonal_[k]; }
	Vector12& force(int k) { return force_[k]; }
	// The off-diagonal block of row a, column b (a, b joined by build's links);
	// the (b, a) block is its transpose and is not stored.
	Matrix12& offDiagonal(int a, int b, bool& transposed);

	// Solves every component; solutions[k] for moving block k. `blocks[k]`
	// is moving block k (for the 3 + 9 fast path). Throws std::runtime_error if
	// a factorisation fails (K not positive definite).
	void solve(const std::vector<const Block*>& blocks, std::vector<Vector12>& solutions, int threadsFrom);

	int components() const { return static_cast<int>(components_.size()); }
	int largestComponent() const;
	// Unknowns factorised by the last solve, all components together.
	long solvedUnknowns() const { return solvedUnknowns_; }

private:
	std::vector<std::vector<int>> components_;  // moving-block indices, ascending
	std::vector<int> componentOf_, localIndex_;
	std::vector<char> hasSprings_;
	std::vector<int> unknowns_;           // per moving block: 12, or 6 when rigid
	std::vector<long> componentUnknowns_;  // per component, of the last solve
	long solvedUnknowns_ = 0;
	std::vector<Matrix12> diagonal_;
	std::vector<Vector12> force_;
	std::vector<Matrix12> offDiagonal_;
	std::unordered_map<std::uint64_t, int> offDiagonalIndex_;  // (min, max) -> slot
	std::vector<std::pair<int, int>> offDiagonalPairs_;          // slot -> (min, max)
	std::vector<std::vector<int>> componentLinks_;               // slots per component
};

}  // namespace dda
