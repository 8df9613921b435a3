// World's prescribed motions of fixed blocks (World.hpp, BaseMotion.hpp;
// doc/DESIGN.md "Prescribed motion of fixed blocks"): the blocks a motion
// moves, their known displacement over each attempt, their move after the
// accepted step, and the work the motion does on the moving blocks.
#include "World.hpp"

#include "ContactEquations.hpp"
#include "dda/core/StateStream.hpp"

#include <algorithm>
#include <sstream>

namespace dda {

int World::addBaseMotion(const std::vector<int>& indices, BaseMotion motion) {
	if (indices.empty()) throw InputError("a base motion needs at least one fixed block");
	std::vector<int> moved;
	for (const int index : indices) {
		if (index < 0 || index >= blockCount()) {
			std::ostringstream message;
			message << "no DDA block with index " << index << " (the scene has " << blockCount() << ")";
			throw InputError(message.str());
		}
		const int body = bodyOf(index);
		if (!blocks_[body].fixed)
			throw InputError("block " + std::to_string(index) +
			                 " is not fixed: only a fixed block (no unknowns) can be given a prescribed motion");
		for (int p = 0; p < blocks_[body].partCount; ++p) moved.push_back(body + p);
	}
	std::sort(moved.begin(), moved.end());
	for (std::size_t k = 0; k < moved.size(); ++k) {
		if (k > 0 && moved[k] == moved[k - 1])
			throw InputError("block " + std::to_string(moved[k]) + " is given twice to one base motion");
		if (blocks_[moved[k]].shaken)
			throw InputError("block " + std::to_string(moved[k]) + " has a prescribed motion already");
	}
	baseMotions_.push_back(ShakenGroup{std::move(motion), std::move(moved)});
	markShakenBlocks();
	return baseMotionCount() - 1;
}

const BaseMotion& World::baseMotion(int motion) const { return baseMotions_.at(motion).motion; }

const std::vector<int>& World::baseMotionBlocks(int motion) const { return baseMotions_.at(motion).blocks; }

void World::markShakenBlocks() {
	for (Block& block : blocks_) block.shaken = false;
	for (const ShakenGroup& group : baseMotions_)
		for (const int b : group.blocks) blocks_[b].shaken = true;
}

void World::prescribeMotions(double dt) {
	prescribed_.assign(blocks_.size(), Vector12::Zero());
	prescribedLargest_ = 0;
	for (const ShakenGroup& group : baseMotions_) {
		const Vector3 u = group.motion.displacement(time_, time_ + dt);
		prescribedLargest_ = std::max(prescribedLargest_, u.norm());
		for (const int b : group.blocks) prescribed_[b].head<3>() = u;
	}
}

void World::moveShakenBlocks(double dt) {
	for (const ShakenGroup& group : baseMotions_) {
		const Vector3 velocity = group.motion.velocity(time_ + dt);
		for (const int b : group.blocks) {
			Block& block = blocks_[b];
			const Vector3 u = prescribed_[b].head<3>();
			for (Vector3& x : block.vertices) x += u;
			block.centroid += u;
			block.velocity.head<3>() = velocity;
		}
	}
	// Faces that were flush between a shaken and a still fixed block (part)
	// may be no longer (blocks added since the motions count too).
	if (std::any_of(blocks_.begin(), blocks_.end(), [](const Block& b) { return b.fixed && !b.shaken; }))
		detection_.fixedBlocksMoved();
}

double World::boundaryWork(const Contact& contact, double gamma) const {
	const int bi = contact.bodyI, bj = contact.bodyJ;
	const bool knownI = blocks_[bi].shaken, knownJ = blocks_[bj].shaken;
	if (knownI == knownJ) return 0;  // none, or two fixed blocks (never a contact)
	ContactTerms terms;
	if (!contactTerms(contact, blocks_[bi], blocks_[bj], terms)) return 0;
	Vector24 D;
	D << openClose_.solutionOf(bi), openClose_.solutionOf(bj);
	// The model's force on both sides, F - K D; the known side's part.
	Vector24 force = terms.force;
	for (int r = 0; r < terms.rank; ++r) force -= (terms.weight[r] * terms.vector[r].dot(D)) * terms.vector[r];
	const int known = knownI ? 0 : 12;
	return -gamma * force.segment<12>(known).dot(D.segment<12>(known));
}

// A section only when there are motions: a scene without keeps its bytes.
void World::writeBaseMotions(StateWriter& out) const {
	if (baseMotions_.empty()) return;
	out.tag("BASE");
	out.pod(energy_.boundaryWork);
	out.size(baseMotions_.size());
	for (const ShakenGroup& group : baseMotions_) {
		group.motion.writeState(out);
		out.podVector(group.blocks);
	}
}

void World::readBaseMotions(StateReader& in) {
	if (in.nextTag("BASE")) {
		in.tag("BASE");
		in.pod(energy_.boundaryWork);
		const std::size_t motions = in.size(8, "base motions");
		for (std::size_t m = 0; m < motions; ++m) {
			BaseMotion motion = BaseMotion::readState(in);
			std::vector<int> blocks;
			in.podVector(blocks, "shaken blocks");
			for (const int b : blocks)
				if (b < 0 || b >= blockCount() || !blocks_[b].fixed) in.fail("shaken block " + std::to_string(b));
			baseMotions_.push_back(ShakenGroup{std::move(motion), std::move(blocks)});
		}
	}
	markShakenBlocks();
}

}  // namespace dda
