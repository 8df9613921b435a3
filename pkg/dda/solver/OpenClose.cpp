#include "OpenClose.hpp"

#include "StepClock.hpp"
#include "dda/core/CapacityBytes.hpp"

#include <algorithm>
#include <cmath>

namespace dda {

namespace {
// A pass of the iteration has converged when, besides no state changing,
// every contact's tangential force agrees with the model the last solve used
// (a slipping contact's direction is linearised) to within this fraction of
// the largest normal force of its group. Newton's method converges
// quadratically there, so a tight tolerance costs about one solve more; at
// 1e-4 the forces left over pushed a cube sliding along x sideways by 1e-7
// m in a set-up symmetric in y.
constexpr double kNewtonTolerance = 1e-10;
// A step's friction limits are consistent with its normal forces when moving
// every limit to its normal force's would move no contact's tangential
// force by more than this fraction of its blocks' force scale (forceScale;
// limitForceChange: a contact inside both its old and its new cone keeps
// its force, so its limit does not count; measureLimits); a step makes at
// most kLimitPasses passes (see solve()). Per block, that is at least as
// tight as the group test it replaces (1e-3 of the group's largest limit)
// for every block. (At 5e-3 the 4 m jointed masses made a second pass half
// as often, but a fuzzed pile whose first step is accepted unconverged then
// crushed a block, and a random hull pile at 1e11 Pa, whose contacts add
// energy between steps, threw a block 0.4 % faster than a fall from its
// top.) Any limit >= 0 resists slip, so an unsettled limit is an error in
// the friction's size, not in the energy.
constexpr double kLimitTolerance = 1e-3;
constexpr int kLimitPasses = 12;
// Coulomb-safe passes (closePasses) first set every limit to its normal
// force's, this many times, then only lower them.
constexpr int kFollowingPasses = 8;

// The solves a group may make: maxOpenCloseIterations, and half as many again
// once it is in Coulomb-safe passes (closePasses): on the sliding wedge of
// bench/rock_mass_wedge.py (x variant) a step cut redid 40 solves at half
// the dt in 98 of 640 steps; with the extra solves 17 of 360 were.
int solveBudget(int maxIterations, bool coulombSafe) {
	return coulombSafe ? maxIterations + maxIterations / 2 : maxIterations;
}
}  // namespace

void OpenCloseIteration::selectMovingBlocks(const std::vector<Block>& blocks, const std::vector<char>& frozen,
                                            StepStatistics& stats) {
	const int count = static_cast<int>(blocks.size());
	moving_.clear();
	movingIndex_.assign(count, -1);
	int bodies = 0;
	for (int i = 0; i < count; ++i) {
		// A concave block's later parts move with its body (Block::body):
		// their contacts take its unknowns.
		if (blocks[i].body >= 0) {
			movingIndex_[i] = movingIndex_[blocks[i].body];
			continue;
		}
		++bodies;
		if (blocks[i].fixed || (!frozen.empty() && frozen[i])) continue;
		movingIndex_[i] = static_cast<int>(moving_.size());
		moving_.push_back(i);
	}
	const int n = static_cast<int>(moving_.size());
	stats.movingBlocks = n;
	stats.fixedBlocks = bodies - n;
	blockUnknowns_.resize(n);
	for (int k = 0; k < n; ++k) {
		const Block& b = blocks[moving_[k]];
		blockUnknowns_[k] = b.unknowns();
		stats.unknowns += b.unknowns();
		stats.rigidBlocks += b.rigid;
		stats.strainUnknowns += b.unknowns() - kRigidBlockDofs;
	}
	solutions_.resize(n);
}

const Vector12& OpenCloseIteration::solutionOf(int block) const {
	static const Vector12 zero = Vector12::Zero();
	const int k = movingIndex_[block];
	if (k >= 0) return iterate_[k];
	return prescribed_ ? (*prescribed_)[block] : zero;
}

bool OpenCloseIteration::solve(const std::vector<Block>& blocks, std::vector<Contact>& contacts,
                               const IntegratorSettings& settings, double dt, bool firstStep, StepStatistics& stats) {
	const Attempt attempt{blocks, contacts, settings, dt, stats};
	// Open-close iteration: Newton's method on the step's energy (the
	// blocks' quadratic energy plus every contact's compression-only
	// normal spring and Coulomb-limited tangential spring; see
	// ContactEquations.hpp), in passes. Within a pass each contact's
	// friction limit is fixed, so the energy is one convex function:
	// each solve minimises the contacts' model at the states of the
	// current iterate, the states are evaluated at the new iterate, and
	// once a contact has swung back (or the pass runs long) a line search
	// makes every iterate lower the energy, so the pass cannot cycle. A
	// pass has converged when no state changes and the slipping
	// contacts' forces agree with their model: every closed contact is
	// then in compression and every open one apart, exactly the
	// gradients the energy account books, so the step creates no energy
	// (World::accountStep). Then the limits are set from the normal
	// forces found, and another pass is made while they change by more
	// than kLimitTolerance (at most kLimitPasses). The hold-closed and
	// friction-switch rules this replaces held contacts in tension and
	// created energy (a stiff pile gained up to 36%).
	startAttempt(attempt, firstStep);
	bool converged = false, structureStale = true;
	int iterations = 0, changes = 0;
	// Each group has its budget of solves (solveBudget); the attempt ends
	// unconverged when a group reaches its own without converging.
	bool exhausted = false;
	while (!exhausted) {
		solveOnce(attempt, structureStale);
		++iterations;
		group_.startIteration();
		structureStale = evaluateStates(attempt);
		measureLimits(contacts);
		changes = 0;
		if (closePasses(iterations, attempt, changes, exhausted)) {
			converged = true;
			break;
		}
		if (startPasses(attempt)) structureStale = true;
	}
	solutions_ = iterate_;
	stats.openCloseIterations = iterations;
	stats.openCloseIterationsTotal += iterations;
	stats.stateChanges = changes;
	return converged;
}

void OpenCloseIteration::startAttempt(const Attempt& attempt, bool firstStep) {
	const int n = static_cast<int>(moving_.size());
	std::vector<Contact>& contacts = attempt.contacts;
	// The blocks' own systems depend on dt: assembled anew in each attempt.
	ownSystems_.clear();
	ownSystemOf_.assign(n, -1);
	solvedAlone_.assign(n, 0);
	// assembleBlock adds a body force only for non-zero gravity.
	if (!attempt.settings.gravity.isZero()) attempt.stats.bodyForceBlocks += n;
	iterate_.assign(n, Vector12::Zero());
	coupled_.beginAttempt(attempt.settings.refineSolves);
	coupled_.setIterative(attempt.settings.iterativeSolveBlocks, attempt.settings.iterativeTolerance,
	                      attempt.settings.iterativeCoarseBlocks);
	centroids_.resize(n);
	for (int k = 0; k < n; ++k) centroids_[k] = attempt.blocks[moving_[k]].centroid;
	coupled_.setCentroids(&centroids_);
	keptTerms_.clear();
	keptTermsOf_.assign(contacts.size(), -1);
	for (Contact& contact : contacts) {
		startTrial(contact, firstStep);
		const Block& blockI = attempt.blocks[contact.bodyI];
		const Block& blockJ = attempt.blocks[contact.bodyJ];
		// The first pass's limit from the normal force at the start of
		// the step (its gap now), not the one the contact ended the last
		// step with: a corner that bounced off keeps no friction. At D = 0
		// on both sides (a prescribed motion's block too: the start).
		static const Vector12 start = Vector12::Zero();
		evaluateContact(contact, blockI, blockJ, start, start);
		updateFrictionLimit(contact, true);
		evaluateContact(contact, blockI, blockJ, start, start);
	}
	computeStartAccelerations(attempt);
	// The blocks that contacts join (open ones too: their energy counts
	// once they close) form groups whose energies are independent: each
	// group iterates, searches and converges on its own, so a block
	// elsewhere in the scene cannot change another's trajectory, not even
	// by round-off. A converged group's iterate is no longer moved.
	groupContacts(contacts);
	group_.reset(n);
	for (const Contact& contact : contacts) group_.hasContacts[contactGroup_[&contact - contacts.data()]] = 1;
}

void OpenCloseIteration::solveOnce(const Attempt& attempt, bool structureStale) {
	StepStatistics& stats = attempt.stats;
	auto phase = Clock::now();
	if (structureStale) {
		buildSystemStructure(attempt);
		assembleOwnSystems(attempt);
	}
	coupled_.reset(ownSystems_, ownSystemOf_);
	assembleContacts(attempt);
	stats.timeAssembly += secondsSince(phase);
	phase = Clock::now();
	// Which blocks are alone changes only with the structure.
	if (structureStale) solveAloneBlocks(attempt);
	coupled_.solve(solutions_, kMinBlocksForThreads);
	stats.solvedUnknowns = coupled_.solvedUnknowns() + aloneUnknowns_;
	stats.refinedComponents += coupled_.refinedComponents();
	stats.refineIterations += coupled_.refineIterations();
	stats.refineFallbacks += coupled_.refineFallbacks();
	stats.iterativeComponents += coupled_.iterativeComponents();
	stats.iterativeIterations += coupled_.iterativeIterations();
	stats.iterativeFallbacks += coupled_.iterativeFallbacks();
	stats.coarseAggregates = coupled_.coarseAggregates();
	if (lineSearch(attempt) < 1) ++stats.lineSearches;
	stats.timeSolve += secondsSince(phase);
}

bool OpenCloseIteration::evaluateStates(const Attempt& attempt) {
	bool structureStale = false;
	std::vector<Contact>& contacts = attempt.contacts;
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		Contact& contact = contacts[c];
		const int g = contactGroup_[c];
		if (group_.done[g]) continue;
		const int bi = contact.bodyI, bj = contact.bodyJ;
		const Block& blockI = attempt.blocks[bi];
		const Block& blockJ = attempt.blocks[bj];
		const Vector12& Di = solutionOf(bi);
		const Vector12& Dj = solutionOf(bj);
		const Vector3 model = tangentialForce(contact, blockI, blockJ, Di, Dj);
		const double normalMiss = normalModelError(contact, Di, Dj);
		const bool wasClosed = isClosed(contact);
		if (evaluateContact(contact, blockI, blockJ, Di, Dj)) {
			++group_.changes[g];
			// Only closed contacts carry normal terms: opening and
			// closing change which blocks the system couples.
			if (wasClosed != isClosed(contact)) {
				structureStale = true;
				if (++contact.openCloseChanges >= 2) group_.swungBack[g] = 1;
			}
		}
		// A contact that closes with no limit takes the limit of its
		// normal force now, once per pass (so the pass's energy changes
		// a finite number of times): frictionless until the next pass,
		// a block landing on a much larger one was held sideways by its
		// inertia alone, and the system's Cholesky failed on round-off
		// at five decades of scale. Not in a step of one pass
		// (setOnePass), whose limits are those of its start.
		if (!onePass_ && isClosed(contact) && !(contact.slipLimit > 0) && contact.trial.normalForce > 0 &&
		    contact.frictionTangent > 0) {
			updateFrictionLimit(contact, true);
			evaluateContact(contact, blockI, blockJ, Di, Dj);
			++group_.changes[g];
		}
		// The force scale of the group: its largest normal force, or
		// friction limit (an open contact keeps its limit for the pass,
		// so a group may slip with no normal force at all).
		group_.largestNormalForce[g] =
		    std::max({group_.largestNormalForce[g], std::abs(contact.trial.normalForce), contact.slipLimit});
		group_.forceChange[g] = std::max(
		    {group_.forceChange[g], normalMiss, (tangentialForce(contact, blockI, blockJ, Di, Dj) - model).norm()});
	}
	return structureStale;
}

