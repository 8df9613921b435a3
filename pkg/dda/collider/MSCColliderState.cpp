// Saving and restoring MSCCollider's covers (Collider::writeState/readState).
// A block's cover is built from its geometry when first seen (and again when
// the block count or the cover's parameters change), so it depends on the
// history of the scene; it is written as built, with its frame faces and
// whether the block's shell boxes were built while it was fixed (built once).
// Those boxes, frames and extents are not written: readState computes them
// again from the restored vertices, which are the ones they were built from,
// so they come out the same (and are not counted as updates again). The
// shell-pair cache, which never changes the pairs, starts empty. Per-call work
// arrays are not written.
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
		out.pod(c.widening);
		out.pod(static_cast<std::uint8_t>(c.boxesBuilt));
		for (int f : c.frameFaces) out.pod(f);
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
	std::vector<char> boxesBuilt(m.covers_.size());
	if (m.covers_.size() > blocks.size()) in.fail("more MSC covers than blocks");
	for (std::size_t b = 0; b < m.covers_.size(); ++b) {
		BlockCover& c = m.covers_[b];
		const bool built = in.pod<std::uint8_t>() != 0;
		c.shape = built ? blocks[b].shape.get() : nullptr;
		in.pod(c.criticalLength);
		in.pod(c.segments);
		in.pod(c.shellCount);
		in.pod(c.widening);
		// (A block freed since is recomputed at the next call either way.)
		boxesBuilt[b] = in.pod<std::uint8_t>() != 0 && built && blocks[b].fixed;
		for (int& f : c.frameFaces) in.pod(f);
		const int faces = static_cast<int>(blocks[b].shape->faces.size());
		const auto inRange = [faces](int f) { return f >= 0 && f < faces; };
		const auto& ff = c.frameFaces;
		if (!(ff[0] == -1 && ff[1] == -1 && ff[2] == -1) && !(inRange(ff[0]) && inRange(ff[1]) && inRange(ff[2])))
			in.fail("MSC frame faces of block " + std::to_string(b) + " out of range");
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
	in.pod(m.totalShellUpdates_);
	in.pod(m.coverBuilds_);
	m.layoutShells();
	const long updates = m.totalShellUpdates_;
	for (std::size_t b = 0; b < m.covers_.size(); ++b)
		if (boxesBuilt[b]) m.updateBoxes(blocks[b], m.covers_[b], m.frames_[b]);
	m.totalShellUpdates_ = updates;
	*this = std::move(m);
}

}  // namespace dda
