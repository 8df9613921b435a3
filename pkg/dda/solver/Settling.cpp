// Start from rest (World::settle, IntegratorSettings::startFromRest): static
// steps with friction locked bring the supported blocks at rest to
// equilibrium before the first step.
#include "World.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dda {

namespace {
// Start from rest (World::settle): friction tangents are multiplied by this
// while settling (the contacts' tangential springs hold whatever the
// equilibrium asks). Each stage's static steps stop once one moves the
// blocks by no more than kSettleTolerance of what the first locked step did
// (an equilibrium to round-off), or once kSettleQuietSteps steps in a row
// leave them quiet, and give up after kSettleSteps (each closes all but
// about 1e-3 of the way, see settle).
//
// Quiet: no vertex moved by more than kSettleQuiet of the first locked
// step's move, or by more than kSettleQuietAcceleration g dt^2 / 2. The
// second is an out-of-balance force. A static step solves
// (2 M / dt^2) D + K D = F with no velocity carried, so the force left
// unbalanced at its end is exactly 2 M D / dt^2: a vertex that moved delta
// carries 2 delta / dt^2 of acceleration, and at 1e-4 g (ten times tighter
// than the unbalanced-force ratios YADE scripts settle to) a block left so
// would reach at most 5e-4 m/s in 0.5 s were nothing to resist it.
//
// Why quiet counts. In a jointed rock mass (every block touching its
// neighbours face to face, hundreds of contacts on steep joints carrying
// next to no normal force) the static steps with the true friction do not
// contract to round-off: each re-evaluates the friction limits of the
// contacts at the edge of their cones, a few slip by nanometres and the
// load moves to their neighbours, step after step. A 5 m cube cut by sets
// 85/030, 80/130, 15/250 (60 free blocks, E = 1e9 Pa) comes to rest moving
// by about 1.2e-2 of its locked stage's first move at every step, without
// end; a 4 m cube cut by three oblique sets (seed 1 of
// tests/py/rockmass_scenes.py) by 0.8e-2 to 1.3e-2 of it (7.8e-9 to 1.2e-8 m
// in static steps of 0.022 s: 3e-6 g to 5e-6 g). Such a residual is a state
// at rest; the relative form alone never called the second quiet.
//
// A block that must slide is never quiet, and its static steps repeat one
// move: it slides on the same contacts in the same direction under the same
// forces, by a dt^2 / 2 each step, where an approach to an equilibrium
// shrinks the moves by about 1e-3 a step (settlingTimeStep). So a stage
// gives up once kSettleSteadyRepeats steps in a row move the blocks by more
// than the first locked step did and by the same amount, within
// kSettleSteady, as the step before (a cube on a 30 deg slope with 20 deg
// of friction: 21 to 128 times the first move, 3.965e-5, 3.930e-5 m, then
// the same to 4 digits). One repeat is not enough: the moves of a mass on
// its way to rest go up and down and can repeat within 1 % once by chance;
// given up there, the 5 m cube above kept 40 of its 60 free blocks in the
// locked state, where let on it came to rest. A move below the first is a
// creep of a mechanism driven by a few 1e-5 of its weight (with 2 m / dt^2
// = 1e-3 kn a step moves a free mode by 1000 R / kn against the settlement
// m g / kn): not a block that must slide. Nor can the rule ask the moves to
// shrink: the 5 m cube above, on its way to rest, moved by amounts going up
// and down by factors of 2 to 40 from step to step. Energy: the settling is
// an initial condition (see settle); the account starts from the state
// reached.
//
// The friction ramp (admitFriction): one static step at each of these
// friction scales between the locked stage and the true friction, so that
// the locked springs' excess over their limits is released a part at a
// time. Released at once, a friction stage's first static steps slip many
// contacts at once (in the 5 m cube their friction directions swung by up
// to 0.75 of the largest normal force between solves, 30 to 40 solves a
// step), and the state they stop in rings: the 5 m cube started at 8.9e-4
// m/s, a 4 m oblique cube (seed 4) at 2.4e-3 m/s with 14 solves a step.
// Ramped, they start at 2.2e-5 and 4e-19 m/s.
// The rules here were tuned on the 5 m cube and the 4 m oblique and
// orthogonal cubes of seeds 1 to 6 (all settle, every free block below
// 5e-4 m/s over the next 0.2 s); checked on the 6 m cubes and the start
// from rest, random slope and dt-convergence suites.
constexpr double kSettleFrictionScale = 1e6;
constexpr double kSettleTolerance = 1e-6;
constexpr double kSettleQuiet = 1e-2;
constexpr double kSettleQuietAcceleration = 1e-4;
constexpr int kSettleQuietSteps = 5;
constexpr double kSettleSteady = 1e-2;
constexpr int kSettleSteadyRepeats = 2;
constexpr double kFrictionRamp[] = {100, 10, 3, 1.5, 1.2};
// At most this many static steps a stage: the 8 m orthogonal stack of seed 2
// of tests/py/rockmass_scenes.py (392 free blocks) did not settle in 40 and
// settles in 62 static steps in all; the 4 to 6 m masses take 13 to 47.
constexpr int kSettleSteps = 80;
// Open-close solves a static step may take (at least; the dynamics' own
// maximum when larger). A static step moves a mass from one equilibrium
// towards the next in one go, its contacts' states changing all at once,
// and a cut there only shrinks a step that has no time to be accurate in:
// with the dynamics' 40, the static steps of an 8 m orthogonal stack (392
// free blocks) with Coulomb's limits ran out of solves without converging
// a pass, their moves repeated and the settling took the stack for a block
// that must slide (all 392 left locked; the stack rang at 0.08 m/s). With
// 100 it settles and stays at rest, at one solve a step.
constexpr int kSettleOpenCloseIterations = 100;
// A contact whose start gap is within this many ulps of the two blocks'
// reach (distance of the farther centroid from the origin plus the larger
// size) touches: a block placed flush on another has gaps of round-off,
// either sign (prisms laid exactly on a slab 10 m from the origin:
// +1e-16 to +1e-15 m at every corner for 14 of 132 random slopes,
// tests/py/contact/test_random_slopes.py, so they were not settled and
// started on unloaded springs, 0.6 to 3.4 mm/s in their first step).
constexpr double kFlushUlps = 64;

double flushGap(const Block& a, const Block& b) {
	const double reach = std::max(a.centroid.norm(), b.centroid.norm()) + std::max(a.size, b.size);
	return kFlushUlps * std::numeric_limits<double>::epsilon() * reach;
}

// The static steps' dt [s]: at least maxTimeStep, and long enough for every
// moving block (see below).
double settlingTimeStep(const std::vector<Block>& blocks, const IntegratorSettings& settings) {
	// A step long enough that inertia weighs at most 1e-3 of every block's
	// stiffnesses: of its contact springs (2 m / dt^2 = 1e-3 kn) and, for a
	// deformable block, of its strain modes (the mass of a uniform strain,
	// rho J ~ rho V L^2 / 12, against V E: rho L^2 / (6 E dt^2) = 1e-3).
	// Each static step then closes all but about 1e-3 of the distance to
	// equilibrium. (Sized by the contacts alone, a block 1000 times stiffer
	// in its contacts than in itself needed more than 12 steps.)
	double longest = settings.maxTimeStep;
	for (const Block& block : blocks) {
		if (block.fixed) continue;
		const double kn = settings.contactPenaltyFactor * block.material.young * block.size;
		longest = std::max(longest, std::sqrt(2000 * block.mass / kn));
		if (!block.rigid)
			longest = std::max(longest, std::sqrt(1000 * block.density() * block.size * block.size /
			                                      (6 * block.material.young)));
	}
	return longest;
}
}  // namespace