void OpenCloseIteration::measureLimits(std::vector<Contact>& contacts) {
	// Groups whose pass converged: their limits against the normal
	// forces found; done when they agree, else another pass. (Limits
	// that follow the normal forces at every solve instead, as Shi's
	// friction does, settled most steps in fewer solves but cycled in
	// others and, accepted unsettled, lost a sliding cube a fifth of
	// its speed in its first step.)
	//
	// Each contact's change is measured against the force scale of its
	// blocks: per moving block, the largest over its contacts of what each
	// carries or may carry now (forceScale: an open contact's limit, kept
	// for the pass, is no force); the smaller of the two blocks' when both
	// move. Against the group's largest limit instead, a light block's
	// friction would be settled only to a fraction of the heaviest
	// block's limits: for a 10 cm cube touching a 100 m prism, 1e-3 of
	// the prism's is more than 1e5 times the cube's weight.
	auto converged = [&](std::size_t c) {
		const int g = contactGroup_[c];
		return !group_.done[g] && group_.passConverged(g, kNewtonTolerance);
	};
	// One pass a step (setOnePass): the limits are those of the step's
	// start, settled across static steps rather than within each.
	if (onePass_) return;
	const int n = static_cast<int>(moving_.size());
	blockLimit_.assign(n, 0.0);
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		if (!converged(c)) continue;
		// A contact that broke away from static friction slides at
		// Coulomb's limit: another pass with it, when that moves its force
		// by more than the tolerance (a limit change like any other).
		dropStaticFriction(contacts[c]);
		const double limit = forceScale(contacts[c]);
		for (const int block : {contacts[c].bodyI, contacts[c].bodyJ}) {
			const int k = movingIndex_[block];
			if (k >= 0) blockLimit_[k] = std::max(blockLimit_[k], limit);
		}
	}
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		if (!converged(c)) continue;
		const double change =
		    group_.coulombSafe[contactGroup_[c]] ? limitExcess(contacts[c]) : limitForceChange(contacts[c]);
		if (!(change > 0)) continue;
		const int ki = movingIndex_[contacts[c].bodyI], kj = movingIndex_[contacts[c].bodyJ];
		const double scaleI = ki >= 0 ? blockLimit_[ki] : blockLimit_[kj];
		const double scaleJ = kj >= 0 ? blockLimit_[kj] : blockLimit_[ki];
		// Both blocks' scales hold this contact's forceScale, which bounds
		// the change (|a - b| <= max(a, b) for a, b >= 0), but for a bonded
		// contact's |L' - L|: its ratio may then be large, or infinite when
		// the scale is 0, and the group is not settled.
		const double scale = std::min(scaleI, scaleJ);
		const int g = contactGroup_[c];
		group_.limitChange[g] = std::max(group_.limitChange[g], change / scale);
	}
}

