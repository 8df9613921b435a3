// The open-close iteration of a step (OpenClose.cpp): Newton's method on the
// step's energy over the moving blocks, in passes whose friction limits are
// fixed, per group of blocks that contacts join, with a line search once a
// contact swings back or slips, until every group's pass converges with its
// limits settled. The step's linear system (OpenCloseAssembly.cpp: structure,
// the blocks' own systems, the contacts' terms, kept within an attempt) and
// the line search (LineSearch.cpp) are its parts. World owns one and calls it
// once per attempt at a time step; TimeStepControl decides on the attempts.
#pragma once

#include "BlockEquations.hpp"
#include "ContactEquations.hpp"
#include "CoupledSystem.hpp"
#include "IntegratorSettings.hpp"
#include "TimeStepControl.hpp"
#include "dda/block/Block.hpp"
#include "dda/contact/Contact.hpp"

#include <cstddef>
#include <utility>
#include <vector>

namespace dda {

class OpenCloseIteration {
public:
	// The step's moving blocks: those neither fixed nor frozen (frozen empty:
	// none is). Fills stats' block and unknown counts.
	void selectMovingBlocks(const std::vector<Block>& blocks, const std::vector<char>& frozen, StepStatistics& stats);
	const std::vector<int>& moving() const { return moving_; }
	// The coupled system of the last solve, and the moving blocks' centroids
	// its unknowns refer to [m] (for export).
	const CoupledSystem& coupledSystem() const { return coupled_; }
	const std::vector<Vector3>& solveCentroids() const { return centroids_; }
	// A block's index in moving(), -1 for fixed (or frozen) blocks.
	int movingIndex(int block) const { return movingIndex_[block]; }
	// One attempt of the step at dt: the open-close iteration over `contacts`
	// (this step's, in the contact store) from their start-of-step states;
	// firstStep forms bonds (startTrial). Returns whether every group
	// converged; solution() then holds the attempt's displacements either way.
	bool solve(const std::vector<Block>& blocks, std::vector<Contact>& contacts, const IntegratorSettings& settings,
	           double dt, bool firstStep, StepStatistics& stats);
	// The accepted solution of moving block k (an index of moving()).
	const Vector12& solution(int k) const { return solutions_[k]; }
	// A block's entry of the current iterate; for a fixed block its known
	// displacement (setPrescribed), else zero.
	const Vector12& solutionOf(int block) const;
	// The known displacement of each block over the attempts' dt (indexed
	// by block; a moving block's entry is not read), or nullptr: fixed blocks
	// stay. A fixed block with a prescribed motion (BaseMotion.hpp) has no
	// unknowns; its contacts with moving blocks take its displacement as a
	// known gap and stretch change (addKnownDisplacement). World sets it
	// for each attempt.
	void setPrescribed(const std::vector<Vector12>* prescribed) { prescribed_ = prescribed; }
	bool prescribed() const { return prescribed_ != nullptr; }
	// Largest vertex displacement of the last attempt [m].
	double largestDisplacement(const std::vector<Block>& blocks) const;
	// The moving blocks (block indices, ascending) whose corners the last
	// solution moves by more than `threshold` [m].
	void blocksMovedMoreThan(const std::vector<Block>& blocks, double threshold, std::vector<int>& out) const;
	// The smallest stepJacobian over the moving blocks, and that block.
	StepShrink smallestJacobian(const std::vector<Block>& blocks) const;
	// Whether the solver keeps work between solves (World::setSolverReuse).
	void setSolverReuse(bool reuse) {
		coupled_.setAnalysisReuse(reuse);
		keepTerms_ = reuse;
	}
	// Whether a step makes one pass: its friction limits are those of its
	// start (set from each contact's normal force there; a contact that
	// closes during the step takes none), and a converged pass ends it
	// (closePasses). World::settle's locked stage and ramp after their first
	// static step: their limits follow the normal forces from one static
	// step to the next.
	void setOnePass(bool onePass) { onePass_ = onePass; }
	// Whether limits that do not settle end Coulomb-safe (closePasses; off
	// in World::settle's static steps, which accept them as they stand).
	void setCoulombSafe(bool safe) { coulombSafe_ = safe; }
	// The solver's heap [bytes] (World::MemoryUse::solver, World's motions aside).
	std::size_t memoryBytes() const;

private:
	// The largest displacement [m] of moving block k's corners (all its parts) by its last solution.
	double displacementOf(const std::vector<Block>& blocks, int k) const;
	// One attempt's inputs, as solve() was given them.
	struct Attempt {
		const std::vector<Block>& blocks;
		std::vector<Contact>& contacts;
		const IntegratorSettings& settings;
		double dt;
		StepStatistics& stats;
	};
	// The attempt's start: own systems cleared, trial states and the first
	// pass's limits, start accelerations, groups.
	void startAttempt(const Attempt& attempt, bool firstStep);
	// One solve: structure (when stale), assembly, solve, line search.
	void solveOnce(const Attempt& attempt, bool structureStale);
	// The contacts' states at the new iterate; returns whether the structure
	// changed (a contact opened or closed).
	bool evaluateStates(const Attempt& attempt);
	// Groups whose pass converged: their limits against the normal forces found.
	void measureLimits(std::vector<Contact>& contacts);
	// Which groups are done, which start a new pass; returns whether all are
	// done, adds the state changes of the groups still iterating to changes,
	// and sets `exhausted` when a group has made its last solve (solveBudget)
	// without converging.
	bool closePasses(int iterations, const Attempt& attempt, int& changes, bool& exhausted);
	// The limits of the groups starting a new pass; returns whether the
	// structure changed.
	bool startPasses(const Attempt& attempt);

