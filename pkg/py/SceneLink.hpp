// The link between a dda::World and the YADE bodies that show its blocks.
// A YADE Polyhedra body stores its vertices in a local frame (origin at the
// centroid, axes along the principal axes chosen by YADE when the body was
// made) and in YADE's own vertex order; this keeps, per block, the body id, the
// body's orientation at creation and the vertex permutation, so that a sync
// writes position, orientation and (deformed) local vertices without any search.
#pragma once

#include "dda/solver/World.hpp"

#include <Eigen/Geometry>

#include <map>
#include <string>
#include <unordered_map>
#include <vector>

namespace dda {

struct BodyLink {
	int bodyId = -1;
	Eigen::Quaterniond orientation0 = Eigen::Quaterniond::Identity();  // body ori at creation
	std::vector<int> vertexOrder;  // body vertex k is block vertex vertexOrder[k]
	bool synced = false;           // written at least once (fixed blocks need only that)
};

// A concave block (World::addConcaveBlock) shows in YADE as a clump: each
// part a member body with a Polyhedra shape (linked like any block), the
// block as a whole the clump body, whose state the sync writes (position the
// block's centroid, orientation, velocity, angular velocity).
struct ClumpLink {
	int bodyId = -1;
	Eigen::Quaterniond orientation0 = Eigen::Quaterniond::Identity();  // the clump's ori at creation
	bool synced = false;
};

class SceneLink {
public:
	// Rewrite a body's vertices when the strain accumulated since the last
	// write exceeds this (relative length change, well above round-off).
	static constexpr double kVertexSyncStrain = 1e-13;

	World world;

	// Round-off factors of the vertex match (SceneLink.cpp, link): the
	// tolerance is eps (kPositionRoundoff |pos| + kFrameRoundoff r), r the
	// largest distance of a corner from the centroid [m].
	static constexpr double kPositionRoundoff = 4;
	static constexpr double kFrameRoundoff = 64;

	// Matches the body's vertices (local, in the frame at position0 turned by
	// orientation0: the body's state.pos and state.ori) one to one to the
	// block's corners, each within the round-off tolerance above; else
	// std::invalid_argument naming the vertex, the distance and the tolerance.
	void link(int block, int bodyId, const Vector3& position0, const Eigen::Quaterniond& orientation0,
	          const std::vector<Vector3>& localVertices);
	const BodyLink* bodyLink(int block) const;
	BodyLink* bodyLink(int block);
	// The clump body of a concave block, `block` its body (World::bodyOf);
	// std::invalid_argument when it is not one, or the id is taken.
	void linkClump(int block, int clumpId, const Eigen::Quaterniond& orientation0);
	const ClumpLink* clumpLink(int block) const;  // nullptr unless linked
	ClumpLink* clumpLink(int block);
	const std::map<int, ClumpLink>& clumps() const { return clumps_; }
	// The block a body shows: the block itself, or for a member or the clump
	// of a concave block its body (World::bodyOf); -1 for other bodies.
	int blockOfBody(int bodyId) const;
	// The block a body is linked to itself: a member's part (not its body), a clump's body; -1 for others.
	int partOfBody(int bodyId) const;
	Eigen::Quaterniond bodyOrientation(int block) const;
	Eigen::Quaterniond clumpOrientation(int block) const;
	// Where YADE's body of a block sits [m]: the block's centroid, or for a
	// part of a concave block the part's own (the body of a concave block
	// holds the whole block's centroid; its own part's is computed).
	Vector3 partPosition(int block) const;
	// Velocity [m/s] of the block's point at `position` (its partPosition) in its body's motion.
	Vector3 partVelocity(int block, const Vector3& position) const;
	// The block's corners in its YADE body's frame, the body at `position`
	// (its partPosition) [m], into `local` (replaced; none for an unlinked block).
	void localVertices(int block, const Vector3& position, std::vector<Vector3>& local) const;

	// World::reserveBlocks, and as much room in the body links.
	void reserveBlocks(int extra);
	int blockCount() const { return world.blockCount(); }
	double motionHalfSize() { return world.motionHalfSize(); }
	double time() const { return world.time(); }
	long steps() const { return world.steps(); }

	// The whole scene (world and body links) as a framed binary state
	// (dda/core/StateStream.hpp), and back. loadState throws StateError
	// naming the problem and leaves this scene unchanged.
	std::string saveState() const;
	void loadState(const std::string& state);

private:
	std::vector<BodyLink> links_;  // per block; bodyId -1 until linked
	std::unordered_map<int, int> blockOfBody_;  // a member's part, a clump's body
	std::map<int, ClumpLink> clumps_;           // by the concave block's body
};

}  // namespace dda