bool OpenCloseIteration::closePasses(int iterations, const Attempt& attempt, int& changes, bool& exhausted) {
	const int n = static_cast<int>(moving_.size());
	StepStatistics& stats = attempt.stats;
	const int maxIterations = std::max(1, attempt.settings.maxOpenCloseIterations);
	bool allDone = true;
	exhausted = false;
	for (int g = 0; g < n; ++g) {
		if (group_.done[g]) continue;
		changes += group_.changes[g];
		if (!group_.hasContacts[g]) {
			group_.done[g] = 1;  // no contact: its own solve is its answer
			continue;
		}
		const bool converged = group_.passConverged(g, kNewtonTolerance);
		// In Coulomb-safe passes limitChange is the largest excess of a
		// friction force over Coulomb's limit at its normal force.
		// (A step of one pass measures no limit change, measureLimits: its
		// converged pass is settled.)
		const bool settled = group_.limitChange[g] <= kLimitTolerance;
		// The passes a group may make to settle its limits: kLimitPasses,
		// and none once three quarters of the step's solves are spent.
		const bool outOfPasses = iterations >= (3 * maxIterations) / 4 || group_.passes[g] + 1 >= kLimitPasses;
		if (converged && settled) {
			group_.done[g] = 1;
			continue;
		}
		allDone = false;
		if (!converged) {
			exhausted = exhausted || iterations >= solveBudget(maxIterations, group_.coulombSafe[g] > 0);
			continue;
		}
		if (!coulombSafe_ && outOfPasses) {
			// Start from rest's static steps with the true friction accept a
			// converged pass with its limits as they stand; its end state is
			// checked (World::settle).
			group_.done[g] = 1;
			++stats.limitsUnsettled;
			continue;
		}
		if (outOfPasses && !group_.coulombSafe[g]) {
			// Limits that did not settle end on the side Coulomb's law
			// allows (see DESIGN, "Friction limits that do not settle"):
			// the group's later passes set every limit to tan(phi) N of
			// the normal force found (kFollowingPasses times), then only
			// lower those above it, until no friction force exceeds
			// Coulomb's limit at its normal force. In a pile of 30 stiff
			// cubes a limit can swing between its closed and open values
			// pass after pass; accepted as it stood, a limit from a normal
			// force that had gone held a wedge of a cut slope (FS 0.81)
			// with 13 times Coulomb's friction at one contact.
			group_.coulombSafe[g] = 1;
			++stats.limitsLowered;
		} else if (iterations >= solveBudget(maxIterations, group_.coulombSafe[g] > 0)) {
			// Out of solves with a friction force above Coulomb's limit:
			// the attempt is redone with a shorter step, like one whose pass
			// did not converge.
			exhausted = true;
			continue;
		}
		group_.newPass[g] = 1;
		++group_.passes[g];
		++stats.limitPasses;
		group_.passSolves[g] = 0;
	}
	return allDone;
}

