#include "SceneLink.hpp"

#include "dda/geometry/MassProperties.hpp"

#include <algorithm>
#include <limits>
#include <sstream>

namespace dda {

// Which body vertex is which block vertex. YADE made the body from the
// block's own corners: it keeps each corner's coordinates, subtracts its
// centroid c and turns the difference into its principal frame,
// v = q^-1 (x - c), and puts c in state.pos (blocks.py shifts the corners
// near the origin first and adds the shift to pos). So ori0^-1 (x_j - pos)
// is v_k for the corner x_j that body vertex k is, up to round-off:
//   - pos = shift + c rounded: at most eps/2 |pos| per coordinate;
//   - x_j - pos, and the two turns (YADE's and this one): a few eps times the
//     corner's distance from the centroid (measured: at most 2.6e-16 x the
//     block's diagonal, 2.4 eps r, on prisms and boxes up to 1000:1 in any
//     turn, at offsets 0 to 1e6 m).
// The tolerance is eps (kPositionRoundoff |pos| + kFrameRoundoff r), r the
// largest corner distance from the centroid: 8 and 25 times those bounds.
// The core's centroid is not used: YADE's differs from it by its own
// round-off, measured up to ~10 |pos| eps and, on turned 1000:1 blocks at any
// offset, 3.8e-11 x the diagonal: beyond the old tolerance 1e-9 x size (size
// the cube root of the volume, 7e-12 x the diagonal of a 1000:1 prism), which
// refused 6% of them; and, before blocks.py shifted the corners, by up to 25%
// of the block (YADE merged faces that were not coplanar far from the origin).
// Criterion: each body vertex is matched to the nearest unmatched block vertex
// within the tolerance, pairs taken nearest first, and every vertex must be
// matched (a bijection: the counts are equal). A bound derived from "well
// below half the smallest distance between two corners" would be looser: it
// would accept a shape whose corner moved by a fraction of an edge, which is
// another shape, not round-off. With the round-off bound two corners can be
// both within it only if they are within twice the round-off of each other;
// then either assignment is the same shape to round-off, and the injectivity
// keeps the map a bijection.
void SceneLink::link(int blockIndex, int bodyId, const Vector3& position0, const Eigen::Quaterniond& orientation0,
                     const std::vector<Vector3>& localVertices) {
	const Block& b = world.block(blockIndex);
	if (static_cast<int>(links_.size()) < world.blockCount()) links_.resize(world.blockCount());
	const std::size_t n = b.vertices.size();
	if (localVertices.size() != n) {
		std::ostringstream message;
		message << "body " << bodyId << " has " << localVertices.size() << " vertices, block " << blockIndex << " has "
		        << n;
		throw std::invalid_argument(message.str());
	}
	BodyLink link{bodyId, orientation0.normalized(), {}};
	const Eigen::Quaterniond inverse = (b.rotation * link.orientation0).conjugate();
	std::vector<Vector3> blockLocal(n);
	double radius = 0;
	const Vector3 centre = partPosition(blockIndex);
	for (std::size_t j = 0; j < n; ++j) {
		blockLocal[j] = inverse * (b.vertices[j] - position0);
		radius = std::max(radius, (b.vertices[j] - centre).norm());
	}
	const double eps = std::numeric_limits<double>::epsilon();
	const double tolerance = eps * (kPositionRoundoff * position0.norm() + kFrameRoundoff * radius);
	struct Candidate {
		double distance;
		int body, block;
	};
	std::vector<Candidate> candidates;
	std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
	std::vector<int> nearestVertex(n, -1);
	for (std::size_t k = 0; k < n; ++k)
		for (std::size_t j = 0; j < n; ++j) {
			const double d = (blockLocal[j] - localVertices[k]).norm();
			if (nearestVertex[k] < 0 || d < nearest[k]) {  // a NaN distance never matches: reported below
				nearest[k] = d;
				nearestVertex[k] = static_cast<int>(j);
			}
			if (d <= tolerance) candidates.push_back({d, static_cast<int>(k), static_cast<int>(j)});
		}
	std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
		return x.distance != y.distance ? x.distance < y.distance : x.body != y.body ? x.body < y.body : x.block < y.block;
	});
	link.vertexOrder.assign(n, -1);
	std::vector<char> taken(n, 0);
	for (const Candidate& c : candidates)
		if (link.vertexOrder[c.body] < 0 && !taken[c.block]) {
			link.vertexOrder[c.body] = c.block;
			taken[c.block] = 1;
		}
	for (std::size_t k = 0; k < n; ++k) {
		if (link.vertexOrder[k] >= 0) continue;
		std::ostringstream message;
		message.precision(3);
		message << "vertex " << k << " of body " << bodyId << " ";
		if (nearest[k] <= tolerance)
			message << "is within the round-off tolerance only of vertices of block " << blockIndex
			        << " that other vertices of the body match (nearest: vertex " << nearestVertex[k] << ", "
			        << nearest[k] << " m)";
		else
			message << "matches no vertex of block " << blockIndex << ": the nearest, vertex " << nearestVertex[k]
			        << ", is " << nearest[k] << " m away, tolerance " << tolerance << " m (round-off of YADE's frame: eps x ("
			        << kPositionRoundoff << " |pos| + " << kFrameRoundoff << " x corner distance " << radius
			        << " m), |pos| " << position0.norm() << " m)";
		message << "; the body's shape, state.pos or state.ori is not the block's (changed after ddaBlock?)";
		throw std::invalid_argument(message.str());
	}
	links_[blockIndex] = link;
	blockOfBody_[bodyId] = blockIndex;
}

