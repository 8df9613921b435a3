// Saving and restoring a SceneLink: the world's state, then each block's link
// to its YADE body (body id, the body's orientation at creation, vertex order).
#include "SceneLink.hpp"
#include "dda/core/StateStream.hpp"

namespace dda {

std::string SceneLink::saveState() const {
	StateWriter out;
	world.writeState(out);
	out.tag("LINK");
	out.size(links_.size());
	for (const BodyLink& link : links_) {
		out.pod(link.bodyId);
		out.quaternion(link.orientation0);
		out.podVector(link.vertexOrder);
		out.pod(static_cast<std::uint8_t>(link.synced));
	}
	out.tag("CLMP");
	out.size(clumps_.size());
	for (const auto& [block, clump] : clumps_) {
		out.pod(block);
		out.pod(clump.bodyId);
		out.quaternion(clump.orientation0);
		out.pod(static_cast<std::uint8_t>(clump.synced));
	}
	out.tag("END.");
	return frameState(out.bytes());
}

void SceneLink::loadState(const std::string& state) {
	const std::string payload = unframeState(state);
	StateReader in(payload);
	World restored;
	restored.readState(in);
	in.tag("LINK");
	std::vector<BodyLink> links(in.size(4 + 32 + 8 + 1, "body links"));
	if (static_cast<int>(links.size()) > restored.blockCount()) in.fail("more body links than blocks");
	std::unordered_map<int, int> blockOfBody;
	for (std::size_t b = 0; b < links.size(); ++b) {
		BodyLink& link = links[b];
		in.pod(link.bodyId);
		in.quaternion(link.orientation0);
		in.podVector(link.vertexOrder, "vertex order");
		link.synced = in.pod<std::uint8_t>() != 0;
		const int nv = static_cast<int>(restored.block(static_cast<int>(b)).vertices.size());
		if (link.bodyId >= 0 && static_cast<int>(link.vertexOrder.size()) != nv)
			in.fail("the body link of block " + std::to_string(b) + " does not match its vertices");
		for (int v : link.vertexOrder)
			if (v < 0 || v >= nv) in.fail("vertex order of block " + std::to_string(b));
		if (link.bodyId >= 0 && !blockOfBody.emplace(link.bodyId, static_cast<int>(b)).second)
			in.fail("body " + std::to_string(link.bodyId) + " is linked to two blocks");
	}
	in.tag("CLMP");
	std::map<int, ClumpLink> clumps;
	const std::size_t clumpCount = in.size(4 + 4 + 32 + 1, "clump links");
	for (std::size_t k = 0; k < clumpCount; ++k) {
		const int block = in.pod<int>();
		ClumpLink clump;
		in.pod(clump.bodyId);
		in.quaternion(clump.orientation0);
		clump.synced = in.pod<std::uint8_t>() != 0;
		if (block < 0 || block >= restored.blockCount() || restored.block(block).partCount < 2)
			in.fail("a clump link of block " + std::to_string(block) + ", which is no concave block's body");
		if (!clumps.emplace(block, clump).second || !blockOfBody.emplace(clump.bodyId, block).second)
			in.fail("clump body " + std::to_string(clump.bodyId) + " is linked twice");
	}
	in.tag("END.");
	if (!in.atEnd()) in.fail("bytes left after the end of the state");
	world = std::move(restored);
	links_ = std::move(links);
	blockOfBody_ = std::move(blockOfBody);
	clumps_ = std::move(clumps);
}

}  // namespace dda