bool OpenCloseIteration::startPasses(const Attempt& attempt) {
	bool structureStale = false;
	std::vector<Contact>& contacts = attempt.contacts;
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		Contact& contact = contacts[c];
		if (!group_.newPass[contactGroup_[c]]) continue;
		// Which contacts carry terms may change with the limits (an
		// open contact with a limit keeps its tangential spring).
		const bool hadTerms = isClosed(contact) || contact.slipLimit > 0;
		const int safe = group_.coulombSafe[contactGroup_[c]];
		if (safe > kFollowingPasses)
			lowerFrictionLimit(contact);
		else if (safe > 0)
			setFrictionLimit(contact);
		else
			updateFrictionLimit(contact, true);
		if (hadTerms != (isClosed(contact) || contact.slipLimit > 0)) structureStale = true;
		const int bi = contact.bodyI, bj = contact.bodyJ;
		evaluateContact(contact, attempt.blocks[bi], attempt.blocks[bj], solutionOf(bi), solutionOf(bj));
	}
	for (std::size_t g = 0; g < group_.coulombSafe.size(); ++g)
		if (group_.coulombSafe[g] > 0 && group_.newPass[g]) ++group_.coulombSafe[g];
	return structureStale;
}

void OpenCloseIteration::groupContacts(const std::vector<Contact>& contacts) {
	const int n = static_cast<int>(moving_.size());
	std::vector<int>& root = groupRoot_;
	root.resize(n);
	for (int k = 0; k < n; ++k) root[k] = k;
	auto find = [&](int k) {
		while (root[k] != k) k = root[k] = root[root[k]];
		return k;
	};
	for (const Contact& contact : contacts) {
		const int mi = movingIndex_[contact.bodyI], mj = movingIndex_[contact.bodyJ];
		if (mi < 0 || mj < 0) continue;
		const int a = find(mi), b = find(mj);
		if (a != b) root[std::max(a, b)] = std::min(a, b);
	}
	for (int k = 0; k < n; ++k) root[k] = find(k);
	contactGroup_.resize(contacts.size());
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		const int mi = movingIndex_[contacts[c].bodyI];
		contactGroup_[c] = root[mi >= 0 ? mi : movingIndex_[contacts[c].bodyJ]];
	}
}

