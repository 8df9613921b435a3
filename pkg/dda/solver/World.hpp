// The DDA scene: its blocks and the implicit step that advances them.
// One World per YADE scene; the Python side maps YADE body ids to block indices.
#pragma once

#include "BaseMotion.hpp"
#include "BlockEquations.hpp"
#include "ContactDetection.hpp"
#include "ContactEquations.hpp"
#include "CoupledSystem.hpp"
#include "IntegratorSettings.hpp"
#include "OpenClose.hpp"
#include "TimeStepControl.hpp"
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

// The blocks of a concave block made of convex parts, each given by its
// corners [m] (Block::body: the first is its body, the others refer to it by
// an index relative to the first, which World::addConcaveBlock offsets).
// Throws InputError naming the part and the problem: a part that is no
// convex polyhedron (buildConvexPolyhedron), parts that overlap, share a face
// only in part, or are not one piece (checkConvexParts). One part makes an
// ordinary convex block.
std::vector<Block> makeConcaveBlock(const std::vector<std::vector<Vector3>>& parts, const Material& material,
                                    bool fixed, bool rigid = false);

// boundingDiagonal and pairDetectionSettings: ContactDetection.hpp.

class World {
public:
	// Builds and validates a block (throws InputError; the world is unchanged then).
	// A rigid block has 6 unknowns (translation, rotation) and no strain or stress.
	int addBlock(const std::vector<Vector3>& points, const Material& material, bool fixed, bool rigid = false);
	// A concave block (makeConcaveBlock): its parts join the world as
	// consecutive blocks; returns the index of the first, its body, which
	// carries its unknowns, mass properties and state (Block::body).
	int addConcaveBlock(const std::vector<std::vector<Vector3>>& parts, const Material& material, bool fixed,
	                    bool rigid = false);
	// The body a block moves with (bodyIndex; itself unless it is a later
	// part of a concave block).
	int bodyOf(int index) const { return bodyIndex(blocks_, index); }
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
	// A prescribed translation (BaseMotion.hpp) of the fixed blocks
	// `indices` (a concave block with all its parts); returns the motion's
	// index. Throws InputError naming the block: an index out of range, a
	// block that is not fixed, one given twice or that has a motion already.
	// The blocks move from the first dynamic step on (never while settling:
	// start from rest holds them where they are). PrescribedMotion.cpp.
	int addBaseMotion(const std::vector<int>& indices, BaseMotion motion);
	int baseMotionCount() const { return static_cast<int>(baseMotions_.size()); }
	const BaseMotion& baseMotion(int motion) const;
	// The blocks (parts) a motion moves, ascending.
	const std::vector<int>& baseMotionBlocks(int motion) const;

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
	// Start from rest: the blocks (indices, ascending) still moving by more
	// than the quiet level at the last static step of a stage that gave up:
	// the locked stage (the scene starts as placed) or the stage with the
	// true friction (the locked state is kept; these blocks cannot be held by
	// friction). Empty when the settling converged; not saved.
	const std::vector<int>& unsettledBlocks() const { return unsettled_; }
	// The broad phase (DESSCollider unless set).
	void setCollider(std::unique_ptr<Collider> collider);
	const Collider& collider() const { return *collider_; }
	// (Its settings, e.g. Collider::setCover, taken at the next step.)
	Collider& collider() { return *collider_; }
	// Whether the solver keeps work between solves: the sparse components'
	// analyses (CoupledSystem.hpp) and, within an attempt, the terms of
	// contacts that neither slip nor carry a secant force (keptTerms_); and
	// whether the line search skips the evaluations whose sign is certain
	// (searchLine). On by default; the results are bitwise the same (off for
	// tests).
	void setSolverReuse(bool reuse) { openClose_.setSolverReuse(reuse); }
	// The last step's open-close iteration: its moving blocks and the system
	// of its last solve (read only, for export).
	const OpenCloseIteration& openClose() const { return openClose_; }
	// Shi's w0 [m]: half the largest extent of the bounding box of the moving
	// blocks (TimeStepControl::motionHalfSize), measured at the first step
	// after blocks were added.
	double motionHalfSize();

	// Saving (WorldState.cpp): writes every member that affects later steps,
	// in container order (contact order decides summation order, hence
	// round-off), so a restored world continues bitwise as this one would.
	// readState replaces this world's state, or throws StateError and leaves
	// it unchanged.
	void writeState(StateWriter& out) const;
	void readState(StateReader& in);

private:
	// The block `index` moves with (bodyOf), after checking the index: what
	// the setters above change (a concave block's state is its body's).
	Block& bodyBlock(int index);
	// One accepted step of the blocks not frozen (frozen_), as step() makes it.
	double advance(const IntegratorSettings& settings);
	// The attempts of a step (OpenCloseIteration::solve) at the dt that
	// TimeStepControl gives and cuts; returns the dt accepted.
	double solveStep(const IntegratorSettings& settings, StepStatistics& stats);
	// The accepted step applied: the contacts' forces and anchors (counted in
	// stats), then the blocks' displacements and velocities.
	void moveContactsAndBlocks(const IntegratorSettings& settings, double dt, StepStatistics& stats);