void SceneLink::reserveBlocks(int extra) {
	world.reserveBlocks(extra);
	links_.reserve(world.blockCapacity());
}

const BodyLink* SceneLink::bodyLink(int blockIndex) const {
	if (blockIndex < 0 || blockIndex >= static_cast<int>(links_.size()) || links_[blockIndex].bodyId < 0) return nullptr;
	return &links_[blockIndex];
}

BodyLink* SceneLink::bodyLink(int blockIndex) {
	return const_cast<BodyLink*>(static_cast<const SceneLink*>(this)->bodyLink(blockIndex));
}

int SceneLink::blockOfBody(int bodyId) const {
	const auto found = blockOfBody_.find(bodyId);
	return found == blockOfBody_.end() ? -1 : world.bodyOf(found->second);
}

int SceneLink::partOfBody(int bodyId) const {
	const auto found = blockOfBody_.find(bodyId);
	return found == blockOfBody_.end() ? -1 : found->second;
}

void SceneLink::linkClump(int block, int clumpId, const Eigen::Quaterniond& orientation0) {
	if (world.block(block).partCount < 2) {
		std::ostringstream message;
		message << "block " << block << " is not the body of a concave block: no clump to link";
		throw std::invalid_argument(message.str());
	}
	if (blockOfBody_.count(clumpId)) {
		std::ostringstream message;
		message << "body " << clumpId << " is already linked to block " << blockOfBody_.at(clumpId);
		throw std::invalid_argument(message.str());
	}
	clumps_[block] = ClumpLink{clumpId, orientation0.normalized(), false};
	blockOfBody_[clumpId] = block;
}

const ClumpLink* SceneLink::clumpLink(int block) const {
	const auto found = clumps_.find(block);
	return found == clumps_.end() ? nullptr : &found->second;
}

ClumpLink* SceneLink::clumpLink(int block) {
	return const_cast<ClumpLink*>(static_cast<const SceneLink*>(this)->clumpLink(block));
}

Eigen::Quaterniond SceneLink::clumpOrientation(int block) const {
	const ClumpLink* link = clumpLink(block);
	const Eigen::Quaterniond base = link ? link->orientation0 : Eigen::Quaterniond::Identity();
	return (world.block(block).rotation * base).normalized();
}

Vector3 SceneLink::partPosition(int block) const {
	const Block& b = world.block(block);
	if (b.partCount < 2) return b.centroid;
	return computeMassProperties(b.vertices, b.shape->faces).centroid;
}

Vector3 SceneLink::partVelocity(int block, const Vector3& position) const {
	const Block& body = world.block(world.bodyOf(block));
	if (!world.block(block).isPart()) return body.velocity.head<3>();
	return displacementAt(position - body.centroid, body.velocity);
}

Eigen::Quaterniond SceneLink::bodyOrientation(int blockIndex) const {
	const BodyLink* link = bodyLink(blockIndex);
	const Eigen::Quaterniond base = link ? link->orientation0 : Eigen::Quaterniond::Identity();
	return (world.block(blockIndex).rotation * base).normalized();
}

void SceneLink::localVertices(int blockIndex, const Vector3& position, std::vector<Vector3>& local) const {
	const Block& b = world.block(blockIndex);
	const BodyLink* link = bodyLink(blockIndex);
	const Eigen::Quaterniond inverse = bodyOrientation(blockIndex).conjugate();
	local.clear();
	if (!link) return;
	for (int j : link->vertexOrder) local.push_back(inverse * (b.vertices[j] - position));
}

}  // namespace dda
