// The global DDA system K D = F of the moving blocks that have springs (closed
// contacts or fixed points), block-sparse: a 12x12 diagonal block per such
// block, and an off-diagonal block per pair of moving blocks joined by at
// least one closed contact (open contacts carry no terms; World rebuilds the
// structure when the open-close iteration opens or closes one). Blocks that no
// closed contact joins form independent components, each solved on its own:
//   - one block with closed contacts (against fixed blocks) or fixed points: a dense
//     12x12 Cholesky;
//   - several blocks: a sparse Cholesky on 12x12 blocks (BlockCholesky.hpp);
//   - at least IntegratorSettings::iterativeSolveBlocks blocks (setIterative):
//     conjugate gradients preconditioned by block Jacobi
//     (BlockConjugateGradient.hpp), threaded over the block rows, to a
//     normwise backward error of iterativeTolerance. A jointed rock mass is
//     one connected component whose factor fills in: the Cholesky's cost
//     grows like the cube of its blocks (a solve of 155 free blocks took
//     7 ms, of 372 blocks 250 ms), the iteration's like its blocks times
//     its iterations, which the mass term bounds. The first solve of an
//     attempt starts from zero (a step depends on its start state alone);
//     later ones start from the attempt's last solution, the systems of
//     the open-close iteration differing by a few contacts' terms. One that
//     has not converged within kMaxIterativeIterations is factorised.
//     These components are solved one after another before the others
//     (which run in parallel), so that each is threaded inside.
// A block without springs is not part of it: World solves it by the block's
// own 3 + 9 solve (BlockEquations.hpp), so a free block is not affected by the
// rest of the scene, not even by round-off, and costs no stored 12x12 block.
// K is symmetric positive definite: the mass term is, and springs add
// positive semi-definite terms.
//
// Storage is by slot: the blocks with springs numbered component by
// component, ascending within one, so a component's diagonal blocks and its
// links (sorted by slot pair) are contiguous ranges.
//
// Analysis reuse. A sparse component's matrix pattern (its block sizes and
// links, numbered within the component) decides its factorisation's
// symbolic analysis (BlockCholesky::analyse: the block order, the factor's
// pattern, the update targets): it is kept per pattern and reused by every
// solve with the same pattern (the open-close iteration's solves between
// structure changes, the structures it swaps between, the next steps of a
// resting pile). The numeric factorisation depends on the pattern and the
// values alone, so the solutions are bitwise those of a fresh analysis
// (tests/cpp/solver/test_effects.cpp compares them). Patterns unused for
// kKeptBuilds builds, or beyond the used patterns' size, are dropped.
//
// Later solves of an attempt (refinement). Within one attempt of a step the
// open-close iteration solves systems that differ only by the terms of the
// contacts whose state changed (a few rank-one terms each), so a
// component's matrix stays close to the one factorised at its first solve.
// When refinement is on (IntegratorSettings::refineSolves) a later solve of a
// component (kMinRefineBlocks or more) whose blocks are exactly those of a component factorised earlier
// in the same attempt runs preconditioned conjugate gradients with that
// factor, the latest one (refineComponent): with the exact factor of K_old as the
// preconditioner, the iteration matrix is K_old^-1 K = I + K_old^-1 dK, whose
// eigenvalues other than 1 are as many as the rank of dK, so it converges in
// about that many iterations. It stops when the normwise backward error of
// the true residual, |b - K x| / (|K| |x| + |b|) (infinity norms), is at most
// kRefineTolerance; a direct Cholesky's is of the order of n times the unit
// round-off. If it has not converged after as many iterations as cost one
// factorisation, the component is factorised as before (and that factor
// preconditions the attempt's later solves). Every attempt starts with
// factorisations, so a step depends on its start state alone (save and load
// continue bitwise), and the iteration is sequential within a component, so
// the result does not depend on the thread count.
//
// Rigid blocks have 6 unknowns, not 12. Every block keeps the 12-layout in
// storage (contact terms are assembled as for any block), but a rigid block's
// strain unknowns are constrained to zero: alone in its component it is
// solved 6x6 (3 + 3 without springs, by World), and in a sparse component
// BlockCholesky replaces its strain rows and columns by the identity's, with
// a zero right-hand side. That is exactly the restriction of the quadratic
// energy to the rigid subspace (tests/cpp/solver/test_rigid_blocks.cpp
// compares with the dense system with those rows struck out); its
// solution's strain part is set to zero.
#pragma once

#include "BlockCholesky.hpp"
#include "BlockConjugateGradient.hpp"
#include "BlockEquations.hpp"

#include <cstddef>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

