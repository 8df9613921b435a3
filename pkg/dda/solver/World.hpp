// The DDA scene: its blocks and the implicit step that advances them.
// One World per YADE scene; the Python side maps YADE body ids to block indices.
#pragma once

#include "BlockEquations.hpp"
#include "ContactEquations.hpp"
#include "CoupledSystem.hpp"
#include "IntegratorSettings.hpp"
#include "dda/block/Block.hpp"
#include "dda/collider/Collider.hpp"
#include "dda/contact/Contact.hpp"

#include <memory>
#include <utility>
#include <vector>

namespace dda {

class StateWriter;
class StateReader;

// A block at rest built from its corners [m] and material, not in any world
// (throws InputError naming the problem). World::addBlock adds one.
Block makeBlock(const std::vector<Vector3>& points, const Material& material, bool fixed, bool rigid = false);

// Diagonal of a block's bounding box [m].
double boundingDiagonal(const Block& block);

// The narrow phase's settings for a pair of blocks of bounding diagonals
// diagonalA and diagonalB [m], as World::step uses them: contact distance d0
// [m], length tolerance, entrance hysteresis and corner merge distance from the
// blocks' sizes, and the parallel-edge angle from the allowed step
// displacement [m] (0: the smallest angle tolerance).
DetectionSettings pairDetectionSettings(double diagonalA, double diagonalB, double contactDistance,
                                        double allowedDisplacement);

class World {
public:
	// Builds and validates a block (throws InputError; the world is unchanged then).
	// A rigid block has 6 unknowns (translation, rotation) and no strain or stress.
	int addBlock(const std::vector<Vector3>& points, const Material& material, bool fixed, bool rigid = false);
	// Room for `extra` more blocks before they are added one by one: the
	// block array then holds what the scene needs instead of up to twice that
	// (push_back's doubling: 65,536 blocks of storage for 50,000), and is not
	// copied while it grows. Exactly size + extra when the batch is at least
	// as large as the scene, else at least double, so that many small batches
	// still cost amortized constant time per block.
	void reserveBlocks(int extra);
	std::size_t blockCapacity() const { return blocks_.capacity(); }
	int blockCount() const { return static_cast<int>(blocks_.size()); }
	Block& block(int index);
	const Block& block(int index) const;

	// Holds the material point now at `position` of a block with a penalty spring
	// [N/m]; stiffness <= 0 picks IntegratorSettings' default at each step.
	void addFixedPoint(int index, const Vector3& position, double stiffness);
	void addPointLoad(int index, const Vector3& position, const Vector3& force);
	void setVelocity(int index, const Vector3& velocity, const Vector3& angularVelocity);
	void setStress(int index, const Vector6& stress);

	// Advances all blocks by one accepted step; returns the dt taken [s].
	// The first step starts from rest (settle) when settings ask for it.
	double step(const IntegratorSettings& settings);
	const StepStatistics& lastStep() const { return stats_; }
	// Heap held now [bytes] (computed when asked, not every step): the broad
	// phase's arrays (Collider::memoryBytes), the contact store (with the last
	// step's contacts kept for their history), and the narrow phase's work
	// arrays (per block: diagonal, planes entry, last chunk; the candidate
	// pairs; the planes entries and pooled pair results, sized by a chunk of
	// pairs). Between steps they are what the last detection left. The
	// solver's: the per-step arrays of the moving blocks (solutions, motions,
	// the own systems of the blocks with springs) and the coupled system
	// (CoupledSystem::memoryBytes), as the last step left them.
	struct MemoryUse {
		std::size_t collider = 0, contacts = 0, narrowPhase = 0, solver = 0;
	};
	MemoryUse memoryUse() const;
	// The energy account now (EnergyAccount, IntegratorSettings.hpp) [J].
	EnergyAccount energy() const;
	double time() const { return time_; }
	long steps() const { return steps_; }
	// Sub-contacts of the last step, with their state at its end.
	const std::vector<Contact>& contacts() const { return store_.contacts(); }
	// The broad phase (DESSCollider unless set).
	void setCollider(std::unique_ptr<Collider> collider);
	const Collider& collider() const { return *collider_; }
	// Whether the solver keeps work between solves: the sparse components'
	// analyses (CoupledSystem.hpp) and, within an attempt, the terms of
	// contacts that neither slip nor carry a secant force (keptTerms_); and
	// whether the line search skips the evaluations whose sign is certain
	// (searchLine). On by default; the results are bitwise the same (off for
	// tests).
	void setSolverReuse(bool reuse) {
		coupled_.setAnalysisReuse(reuse);
		keepTerms_ = reuse;
	}
	// Half the largest extent of the bounding box of all blocks [m] (Shi's w0),
	// measured at the first step after blocks were added.
	double sceneHalfSize();