void OpenCloseIteration::GroupIteration::reset(int groups) {
	done.assign(groups, 0);
	hasContacts.assign(groups, 0);
	swungBack.assign(groups, 0);
	passes.assign(groups, 0);
	passSolves.assign(groups, 0);
	changes.assign(groups, 0);
	newPass.assign(groups, 0);
	coulombSafe.assign(groups, 0);
	forceChange.assign(groups, 0.0);
	largestNormalForce.assign(groups, 0.0);
	limitChange.assign(groups, 0.0);
}

void OpenCloseIteration::GroupIteration::startIteration() {
	for (std::size_t g = 0; g < done.size(); ++g) {
		if (done[g]) continue;
		++passSolves[g];
		changes[g] = 0;
		newPass[g] = 0;
		forceChange[g] = largestNormalForce[g] = limitChange[g] = 0;
	}
}

std::size_t OpenCloseIteration::GroupIteration::memoryBytes() const {
	return capacityBytes(done) + capacityBytes(hasContacts) + capacityBytes(swungBack) + capacityBytes(newPass) +
	       capacityBytes(coulombSafe) + capacityBytes(passes) + capacityBytes(passSolves) + capacityBytes(changes) + capacityBytes(forceChange) +
	       capacityBytes(largestNormalForce) + capacityBytes(limitChange);
}