namespace dda {

class CoupledSystem {
public:
	// Sets the structure: `links` lists pairs of moving-block indices
	// (0 .. movingBlocks-1) joined by a closed contact; `hasSprings[k]` says
	// whether block k has closed contacts or fixed points (so belongs to the
	// system; both blocks of a link must have it); `unknowns[k]` is its number
	// of unknowns (kBlockDofs, or kRigidBlockDofs for a rigid block).
	void build(int movingBlocks, const std::vector<std::pair<int, int>>& links, const std::vector<char>& hasSprings,
	           const std::vector<int>& unknowns);
	// Whether moving block k belongs to the system (had springs at the last build).
	bool coupled(int k) const { return slot_[k] >= 0; }
	// Blocks that belong to the system.
	int blocks() const { return static_cast<int>(members_.size()); }

	// Starts an assembly: each coupled block k from its own system,
	// systems[systemOf[k]].
	void reset(const std::vector<BlockSystem>& systems, const std::vector<int>& systemOf);
	// Coupled block k's diagonal block and force.
	Matrix12& diagonal(int k) { return diagonal_[slot_[k]]; }
	Vector12& force(int k) { return force_[slot_[k]]; }
	// The off-diagonal block of row a, column b (a, b joined by build's links);
	// the (b, a) block is its transpose and is not stored.
	Matrix12& offDiagonal(int a, int b, bool& transposed);

	// Solves every component; solutions[k] for each coupled moving block k
	// (the others are left as they are). Throws std::runtime_error if a
	// factorisation fails (K not positive definite).
	void solve(std::vector<Vector12>& solutions, int threadsFrom);

	int components() const { return static_cast<int>(componentStart_.size()) - 1; }
	// The last assembly, as solved (for export, yade_dda.coupledSystem):
	// per slot its moving block, unknowns, diagonal block (K in its lower
	// triangle) and force; per link its slots (lo, hi) and K[lo][hi];
	// component c holds slots componentStarts()[c] .. componentStarts()[c+1]-1.
	const std::vector<int>& slotBlocks() const { return members_; }
	const std::vector<int>& slotUnknowns() const { return unknowns_; }
	const std::vector<Matrix12>& diagonalBlocks() const { return diagonal_; }
	const std::vector<Vector12>& forces() const { return force_; }
	const std::vector<std::pair<int, int>>& linkSlots() const { return linkSlots_; }
	const std::vector<Matrix12>& offDiagonalBlocks() const { return offDiagonal_; }
	const std::vector<int>& componentStarts() const { return componentStart_; }
	int largestComponent() const;
	// Unknowns factorised by the last solve, all components together.
	long solvedUnknowns() const { return solvedUnknowns_; }
	// Heap held [bytes] (the arrays' capacities).
	std::size_t memoryBytes() const;

	// Sparse components whose analysis was reused by the last solve, and analysed anew.
	int reusedAnalyses() const { return reusedAnalyses_; }
	int newAnalyses() const { return newAnalyses_; }
	// Without reuse every solve analyses its components afresh (for tests).
	void setAnalysisReuse(bool reuse) { reuse_ = reuse; }

	// A new attempt: factors of earlier attempts no longer precondition.
	// `refine` turns refinement on for the attempt's later solves (above; it
	// needs analysis reuse, which keeps the factors).
	void beginAttempt(bool refine) {
		++attempt_;
		refine_ = refine;
		warm_ = false;
		factorByMembers_.clear();
	}
	// Components the last solve refined instead of factorising, their
	// conjugate-gradient iterations, and refinements that did not converge
	// (and were factorised).
	int refinedComponents() const { return refinedComponents_; }
	int refineIterations() const { return refineIterations_; }
	int refineFallbacks() const { return refineFallbacks_; }