void World::markSettlingBlocks() {
	// Blocks joined by touching contacts (closed at D = 0: penetrating or
	// flush to round-off, flushGap; or bonded) form components; a component settles when it holds a
	// fixed block or a fixed point and all its moving blocks are at rest.
	const int count = blockCount();
	std::vector<int> root(count);
	for (int b = 0; b < count; ++b) root[b] = b;
	auto find = [&](int b) {
		while (root[b] != b) b = root[b] = root[root[b]];
		return b;
	};
	for (const Contact& contact : store_.contacts()) {
		if (!contact.normal.valid ||
		    contact.normal.d0 > flushGap(blocks_[contact.bodyI], blocks_[contact.bodyJ]))
			continue;
		const int a = find(contact.bodyI), b = find(contact.bodyJ);
		if (a != b) root[std::max(a, b)] = std::min(a, b);
	}
	std::vector<char> supported(count, 0), moving(count, 0);
	for (int b = 0; b < count; ++b) {
		const Block& block = blocks_[b];
		const int r = find(b);
		if (block.fixed || !block.fixedPoints.empty()) supported[r] = 1;
		if (!block.fixed && !block.velocity.isZero()) moving[r] = 1;
	}
	frozen_.assign(count, 1);
	settledBlocks_ = 0;
	for (int b = 0; b < count; ++b) {
		const int r = find(b);
		if (blocks_[b].fixed || !supported[r] || moving[r]) continue;
		frozen_[b] = 0;
		++settledBlocks_;
	}
}