bool OpenCloseIteration::GroupIteration::passConverged(int g, double tolerance) const {
	return changes[g] == 0 && forceChange[g] <= tolerance * largestNormalForce[g];
}

const Vector12& OpenCloseIteration::startAccelerationOf(int k) const {
	static const Vector12 zero = Vector12::Zero();
	return startAccelerations_.empty() ? zero : startAccelerations_[k];
}

void OpenCloseIteration::computeStartAccelerations(const Attempt& attempt) {
	const int n = static_cast<int>(moving_.size());
	startAccelerations_.clear();
	if (attempt.settings.shiScheme()) return;
	startAccelerations_.resize(n);
	for (int k = 0; k < n; ++k) {
		const Block& block = attempt.blocks[moving_[k]];
		startAccelerations_[k] = accelerationOf(block, restForce(block, attempt.settings));
	}
}

double OpenCloseIteration::displacementOf(const std::vector<Block>& blocks, int k) const {
	const Block& body = blocks[moving_[k]];
	double largest = largestVertexDisplacement(body, solutions_[k]);
	for (int p = 1; p < body.partCount; ++p)  // a concave block's other parts, about its centroid
		largest = std::max(largest,
		                   largestVertexDisplacement(blocks[moving_[k] + p].vertices, body.centroid, solutions_[k]));
	return largest;
}

double OpenCloseIteration::largestDisplacement(const std::vector<Block>& blocks) const {
	const int n = static_cast<int>(moving_.size());
	double largest = 0;
#pragma omp parallel for schedule(static) reduction(max : largest) if (n >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k) largest = std::max(largest, displacementOf(blocks, k));
	return largest;
}

void OpenCloseIteration::blocksMovedMoreThan(const std::vector<Block>& blocks, double threshold,
                                             std::vector<int>& out) const {
	out.clear();
	for (int k = 0; k < static_cast<int>(moving_.size()); ++k)
		if (displacementOf(blocks, k) > threshold) out.push_back(moving_[k]);
	std::sort(out.begin(), out.end());
}

StepShrink OpenCloseIteration::smallestJacobian(const std::vector<Block>& blocks) const {
	StepShrink smallest;
	for (std::size_t k = 0; k < moving_.size(); ++k) {
		const double jacobian = stepJacobian(blocks[moving_[k]], solutions_[k]);
		if (!(jacobian >= smallest.jacobian)) smallest = {jacobian, moving_[k]};
	}
	return smallest;
}

std::size_t OpenCloseIteration::memoryBytes() const {
	return coupled_.memoryBytes() + capacityBytes(moving_) + capacityBytes(movingIndex_) + capacityBytes(centroids_) +
	       capacityBytes(solutions_) + capacityBytes(ownSystems_) + capacityBytes(ownSystemOf_) +
	       capacityBytes(solvedAlone_) + capacityBytes(links_) + capacityBytes(hasSprings_) +
	       capacityBytes(blockLimit_) + capacityBytes(blockUnknowns_) + capacityBytes(iterate_) +
	       capacityBytes(deltas_) + capacityBytes(lines_) +
	       capacityBytes(groupRoot_) + capacityBytes(lineGroup_) + capacityBytes(groupLines_) +
	       capacityBytes(orderedLines_) + capacityBytes(keptTerms_) + capacityBytes(keptTermsOf_) +
	       capacityBytes(keptTermsKey_) + capacityBytes(groupKink_) + capacityBytes(groupSlope_) +
	       capacityBytes(groupCurvature_) + capacityBytes(groupStep_) + capacityBytes(contactGroup_) +
	       capacityBytes(startAccelerations_) + group_.memoryBytes();
}

}  // namespace dda
