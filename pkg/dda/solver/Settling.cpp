// Start from rest (World::settle, IntegratorSettings::startFromRest): static
// steps with friction locked bring the supported blocks at rest to
// equilibrium before the first step.
#include "World.hpp"

#include <algorithm>
#include <cmath>

namespace dda {

namespace {
// Start from rest (World::settle): friction tangents are multiplied by this
// while settling (the contacts' tangential springs hold whatever the
// equilibrium asks), the static steps stop once one moves the blocks by no
// more than kSettleTolerance of what the first did, and give up after
// kSettleSteps (each closes all but about 1e-3 of the way, see settle).
constexpr double kSettleFrictionScale = 1e6;
constexpr double kSettleTolerance = 1e-6;
constexpr int kSettleSteps = 12;

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
	// flush, or bonded) form components; a component settles when it holds a
	// fixed block or a fixed point and all its moving blocks are at rest.
	const int count = blockCount();
	std::vector<int> root(count);
	for (int b = 0; b < count; ++b) root[b] = b;
	auto find = [&](int b) {
		while (root[b] != b) b = root[b] = root[root[b]];
		return b;
	};
	for (const Contact& contact : store_.contacts()) {
		if (!contact.normal.valid || contact.normal.d0 > 0) continue;
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
	statics.timeStepGrowth = 1;
	const double longest = settlingTimeStep(blocks_, settings);
	statics.maxTimeStep = longest;
	settling_ = true;
	frictionScale_ = kSettleFrictionScale;
	frozen_.clear();
	settleSteps_ = 0;
	settleConverged_ = false;
	double first = -1;
	for (int k = 0; k < kSettleSteps; ++k) {
		timeStep_.setNextTry(longest);
		try {
			advance(statics);
		} catch (const std::exception&) {
			// No static solution with these contacts (a system no inertia
			// keeps definite): the scene starts as placed.
			settleConverged_ = false;
			++settleSteps_;
			break;
		}
		++settleSteps_;
		// The settling blocks only: a frozen one (moving, or unsupported)
		// keeps its velocity.
		for (int b = 0; b < blockCount(); ++b)
			if (!blocks_[b].fixed && !frozen_[b]) blocks_[b].velocity.setZero();
		const double moved = stats_.maxDisplacement;
		if (first < 0) first = moved;
		if (settledBlocks_ == 0) break;
		if (moved <= kSettleTolerance * first) {
			settleConverged_ = true;
			break;
		}
	}
	settling_ = false;
	frictionScale_ = 1;
	frozen_.clear();
	if (settledBlocks_ == 0) settleSteps_ = 0;  // nothing to settle: not tried
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
