#include "SceneLink.hpp"

#include <sstream>

namespace dda {

void SceneLink::link(int blockIndex, int bodyId, const Eigen::Quaterniond& orientation0,
                     const std::vector<Vector3>& localVertices) {
	const Block& b = world.block(blockIndex);
	if (static_cast<int>(links_.size()) < world.blockCount()) links_.resize(world.blockCount());
	if (localVertices.size() != b.vertices.size()) {
		std::ostringstream message;
		message << "body " << bodyId << " has " << localVertices.size() << " vertices, block " << blockIndex << " has "
		        << b.vertices.size();
		throw std::invalid_argument(message.str());
	}
	BodyLink link{bodyId, orientation0.normalized(), {}};
	const Eigen::Quaterniond inverse = (b.rotation * link.orientation0).conjugate();
	const double tolerance = 1e-9 * b.size;
	for (std::size_t k = 0; k < localVertices.size(); ++k) {
		int match = -1;
		for (std::size_t j = 0; j < b.vertices.size(); ++j)
			if ((inverse * (b.vertices[j] - b.centroid) - localVertices[k]).norm() <= tolerance) match = static_cast<int>(j);
		if (match < 0) {
			std::ostringstream message;
			message << "vertex " << k << " of body " << bodyId << " matches no vertex of block " << blockIndex;
			throw std::invalid_argument(message.str());
		}
		link.vertexOrder.push_back(match);
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
	return found == blockOfBody_.end() ? -1 : found->second;
}

Eigen::Quaterniond SceneLink::bodyOrientation(int blockIndex) const {
	const BodyLink* link = bodyLink(blockIndex);
	const Eigen::Quaterniond base = link ? link->orientation0 : Eigen::Quaterniond::Identity();
	return (world.block(blockIndex).rotation * base).normalized();
}

std::vector<Vector3> SceneLink::localVertices(int blockIndex) const {
	const Block& b = world.block(blockIndex);
	const BodyLink* link = bodyLink(blockIndex);
	const Eigen::Quaterniond inverse = bodyOrientation(blockIndex).conjugate();
	std::vector<Vector3> local;
	if (!link) return local;
	for (int j : link->vertexOrder) local.push_back(inverse * (b.vertices[j] - b.centroid));
	return local;
}

}  // namespace dda