void World::settle(const IntegratorSettings& settings) {
	// Static steps bring the blocks to rest; everything a step advances is
	// kept aside and put back, so the settling takes no time, no step and no
	// energy of the account: it sets the scene's initial state.
	const std::vector<Block> placed = blocks_;
	const ContactStore placedContacts = store_;
	const double time = time_;
	const long steps = steps_;
	const TimeStepControl timeStep = timeStep_;  // next dt, failures, misses
	IntegratorSettings statics = settings;
	statics.velocityRatio = 0;
	statics.newmarkBeta = 0.5;
	statics.newmarkGamma = 1;
	// Static steps seek an equilibrium, which no viscosity moves; left out,
	// the settled state is the same with or without it.
	statics.strainDamping = 0;
	statics.timeStepGrowth = 1;
	statics.maxOpenCloseIterations = std::max(settings.maxOpenCloseIterations, kSettleOpenCloseIterations);
	const double longest = settlingTimeStep(blocks_, settings);
	statics.maxTimeStep = longest;
	settling_ = true;
	frictionScale_ = kSettleFrictionScale;
	openClose_.setCoulombSafe(false);
	frozen_.clear();
	settleSteps_ = 0;
	settleSolves_ = settleLimitPasses_ = 0;
	settleConverged_ = false;
	unsettled_.clear();
	double first = -1;
	settleConverged_ = settlingSteps(statics, longest, first);
	if (settleConverged_) {
		admitFriction(statics, longest, first);
		lockSettledContacts();
	}
	settling_ = false;
	openClose_.setOnePass(false);
	openClose_.setCoulombSafe(true);
	frictionScale_ = 1;
	frozen_.clear();
	if (settledBlocks_ == 0) settleSteps_ = settleSolves_ = settleLimitPasses_ = 0;  // nothing to settle: not tried
	if (!settleConverged_) {
		blocks_ = placed;
		store_ = placedContacts;
		collider_->setPairReuse(false);  // its cache saw the moved blocks
		settledBlocks_ = 0;
	}
	// The account starts here: the springs' energy is the settled state's.
	const double springs = energy_.contact;
	energy_ = EnergyAccount{};
	if (settleConverged_) energy_.contact = springs;
	time_ = time;
	timeStep_ = timeStep;
	steps_ = steps;
}