	// The iterative path (above): components of at least `fromBlocks` blocks
	// are solved by preconditioned conjugate gradients to the backward error
	// `tolerance` (then factorised if it has not within
	// kMaxIterativeIterations); fromBlocks <= 0 turns it off.
	// Components of at least `coarseFrom` blocks (coarseFrom > 0) add the
	// coarse level to its preconditioner (AffineCoarseSpace.hpp), which
	// needs the moving blocks' centroids (setCentroids).
	void setIterative(int fromBlocks, double tolerance, int coarseFrom = 0) {
		iterativeFrom_ = fromBlocks;
		iterativeTolerance_ = tolerance;
		coarseFrom_ = coarseFrom;
	}
	// Per moving block, the point its unknowns refer to [m]; the vector must
	// outlive the solves.
	void setCentroids(const std::vector<Vector3>* centroids) { centroids_ = centroids; }
	// Components the last solve solved iteratively, their iterations, and
	// those that did not converge (and were factorised).
	int iterativeComponents() const { return iterativeComponents_; }
	// Aggregates of the coarse levels of the last solve (all components).
	int coarseAggregates() const { return coarseAggregates_; }
	int iterativeIterations() const { return iterativeIterations_; }
	int iterativeFallbacks() const { return iterativeFallbacks_; }

private:
	struct Analysis;  // a sparse pattern's matrix, value map and analysed factorisation
	struct AnalysisDeleter {
		void operator()(Analysis* a) const;
	};
	using AnalysisPtr = std::unique_ptr<Analysis, AnalysisDeleter>;
	// build's last part: each sparse component's kept analysis (found by its
	// pattern, or added), and the unused ones dropped.
	void keepAnalyses();
	// Solves the component of the single block in `slot` (a dense Cholesky of
	// its 12 or 6 unknowns); false when the factorisation fails.
	bool solveSingleBlock(int slot, std::vector<Vector12>& solutions) const;
	// Writes component c's solution x (per slot from its first) to its
	// blocks' solutions, a rigid block's strain part zero.
	void writeSolutions(int c, const std::vector<Vector12>& x, std::vector<Vector12>& solutions) const;
	// Component c's links within it: (lo, hi) slots less its first slot.
	std::vector<std::pair<int, int>> localLinks(int c) const;
	// Factorises component c's system (analysing its pattern first when
	// `analyse`) and writes its blocks' solutions; false when the
	// factorisation fails.
	bool solveComponent(int c, BlockCholesky& cholesky, bool analyse, std::vector<Vector12>& solutions) const;
	// Solves component c by conjugate gradients preconditioned with
	// `factor` (of an earlier matrix of the same blocks), at most
	// `maxIterations` iterations; writes its blocks' solutions and returns
	// true when converged (`iterations` the count either way).
	bool refineComponent(int c, const BlockCholesky& factor, int maxIterations, std::vector<Vector12>& solutions,
	                     int& iterations) const;
	// |K| of component c: the infinity norm of its restricted system.
	double componentNorm(int c) const;
	// The kept analysis holding a factor of this attempt for component c's
	// blocks that no other component of this build uses, or null.
	Analysis* preconditionerFor(int c) const;
	std::size_t membersHash(int c) const;

	std::vector<int> slot_;            // per moving block: its slot, -1 when it has no springs
	std::vector<int> members_;         // per slot: the moving block
	std::vector<int> unknowns_;        // per slot: 12, or 6 when rigid
	std::vector<int> componentStart_;  // component c holds slots componentStart_[c] .. componentStart_[c+1]-1
	std::vector<Matrix12> diagonal_;   // per slot
	std::vector<Vector12> force_;      // per slot
	// Per link, the slots (lo, hi), lo < hi, sorted; its stored block is
	// K[lo][hi]. Component c's links are linkStart_[c] .. linkStart_[c+1]-1.
	std::vector<std::pair<int, int>> linkSlots_;
	std::vector<int> linkStart_;
	std::vector<Matrix12> offDiagonal_;  // per link
	long solvedUnknowns_ = 0;
	// Kept analyses, by pattern hash; per component its analysis (null for a
	// single block, or not yet analysed).
	std::vector<AnalysisPtr> analyses_;
	std::unordered_multimap<std::size_t, Analysis*> analysisByHash_;
	std::vector<Analysis*> componentAnalysis_;
	std::vector<std::size_t> componentHash_;
	long builds_ = 0;
	bool reuse_ = true;
	int reusedAnalyses_ = 0, newAnalyses_ = 0;
	long attempt_ = 0, solves_ = 0;
	// This attempt's factors by the hash of their blocks (membersHash).
	std::unordered_multimap<std::size_t, Analysis*> factorByMembers_;
	bool refine_ = false;
	int refinedComponents_ = 0, refineIterations_ = 0, refineFallbacks_ = 0;
	// The iterative path: settings, its solver (the components it takes run
	// one after another), and whether the solutions hold this attempt's last
	// solve (the first iterate).
	int iterativeFrom_ = 0, coarseFrom_ = 0;
	double iterativeTolerance_ = 0;
	const std::vector<Vector3>* centroids_ = nullptr;
	std::vector<Vector3> slotCentroids_;
	BlockConjugateGradient iterative_;
	bool warm_ = false;
	int iterativeComponents_ = 0, iterativeIterations_ = 0, iterativeFallbacks_ = 0, coarseAggregates_ = 0;
	// Solves component c iteratively; true when it converged.
	bool iterateComponent(int c, std::vector<Vector12>& solutions, int& iterations, int threadsFrom);
	// solve's parts: the iterative path's components (iterated[c] set for
	// those it solved, their unknowns added to `solved`, its statistics
	// set); the refinement's iteration budget for component c from the
	// factor `from`; a component factorised (`how`: with its kept analysis,
	// made now or earlier, or with a factorisation of its own); and the
	// factors made now kept to precondition the attempt's later solves.
	void iterateLargeComponents(std::vector<Vector12>& solutions, int threadsFrom, std::vector<char>& iterated,
	                            long& solved);
	long refineBudget(int c, const Analysis& from) const;
	enum class Factorisation { Own, NewAnalysis, KeptAnalysis };
	bool factorComponent(int c, std::vector<Vector12>& solutions, Factorisation& how);
	void keepFactors(const std::vector<char>& factored);
};

}  // namespace dda