	// Saving (WorldState.cpp): writes every member that affects later steps,
	// in container order (contact order decides summation order, hence
	// round-off), so a restored world continues bitwise as this one would.
	// readState replaces this world's state, or throws StateError and leaves
	// it unchanged.
	void writeState(StateWriter& out) const;
	void readState(StateReader& in);

private:
	// One accepted step of the blocks not frozen (frozen_), as step() makes it.
	double advance(const IntegratorSettings& settings);
	// Start from rest (IntegratorSettings::startFromRest): static steps
	// (Shi's static analysis: no velocity carried, inertia of a step long
	// enough to weigh 1e-3 of a contact's stiffness) with friction locked,
	// for the blocks at rest whose touching contacts join them to a fixed
	// block or point (the rest frozen), until a step moves no vertex by more
	// than kSettleTolerance of the first's; then velocities zero, the
	// account restarted. Not converged within kSettleSteps (no equilibrium
	// with these contacts): the scene is restored as placed.
	void settle(const IntegratorSettings& settings);
	// frozen_ for settling: per block, 1 unless it settles (see settle).
	void markSettlingBlocks();
	std::vector<char> frozen_;   // per block while settling, else empty
	bool settling_ = false;
	double frictionScale_ = 1;   // friction tangents x this (settling: locked)
	bool settleTried_ = false;
	int settleSteps_ = 0, settledBlocks_ = 0;
	bool settleConverged_ = false;
	// Broad and narrow phase; fills store_ with this step's sub-contacts.
	void detectContacts(const IntegratorSettings& settings, StepStatistics& stats);
	// The global system's structure from the contacts' trial states: only
	// closed contacts carry terms, so only they join blocks into components
	// (an open contact within d0 couples nothing until it closes).
	void buildSystemStructure(int movingBlocks, StepStatistics& stats);
	// The own system (assembleBlock) of each block that the last structure
	// build coupled and that has none yet in this attempt: it is the same at
	// every iteration, so it is kept (ownSystems_) for coupled_.reset.
	void assembleOwnSystems(const IntegratorSettings& settings, double dt);
	// Each moving block that the last build left out of coupled_ (no springs)
	// and that has no solution yet in this attempt, by its own 3 + 9 solve
	// (solveBlock). Its system is the same at every iteration, so it is solved
	// once per attempt, and assembled here on the stack rather than kept (its
	// assembly counts as solve time).
	void solveAloneBlocks(const IntegratorSettings& settings, double dt);
	// Adds the trial-state terms of every contact to coupled_ (counted in stats).
	void assembleContacts(StepStatistics& stats);
	// Within an attempt a contact's Newton terms (contactTerms) depend on its
	// state alone unless it slips or carries a secant force: the normal
	// spring's on the start-of-step linearisation, the stick spring's on the
	// anchors, neither of which moves before the attempt ends. So the terms
	// of such a contact are kept (keptTerms_, up to kKeptTermsBytes in
	// World.cpp) with the state they were made for (keptTermsKey_: whether
	// it has normal terms, its tangential term), and added again while it
	// keeps that state: the same numbers, added in the same order. Cleared
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
	struct KeptTerms {
		Matrix24 stiffness;
		Vector24 force;
	};
	std::vector<KeptTerms> keptTerms_;
	std::vector<int> keptTermsOf_;             // per contact: its entry of keptTerms_, -1 if none
	std::vector<unsigned char> keptTermsKey_;  // per contact: the state its kept terms are for
	bool keepTerms_ = true;
	// Adds the accepted step's dissipation, work of loads and contact springs'
	// changes to the account (energy_), and records the springs' energy at its
	// end; called before the contacts and blocks are moved.
	void accountStep(const IntegratorSettings& settings);
	// Newmark's start acceleration a0 of each moving block (unless Shi's
	// scheme, which does not read it): M^-1 times the block's own forces at
	// D = 0 (restForce). Contacts are left out: they enter as the step's mean
	// force (ContactEquations.hpp), so a contact that opens within a step
	// does not push with its start force over the whole step. Computed each
	// step, not carried (nothing to save).
	void computeStartAccelerations(const IntegratorSettings& settings);
	const Vector12& startAccelerationOf(int movingIndex) const;
	std::vector<Vector12> startAccelerations_;
	// Moves the iterate (iterate_) towards the Newton solution (solutions_)
	// by the step t in (0, 1] that minimises the step's energy along the way
	// (1 unless a contact slips or crosses a kink of its energy), per group
	// of blocks that contacts join (groupContacts), leaving converged groups
	// where they are; returns the smallest t.
	double lineSearch(const IntegratorSettings& settings, double dt);
	// Groups the moving blocks that contacts join (groupRoot_: per moving
	// block its group's root; contactGroup_: per contact its group).
	void groupContacts();
	// Per group of the step's iteration (indexed by root).
	struct GroupIteration {
		std::vector<char> done, hasContacts, swungBack, newPass;
		std::vector<int> passes, passSolves, changes;
		std::vector<double> forceChange, largestNormalForce, limitChange, largestLimit;
		void reset(int groups);
		void startIteration();
		bool passConverged(int g, double tolerance) const;
		std::size_t memoryBytes() const;
	};
	GroupIteration group_;
	std::vector<int> contactGroup_;
	// A block's entry of the current iterate; zero for fixed blocks.
	const Vector12& solutionOf(int block) const;
	// A block's start-of-step velocity (startVelocity); zero for fixed blocks.
	Vector12 startVelocityOf(int block, const IntegratorSettings& settings) const;
	std::unique_ptr<Collider> collider_ = std::make_unique<DESSCollider>();
	ContactStore store_;
	CoupledSystem coupled_;
	long openCloseFailures_ = 0;
	std::vector<std::pair<int, int>> pairs_;
	// The narrow phase runs the candidate pairs in chunks (kPairChunk in
	// World.cpp), so what it holds is sized by a chunk, not by the scene.
	// Per pair of the current chunk, its result (a pool: each entry keeps its
	// contacts' capacity from chunk to chunk and step to step, so detection
	// allocates only while it grows), whether it is in contact, and its work.
	std::vector<PairContacts> pairResults_;
	std::vector<char> pairFound_;
	std::vector<NarrowPhaseWork> pairWork_;
	std::vector<int> movingIndex_;  // block -> index in moving_, -1 for fixed blocks
	std::vector<BlockMotion> motions_;
	std::vector<double> diagonals_;  // per block, bounding-box diagonal of this step [m]
	// Entries for the face planes, edge data and bounding box (BlockPlanes) of
	// the blocks of the current chunk's pairs: a block's are built before the
	// parallel pair loop of the first chunk with a pair of it (planeBlocks_
	// lists those of this chunk), read-only in the loops, and its entry goes
	// back to freePlanes_ after its last chunk (lastChunk_). planes_ is only
	// grown, so its entries keep their vectors' capacity.
	std::vector<BlockPlanes> planes_;
	std::vector<int> freePlanes_;
	std::vector<int> planeBlocks_;
	std::vector<int> planeSlot_;  // per block: its entry of planes_, -1 when none
	std::vector<int> lastChunk_;  // per block: the last chunk with a pair of it (this step)
	// Faces of fixed blocks covered by a flush neighbour (BlockGeometry::internalFaces).
	std::vector<std::vector<char>> internalFaces_;
	int internalFacesBlocks_ = -1;  // block count when internalFaces_ was computed
	std::vector<Vector3> points_;
	std::vector<std::pair<int, int>> links_;  // buildSystemStructure's work arrays
	std::vector<char> hasSprings_;
	std::vector<int> blockUnknowns_;  // per moving block: 12, or 6 when rigid
	long aloneUnknowns_ = 0;          // of the moving blocks left out of coupled_
	std::vector<Block> blocks_;
	TopologyPool topologies_;  // the blocks' shared topologies
	StepStatistics stats_;
	// The account's cumulative terms (friction, damping, loads,
	// contactChanges) and the springs' energy at the end of the last step
	// (contact); gravity of the last step, for the potential.
	EnergyAccount energy_;
	Vector3 gravity_ = Vector3::Zero();
	double nextTimeStep_ = 0;  // dt to try first in the next step; 0 = maxTimeStep
	double time_ = 0;
	long steps_ = 0;
	long displacementLimitMisses_ = 0;
	double sceneHalfSize_ = 0;
	int sceneSizedBlocks_ = -1;  // block count when sceneHalfSize_ was measured
	// per-step work arrays, kept to avoid reallocation
	std::vector<int> moving_;
	std::vector<Vector12> solutions_;  // the last Newton solution, per moving block
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