	// The global system's structure from the contacts' trial states: only
	// closed contacts carry terms, so only they join blocks into components
	// (an open contact within d0 couples nothing until it closes).
	void buildSystemStructure(const Attempt& attempt);
	// The own system (assembleBlock) of each block that the last structure
	// build coupled and that has none yet in this attempt: it is the same at
	// every iteration, so it is kept (ownSystems_) for coupled_.reset.
	void assembleOwnSystems(const Attempt& attempt);
	// Each moving block that the last build left out of coupled_ (no springs)
	// and that has no solution yet in this attempt, by its own 3 + 9 solve
	// (solveBlock). Its system is the same at every iteration, so it is solved
	// once per attempt, and assembled here on the stack rather than kept (its
	// assembly counts as solve time).
	void solveAloneBlocks(const Attempt& attempt);
	// Adds the trial-state terms of every contact to coupled_ (counted in stats).
	void assembleContacts(const Attempt& attempt);
	// A contact's energy is a function of (D_i, D_j); with the displacement
	// of its fixed side known (prescribed_), the moving side's Newton model
	// K_ii D_i = F_i takes the known part to the right-hand side:
	// F_i -= K_ij D_j, term by term (K = sum_r w_r v_r v_r^T).
	void addKnownDisplacement(const ContactTerms& terms, int mi, int mj, int bi, int bj);
	const std::vector<Vector12>* prescribed_ = nullptr;
	// Within an attempt a contact's Newton terms (contactTerms) depend on its
	// state alone unless it slips or carries a secant force: the normal
	// spring's on the start-of-step linearisation, the stick spring's on the
	// anchors, neither of which moves before the attempt ends. So the terms
	// of such a contact are kept (keptTerms_, up to kKeptTermsBytes in
	// OpenCloseAssembly.cpp) with the state they were made for (keptTermsKey_:
	// whether it has normal terms, its tangential term), and added again while
	// it keeps that state: the same numbers, added in the same order. Cleared
	// at each attempt's start.
	//
	// Why the key is all they depend on: contactTerms reads the contact's
	// linearisation (normal.ei, ej, d0, valid), stiffnesses, geometry.normal,
	// gamma and weights (set by prepareContact before the attempts), the
	// anchors (set by startTrial at the attempt's start, moved only after the
	// accepted solve), the blocks' centroids (moved after it too), and which
	// terms the state asks for (hasNormalTerms, tangentialTerm: the key).
	// Besides these, only a slipping contact's terms read its stretch and
	// limit, and only the secant's (secantWeight > 0, gamma < 1) read the
	// trial gap and the bond, both of which change from solve to solve; such
	// contacts are never kept. (Keying the secant's on its trial gap as well
	// would be correct but useless: the gap is that of the last solve, which
	// differs at every solve that moves the contact.) Under Shi's scheme
	// secantWeight is 0 and this is the rule as first written.
	std::vector<ContactTerms> keptTerms_;
	std::vector<int> keptTermsOf_;             // per contact: its entry of keptTerms_, -1 if none
	std::vector<unsigned char> keptTermsKey_;  // per contact: the state its kept terms are for
	bool keepTerms_ = true;
	bool coulombSafe_ = true;
	bool onePass_ = false;
	// Newmark's start acceleration a0 of each moving block (unless Shi's
	// scheme, which does not read it): M^-1 times the block's own forces at
	// D = 0 (restForce). Contacts are left out: they enter as the step's mean
	// force (ContactEquations.hpp), so a contact that opens within a step
	// does not push with its start force over the whole step. Computed each
	// step, not carried (nothing to save).
	void computeStartAccelerations(const Attempt& attempt);
	const Vector12& startAccelerationOf(int movingIndex) const;
	std::vector<Vector12> startAccelerations_;
	// Moves the iterate (iterate_) towards the Newton solution (solutions_)
	// by the step t in (0, 1] that minimises the step's energy along the way
	// (1 unless a contact slips or crosses a kink of its energy), per group
	// of blocks that contacts join (groupContacts), leaving converged groups
	// where they are; returns the smallest t (LineSearch.cpp).
	double lineSearch(const Attempt& attempt);
	// Marks the groups whose line must be searched (groupKink_) and collects
	// every contact's line (lines_, lineGroup_).
	void markSearchedGroups(const Attempt& attempt);
	// The blocks' slope and curvature of each searched group along the step.
	void blockSlopes(const Attempt& attempt);
	// The lines of each searched group, together (orderedLines_, groupLines_).
	void orderLines();
	// Groups the moving blocks that contacts join (groupRoot_: per moving
	// block its group's root; contactGroup_: per contact its group).
	void groupContacts(const std::vector<Contact>& contacts);
	// A block's entry of deltas_ (the Newton step from the iterate); zero for fixed blocks.
	const Vector12& deltaOf(int block) const;
	// Per group of the step's iteration (indexed by root).
	struct GroupIteration {
		std::vector<char> done, hasContacts, swungBack, newPass;
		// coulombSafe: 0 while the group's passes settle its limits, then
		// 1 + the Coulomb-safe passes it has started (closePasses).
		std::vector<int> passes, passSolves, changes, coulombSafe;
		// limitChange: relative to its contacts' scales.
		std::vector<double> forceChange, largestNormalForce, limitChange;
		void reset(int groups);
		void startIteration();
		bool passConverged(int g, double tolerance) const;
		std::size_t memoryBytes() const;
	};
	GroupIteration group_;
	std::vector<int> contactGroup_;
	CoupledSystem coupled_;
	std::vector<int> movingIndex_;  // block -> index in moving_, -1 for fixed blocks
	std::vector<std::pair<int, int>> links_;  // buildSystemStructure's work arrays
	std::vector<char> hasSprings_;
	std::vector<double> blockLimit_;  // measureLimits' work array: per moving block, its contacts' largest limit [N]
	std::vector<int> blockUnknowns_;  // per moving block: 12, or 6 when rigid
	long aloneUnknowns_ = 0;          // of the moving blocks left out of coupled_
	// per-step work arrays, kept to avoid reallocation
	std::vector<int> moving_;
	std::vector<Vector12> solutions_;  // the last Newton solution, per moving block
	std::vector<Vector3> centroids_;   // per moving block at the attempt's start (the coarse level's)
	std::vector<Vector12> iterate_;    // the current iterate of the step's iteration
	std::vector<Vector12> deltas_;     // lineSearch's work arrays
	std::vector<ContactLine> lines_, orderedLines_;  // per contact; the searched groups' lines, group by group
	std::vector<int> groupRoot_, lineGroup_, groupLines_;
	std::vector<char> groupKink_;
	std::vector<double> groupSlope_, groupCurvature_, groupStep_;
	// This attempt's own systems of the blocks coupled at some build
	// (ownSystemOf_: per moving block, its index there, -1 if none), and which
	// blocks left alone already have their solution.
	std::vector<BlockSystem> ownSystems_;
	std::vector<int> ownSystemOf_;
	std::vector<char> solvedAlone_;
};

}  // namespace dda