bool World::settlingSteps(const IntegratorSettings& statics, double longest, double& reference) {
	// Static steps until one moves the blocks by no more than kSettleTolerance
	// x `reference` (the first step's displacement when reference < 0, which
	// then sets it) or kSettleQuietSteps in a row each by no more than
	// kSettleQuiet x `reference`, at most kSettleSteps; false when neither
	// happens, when a step larger than the first repeats the move of the one
	// before within kSettleSteady (a block that must slide), when a step has
	// no static solution, or when nothing settles.
	int quiet = 0, steady = 0;
	double previous = -1;
	const double gravity = statics.gravity.norm();
	for (int k = 0; k < kSettleSteps; ++k) {
		if (!staticStep(statics, longest)) return false;
		const double moved = stats_.maxDisplacement;
		if (reference < 0) reference = moved;
		if (settledBlocks_ == 0) return false;
		if (moved <= kSettleTolerance * reference) {
			unsettled_.clear();
			return true;
		}
		const double quietMove =
		    std::max(kSettleQuiet * reference, 0.5 * kSettleQuietAcceleration * gravity * stats_.dt * stats_.dt);
		quiet = moved <= quietMove ? quiet + 1 : 0;
		if (quiet >= kSettleQuietSteps) {
			unsettled_.clear();
			return true;
		}
		openClose_.blocksMovedMoreThan(blocks_, quietMove, unsettled_);
		const bool repeated = moved > reference && std::abs(moved - previous) <= kSettleSteady * previous;
		steady = repeated ? steady + 1 : 0;
		if (steady >= kSettleSteadyRepeats) return false;
		previous = moved;
	}
	return false;
}

bool World::staticStep(const IntegratorSettings& statics, double longest) {
	timeStep_.setNextTry(longest);
	++settleSteps_;
	// Every static step after the first makes one pass
	// (OpenCloseIteration::setOnePass): its friction limits are set from the
	// normal forces at its start, a contact that closes during it takes none
	// until the next, and they follow the normal forces from one static step
	// to the next, which the stage repeats until nothing moves. A contact
	// open at a step's start carries no friction in it, and one that opens
	// during it keeps its limit for that step only: when the steps are
	// quiet, the limits are those of the normal forces the blocks end with.
	// Settled pass by pass within each step instead:
	// - with friction locked, 60 to 80 solves a step (the scaled limit of a
	//   contact that opened, 1e10 to 1e13 N, halved at each swing back,
	//   never passed the test);
	// - with the true friction, a step out of passes was accepted with its
	//   limits as they stood, and a contact that opened in it kept its
	//   limit and its spring's shear: two slivers (16 and 18 kg) of the 9 m
	//   oblique mass of seed 1 (tests/py/rockmass_scenes.py) ended the
	//   settling held by the friction of contacts that carried no normal
	//   force, half their weight unbalanced, and rocked at 1e-3 to 1.5e-2
	//   m/s once the dynamics started (6 solves a step).
	// Energy: each pass minimises one convex energy (limits fixed and >= 0)
	// with D = 0 admissible, so no static step raises the potential energy,
	// and the settling is an initial condition. The first static step keeps
	// its passes and its closing contacts' limits: its contacts start at no
	// normal force, so with no limit, and with one pass it is a
	// frictionless slide (the wedge of test_wedge.py at FS 1.3 moved 3 mm
	// while settling).
	// Tuned on the 8 m orthogonal stack, the 6 m masses and the 9 m oblique
	// mass; checked on the fifteen masses and the 8 m, slope and
	// persistence masses of bench/rock_mass_rest.py, the masses of
	// bench/rock_mass_scale.py and the start from rest, random slope,
	// rock-mass oracle, Coulomb-safe, dt-convergence, wedge and tunnel
	// suites.
	openClose_.setOnePass(settleSteps_ > 1 && !polishing_);
	try {
		advance(statics);
		settleSolves_ += stats_.openCloseIterationsTotal;
		settleLimitPasses_ += stats_.limitPasses;
	} catch (const std::exception&) {
		// No static solution with these contacts (a system no inertia
		// keeps definite).
		return false;
	}
	// The settling blocks only: a frozen one (moving, or unsupported)
	// keeps its velocity.
	for (int b = 0; b < blockCount(); ++b)
		if (!blocks_[b].fixed && !frozen_[b]) blocks_[b].velocity.setZero();
	return true;
}

