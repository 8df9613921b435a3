// Saving and restoring MSCCollider's covers (Collider::writeState/readState).
// A block's cover is built from its geometry when first seen (and again when
// the block count or the cover's parameters change), so it depends on the
// history of the scene; it is written as built, with the shell boxes of the
// fixed blocks (built once). Per-call work arrays are not written.
#include "MSCCollider.hpp"
#include "dda/solver/StateStream.hpp"

namespace dda {

void MSCCollider::writeState(StateWriter& out) const {
	out.tag("MSC.");
	out.pod(criticalLengthFactor_);
	out.pod(criticalLength_);
	out.pod(segments_);
	out.size(overrides_.size());
	for (const auto& [block, o] : overrides_) {
		out.pod(block);
		out.pod(o.criticalLength);
		out.pod(o.segments);
	}
	out.pod(static_cast<std::uint8_t>(coverChanged_));
	out.size(covers_.size());
	for (const BlockCover& c : covers_) {
		out.pod(static_cast<std::uint8_t>(c.shape != nullptr));
		out.pod(c.criticalLength);
		out.pod(c.segments);
		out.pod(c.shellCount);
		out.pod(c.firstShell);
		out.pod(c.widening);
		out.pod(static_cast<std::uint8_t>(c.boxesBuilt));
		out.size(c.shells.size());
		for (const Shell& s : c.shells) {
			out.podVector(s.corners);
			out.size(s.divisions.size());
			for (const DivisionPoint& d : s.divisions) {
				out.pod(d.edge);
				out.pod(d.fraction);
			}
		}
		out.podVector(c.vertexShells);
		out.podVector(c.edgeShells);
		out.podVector(c.faceShells);
	}
	out.size(boxes_.size());
	for (const auto& box : boxes_) {
		out.matrix(box.min());
		out.matrix(box.max());
	}
	out.podVector(shellBlock_);
	out.podVector(shellIndex_);
	out.pod(totalShellUpdates_);
	out.pod(coverBuilds_);
}

void MSCCollider::readState(StateReader& in, const std::vector<Block>& blocks) {
	MSCCollider m;
	in.tag("MSC.");
	in.pod(m.criticalLengthFactor_);
	in.pod(m.criticalLength_);
	in.pod(m.segments_);
	const std::size_t overrides = in.size(4 + 8 + 4, "MSC cover overrides");
	for (std::size_t k = 0; k < overrides; ++k) {
		const int block = in.pod<int>();
		Override o{};
		in.pod(o.criticalLength);
		in.pod(o.segments);
		m.overrides_[block] = o;
	}
	m.coverChanged_ = in.pod<std::uint8_t>() != 0;
	m.covers_.resize(in.size(8, "MSC covers"));
	if (m.covers_.size() > blocks.size()) in.fail("more MSC covers than blocks");
	for (std::size_t b = 0; b < m.covers_.size(); ++b) {
		BlockCover& c = m.covers_[b];
		const bool built = in.pod<std::uint8_t>() != 0;
		c.shape = built ? blocks[b].shape.get() : nullptr;
		in.pod(c.criticalLength);
		in.pod(c.segments);
		in.pod(c.shellCount);
		in.pod(c.firstShell);
		in.pod(c.widening);
		c.boxesBuilt = in.pod<std::uint8_t>() != 0;
		c.shells.resize(in.size(16, "MSC shells"));
		if (static_cast<int>(c.shells.size()) != c.shellCount || c.shellCount > kMaxSegments)
			in.fail("MSC cover of block " + std::to_string(b) + " has an inconsistent shell count");
		const int nv = static_cast<int>(blocks[b].vertices.size());
		const int ne = static_cast<int>(blocks[b].shape->edges.size());
		for (Shell& s : c.shells) {
			in.podVector(s.corners, "shell corners");
			for (int v : s.corners)
				if (v < 0 || v >= nv) in.fail("shell corner " + std::to_string(v) + " out of range");
			s.divisions.resize(in.size(4 + 8, "division points"));
			for (DivisionPoint& d : s.divisions) {
				in.pod(d.edge);
				in.pod(d.fraction);
				if (d.edge < 0 || d.edge >= ne) in.fail("division point on edge " + std::to_string(d.edge));
			}
		}
		in.podVector(c.vertexShells, "vertex shells");
		in.podVector(c.edgeShells, "edge shells");
		in.podVector(c.faceShells, "face shells");
		if (built && (c.vertexShells.size() != static_cast<std::size_t>(nv) || c.edgeShells.size() != static_cast<std::size_t>(ne) ||
		              c.faceShells.size() != blocks[b].shape->faces.size()))
			in.fail("MSC cover of block " + std::to_string(b) + " does not match the block's topology");
	}
	m.boxes_.resize(in.size(6 * sizeof(double), "shell boxes"));
	for (auto& box : m.boxes_) {
		Vector3 low, high;
		in.matrix(low);
		in.matrix(high);
		box = Eigen::AlignedBox3d(low, high);
	}
	in.podVector(m.shellBlock_, "shell blocks");
	in.podVector(m.shellIndex_, "shell indices");
	for (int b : m.shellBlock_)
		if (b < 0 || b >= static_cast<int>(m.covers_.size())) in.fail("shell of block " + std::to_string(b));
	for (const BlockCover& c : m.covers_)
		if (c.firstShell < 0 || c.firstShell + c.shellCount > static_cast<int>(m.boxes_.size()))
			if (c.shape) in.fail("MSC shells out of range");
	if (m.shellBlock_.size() != m.boxes_.size() || m.shellIndex_.size() != m.boxes_.size())
		in.fail("MSC shell arrays differ in length");
	in.pod(m.totalShellUpdates_);
	in.pod(m.coverBuilds_);
	*this = std::move(m);
}

}  // namespace dda