	// Start from rest (IntegratorSettings::startFromRest; Settling.cpp):
	// static steps (Shi's static analysis: no velocity carried, inertia of a
	// step long enough to weigh 1e-3 of a contact's stiffness) with friction
	// locked, for the blocks at rest whose touching contacts join them to a
	// fixed block or point (the rest frozen), until a step moves no vertex by
	// more than kSettleTolerance of the first's, or several in a row leave
	// the blocks quiet (by no more than kSettleQuiet of it, or an out-of-balance
	// force of at most kSettleQuietAcceleration of their weight); then
	// velocities zero, the account restarted. Not converged within
	// kSettleSteps (no equilibrium with these contacts): the scene is
	// restored as placed.
	void settle(const IntegratorSettings& settings);
	// settle's static steps, and its second stage with the true friction.
	bool settlingSteps(const IntegratorSettings& statics, double longest, double& reference);
	// One static step (counted in settleSteps_), the settling blocks' velocities
	// zeroed after it; false when it has no static solution.
	bool staticStep(const IntegratorSettings& statics, double longest);
	void admitFriction(const IntegratorSettings& statics, double longest, double reference);
	// frozen_ for settling: per block, 1 unless it settles (see settle).
	void markSettlingBlocks();
	// While settling: drops the contacts of two frozen (or fixed) blocks.
	void dropFrozenContacts(StepStatistics& stats);
	// After a converged start from rest: contacts at their friction limit start locked.
	void lockSettledContacts();
	std::vector<char> frozen_;   // per block while settling, else empty
	bool settling_ = false;
	bool polishing_ = false;     // the final static steps with their passes (admitFriction)
	double frictionScale_ = 1;   // friction tangents x this (settling: locked)
	bool settleTried_ = false;
	int settleSteps_ = 0, settledBlocks_ = 0;
	long settleSolves_ = 0, settleLimitPasses_ = 0;
	bool settleConverged_ = false;
	std::vector<int> unsettled_;  // see unsettledBlocks()

	// Prescribed motions (PrescribedMotion.cpp): each with its blocks.
	struct ShakenGroup {
		BaseMotion motion;
		std::vector<int> blocks;
	};
	std::vector<ShakenGroup> baseMotions_;
	// Per block, its known displacement over the attempt [time_, time_ + dt]
	// (zero for blocks without a motion), and the largest translation among
	// them [m]; filled only when the step has motions (shaking()).
	std::vector<Vector12> prescribed_;
	double prescribedLargest_ = 0;
	// Whether this step moves the shaken blocks: there are motions, and it
	// is no static step of the start from rest.
	bool shaking() const { return !baseMotions_.empty() && !settling_; }
	void prescribeMotions(double dt);
	// After an accepted step: the shaken blocks (and their parts) translated
	// by their known displacement, their velocity the motion's at the end.
	void moveShakenBlocks(double dt);
	// The work [J] a contact's known side does on its moving side over the
	// accepted step: -gamma f_j . D_j, f_j the force on the known side of the
	// solve's model (F - K D), gamma the scheme's (its mean force).
	double boundaryWork(const Contact& contact, double gamma) const;
	// The shaken flags of the blocks from baseMotions_ (after a load).
	void markShakenBlocks();
	// Saving (WorldState.cpp): the motions, their blocks and the work done;
	// reading them sets the blocks' shaken flags.
	void writeBaseMotions(StateWriter& out) const;
	void readBaseMotions(StateReader& in);

	// Adds the accepted step's dissipation, work of loads and contact springs'
	// changes to the account (energy_), and records the springs' energy at its
	// end; called before the contacts and blocks are moved (EnergyAccount.cpp).
	void accountStep(const IntegratorSettings& settings, double dt);
	// accountStep's contact part: contactChanges, the springs' energy, the
	// contacts' damping and friction, and the work of prescribed motions
	// (gamma: the scheme's, IntegratorSettings::newmarkGamma).
	void accountContacts(double gamma);

	std::unique_ptr<Collider> collider_ = std::make_unique<DESSCollider>();
	ContactStore store_;
	ContactDetection detection_;  // the narrow phase's work and the flush-joint faces
	OpenCloseIteration openClose_;  // the step's moving blocks, system and iteration
	TimeStepControl timeStep_;
	std::vector<BlockMotion> motions_;  // moveContactsAndBlocks' work array
	// accountStep's work arrays: per moving block its damping terms (the
	// kinetic energy velocityRatio removes; the strain's Bregman divergence,
	// when it is strained) and whether it has loads or fixed points; per
	// contact its terms.
	struct BlockStepEnergy {
		double scaling = 0, strain = 0;
		bool strained = false, loaded = false;
	};
	std::vector<BlockStepEnergy> blockEnergies_;
	std::vector<ContactStepEnergy> contactEnergies_;
	std::vector<Block> blocks_;
	TopologyPool topologies_;  // the blocks' shared topologies
	StepStatistics stats_;
	// The account's cumulative terms (friction, damping, loads,
	// contactChanges) and the springs' energy at the end of the last step
	// (contact); gravity of the last step, for the potential.
	EnergyAccount energy_;
	Vector3 gravity_ = Vector3::Zero();
	double time_ = 0;
	long steps_ = 0;
	double motionHalfSize_ = 0;
	int motionSizedBlocks_ = -1;  // block count when motionHalfSize_ was measured
};

}  // namespace dda