void World::admitFriction(const IntegratorSettings& statics, double longest, double reference) {
	// Settled with friction locked, a contact's shear spring holds whatever
	// equilibrium asked of it, which can be more than Coulomb's limit: a
	// deformable block's base spreads by Poisson's ratio under its weight,
	// and the locked springs hold its corners back radially (a random prism
	// on a slope, tests/py/contact/test_random_slopes.py seed 11: 175 to
	// 330 N at corners whose limit tan(phi) N is 121 to 489 N); a light
	// corner's share of the downhill pull can exceed its limit too. The
	// first step then slipped every such corner at once and the block
	// lurched (8e-5 m/s), then rang (Shi's scheme keeps v_{n+1} = 2 d/dt -
	// v_n with d ~ 0): it did not start at rest. So the settling goes on
	// with the true friction: static steps in which those corners slip to
	// their limits, until the blocks are at rest as settlingSteps decides
	// (to round-off, or quiet at kSettleQuiet of the first locked step's
	// move). The state reached is
	// an equilibrium every contact law admits. Energy: these are static
	// steps of the same open-close iteration (each an energy-decreasing
	// solve whose slips dissipate, tan(phi) N >= 0 against them) and the
	// account restarts from the state reached (settle), so they add
	// nothing to it; the springs' and strain's energy can only fall as
	// stretched springs slip back to their limits. A scene with no such
	// equilibrium (a block that must slide) keeps the locked state, as before.
	const std::vector<Block> locked = blocks_;
	const ContactStore lockedContacts = store_;
	const double lockedSprings = energy_.contact;
	// A scene without friction has nothing to release: no ramp.
	bool ramped = true;
	if (stats_.frictionContacts > 0) {
		for (const double scale : kFrictionRamp) {
			frictionScale_ = scale;
			if (!(ramped = staticStep(statics, longest))) break;
		}
	}
	frictionScale_ = 1;
	bool settled = ramped && settlingSteps(statics, longest, reference);
	// The true friction's static steps make one pass each (staticStep), each
	// with the limits of its start. Once they are quiet, static steps with
	// their passes (the dynamics' rule, OpenCloseIteration::closePasses:
	// limits settled within the step, Coulomb-safe once out of passes) end
	// the settling, so that the limits the dynamics starts from are tan(phi)
	// N of the normal forces of the settled state, within kLimitTolerance,
	// or lower. From a quiet state they take 1 to 5 static steps of a few
	// solves. Without them seed 1 of the 5 m oblique mass
	// (tests/py/rockmass_scenes.py) started 8.7e-3 g out of balance and took
	// 2 solves a step; with them 1e-6 g and 1 solve. Energy: as the other
	// static steps (each pass minimises a convex energy with D = 0
	// admissible, every limit >= 0), and the settling is an initial
	// condition.
	if (settled) {
		polishing_ = true;
		openClose_.setCoulombSafe(true);
		settled = settlingSteps(statics, longest, reference);
		openClose_.setCoulombSafe(false);
		polishing_ = false;
	}
	if (settled) return;
	blocks_ = locked;
	store_ = lockedContacts;
	energy_.contact = lockedSprings;
	collider_->setPairReuse(false);  // its cache saw the moved blocks
}

void World::lockSettledContacts() {
	// The settled state is at rest: no contact slips. One that ended the
	// settling at its friction limit is in static equilibrium there, and
	// starts the dynamics locked, so that static friction
	// (staticFrictionExcess) holds it as any contact at rest. Energy: the
	// label changes no force, anchor or stored energy (a sliding contact
	// ends its step with the stretch L / ks that carries its limit,
	// finishContact), only which limit the next step gives it.
	for (Contact& contact : store_.contacts())
		if (contact.history.state == ContactState::Sliding && contact.frictionTangent > 0)
			contact.history.state = ContactState::Locked;
}

void World::dropFrozenContacts(StepStatistics& stats) {
	// Contacts of two frozen (or fixed) blocks carry nothing while
	// settling; left out, the first step finds them as new.
	std::vector<Contact>& found = store_.contacts();
	found.erase(std::remove_if(found.begin(), found.end(),
	                           [&](const Contact& c) {
		                           return openClose_.movingIndex(c.bodyI) < 0 &&
		                                  openClose_.movingIndex(c.bodyJ) < 0;
	                           }),
	            found.end());
	stats.contacts = static_cast<int>(found.size());
}

}  // namespace dda
