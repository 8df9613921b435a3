// The line search of the open-close iteration (OpenCloseIteration::lineSearch,
// OpenClose.hpp): per group of blocks that contacts join, the step t in
// (0, 1] along the Newton step that minimises the step's energy.
#include "OpenClose.hpp"

#include <algorithm>

namespace dda {

namespace {
// Solves of a step's iteration that take Newton's full step before the line
// search is used regardless (see markSearchedGroups).
constexpr int kFullNewtonSolves = 4;
}  // namespace

const Vector12& OpenCloseIteration::deltaOf(int block) const {
	static const Vector12 zero = Vector12::Zero();
	const int k = movingIndex_[block];
	return k < 0 ? zero : deltas_[k];
}

double OpenCloseIteration::lineSearch(const Attempt& attempt) {
	const int n = static_cast<int>(moving_.size());
	deltas_.resize(n);
	for (int k = 0; k < n; ++k) deltas_[k] = solutions_[k] - iterate_[k];
	const std::vector<int>& root = groupRoot_;
	markSearchedGroups(attempt);
	blockSlopes(attempt);
	orderLines();
	double smallest = 1;
	for (int g = 0; g < n; ++g) {
		if (!groupKink_[g] || group_.done[g]) continue;
		// Bisection on the derivative (searchLine; certified: the same
		// result with fewer evaluations).
		const double t = searchLine(orderedLines_.data() + groupLines_[g], orderedLines_.data() + groupLines_[g + 1],
		                            groupSlope_[g], groupCurvature_[g], keepTerms_);
		// A step this close to the full one lowers the energy by no
		// measurable amount more: take the Newton point.
		if (t <= 1 - 1e-9) groupStep_[g] = t;
		smallest = std::min(smallest, groupStep_[g]);
	}
	for (int k = 0; k < n; ++k) {
		if (group_.done[root[k]]) continue;  // converged: kept
		const double t = groupStep_[root[k]];
		if (t == 1)
			iterate_[k] = solutions_[k];
		else
			iterate_[k] += t * deltas_[k];
	}
	return smallest;
}

void OpenCloseIteration::markSearchedGroups(const Attempt& attempt) {
	const int n = static_cast<int>(moving_.size());
	const std::vector<Contact>& contacts = attempt.contacts;
	// Per group (by its root): whether its true energy must be searched,
	// its blocks' slope and curvature along the step, its contacts' lines.
	// The Newton step is the exact minimiser of the model along the line
	// unless some contact crosses a kink of its energy on the way (a gap
	// changing sign against its state, a stuck stretch passing its limit,
	// when `searchKinks`) or slips.
	groupKink_.assign(n, 0);
	groupSlope_.assign(n, 0.0);
	groupCurvature_.assign(n, 0.0);
	lines_.clear();
	lineGroup_.clear();
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		const Contact& contact = contacts[c];
		const int bi = contact.bodyI, bj = contact.bodyJ;
		const int group = contactGroup_[c];
		// A slipping contact's force is not quadratic, so a group with one is
		// always searched. Opening and closing are searched once a contact of
		// the group has swung back (opened and closed again, or the reverse)
		// or its pass runs long: a searched step stops at the energy's minimum
		// along the way, often where the first of many impacting corners
		// touches, so searching those from the start cost a stiff pile one
		// solve per closing contact.
		const bool searchKinks = group_.swungBack[group] || group_.passSolves[group] >= kFullNewtonSolves;
		const ContactLine line = contactLine(contact, attempt.blocks[bi], attempt.blocks[bj], solutionOf(bi),
		                                     solutionOf(bj), deltaOf(bi), deltaOf(bj));
		lines_.push_back(line);
		lineGroup_.push_back(group);
		bool kink = false;
		if (contact.normal.valid && searchKinks) {
			const double g0 = line.gap, g1 = line.gap + line.gapRate;
			kink = isClosed(contact) ? (!line.bonded && std::max(g0, g1) > 0) : std::min(g0, g1) < 0;
			// The secant force is quadratic in energy only where the contact
			// is closed at both ends of the step.
			if (contact.secantWeight > 0 && !line.bonded)
				kink = kink || (line.startGap < 0 ? std::max(g0, g1) > 0 : std::min(g0, g1) < 0);
		}
		if (searchKinks && !contact.slipping && line.tangential)
			kink = kink || (line.stretch + line.stretchRate).norm() > line.limit / line.shearStiffness;
		// A slipping contact's force is not quadratic: its model is exact
		// only at the iterate, and Newton's steps alone can swing about the
		// minimum (seen: the same tangential forces every other solve).
		kink = kink || (contact.slipping && line.tangential);
		if (kink) groupKink_[group] = 1;
	}
}

void OpenCloseIteration::blockSlopes(const Attempt& attempt) {
	const int n = static_cast<int>(moving_.size());
	const std::vector<int>& root = groupRoot_;
	// d Phi / dt along D_k + t Delta: the blocks' quadratic energy
	// 1/2 D^T K D - f^T D, plus each contact's (ContactLine). Phi is convex,
	// so the derivative rises with t; it is negative at 0 (the Newton step
	// descends), and the minimiser is where it vanishes.
	BlockSystem own;
	for (int k = 0; k < n; ++k) {
		if (!groupKink_[root[k]] || deltas_[k].isZero()) continue;
		const BlockSystem* system = &own;
		if (ownSystemOf_[k] >= 0)
			system = &ownSystems_[ownSystemOf_[k]];
		else
			assembleBlock(attempt.blocks[moving_[k]], attempt.settings, attempt.dt, startAccelerationOf(k), own);
		groupSlope_[root[k]] += deltas_[k].dot(system->stiffness * iterate_[k] - system->force);
		groupCurvature_[root[k]] += deltas_[k].dot(system->stiffness * deltas_[k]);
	}
}

void OpenCloseIteration::orderLines() {
	const int n = static_cast<int>(moving_.size());
	// The lines of each searched group, together (a counting sort by group).
	groupStep_.assign(n, 1.0);
	groupLines_.assign(n + 1, 0);
	for (std::size_t c = 0; c < lines_.size(); ++c)
		if (groupKink_[lineGroup_[c]]) ++groupLines_[lineGroup_[c] + 1];
	for (int g = 0; g < n; ++g) groupLines_[g + 1] += groupLines_[g];
	// Copied in that order, so the bisection reads each group's lines
	// contiguously (and sums them in the same order as before).
	orderedLines_.resize(groupLines_[n]);
	std::vector<int> next(groupLines_.begin(), groupLines_.end() - 1);
	for (std::size_t c = 0; c < lines_.size(); ++c)
		if (groupKink_[lineGroup_[c]]) orderedLines_[next[lineGroup_[c]]++] = lines_[c];
}

}  // namespace dda
