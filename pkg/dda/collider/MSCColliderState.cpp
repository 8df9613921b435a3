// Saving and restoring MSCCollider's covers (Collider::writeState/readState).
// A block's cover is built from its geometry when first seen (and again when
// the block count or the cover's parameters change), so it depends on the
// history of the scene; it is written as built, with its frame faces and
// whether the block's shell boxes were built while it was fixed (built once).
// Those boxes, frames and extents are not written: readState computes them
// again from the restored vertices, which are the ones they were built from,
// so they come out the same (and are not counted as updates again). The
// shell-pair cache, which never changes the pairs, starts empty. Per-call work
// arrays are not written. The file keeps its first layout (per shell its
// corners and division points, per sub-unit its shells as a mask), which the
// compact one in memory (MSCCollider.hpp) is converted to and from: files
// written before it load unchanged.
#include "MSCCollider.hpp"
#include "dda/core/StateStream.hpp"

#include <algorithm>
#include <cstring>

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
		// Per shell its corners and division points, then per vertex, edge
		// and face its linked shells as a mask.
		const ShellRange* linked = shellRanges_.data() + c.firstSubUnit;
		out.size(c.shellCount);
		for (int j = 0; j < c.shellCount; ++j) {
			out.size(std::count_if(linked, linked + c.vertexCount, [j](const ShellRange& r) { return r.contains(j); }));
			for (int v = 0; v < c.vertexCount; ++v)
				if (linked[v].contains(j)) out.pod(v);
			const int s = c.firstShell + j;
			out.size(divisionStart_[s + 2] - divisionStart_[s]);
			for (int k = divisionStart_[s]; k < divisionStart_[s + 2]; ++k) {
				const DivisionPoint& d = divisions_[k];
				const auto& edges = c.shape->edges;
				out.pod(static_cast<int>(std::find(edges.begin(), edges.end(), std::array<int, 2>{d.from, d.to}) - edges.begin()));
				out.pod(d.fraction);
			}
		}
		for (const int count : {c.vertexCount, c.edgeCount, c.faceCount}) {
			out.size(count);
			for (int i = 0; i < count; ++i) out.pod(linked[i].mask());
			linked += count;
		}
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
		if (built) c.shape = blocks[b].shape;
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
		copyFrameCorners(*blocks[b].shape, c);
		const std::size_t shellCount = in.size(16, "MSC shells");
		if (shellCount != static_cast<std::size_t>(c.shellCount) || c.shellCount > kMaxSegments)
			in.fail("MSC cover of block " + std::to_string(b) + " has an inconsistent shell count");
		const int nv = static_cast<int>(blocks[b].vertices.size());
		const int ne = static_cast<int>(blocks[b].shape->edges.size());
		std::vector<std::vector<int>> corners(shellCount);
		std::vector<std::vector<DivisionPoint>> divisions(shellCount);
		for (std::size_t j = 0; j < shellCount; ++j) {
			in.podVector(corners[j], "shell corners");
			for (int v : corners[j])
				if (v < 0 || v >= nv) in.fail("shell corner " + std::to_string(v) + " out of range");
			divisions[j].resize(in.size(4 + 8, "division points"));
			for (DivisionPoint& d : divisions[j]) {
				const int e = in.pod<int>();
				if (e < 0 || e >= ne) in.fail("division point on edge " + std::to_string(e));
				d.from = blocks[b].shape->edges[e][0];
				d.to = blocks[b].shape->edges[e][1];
				in.pod(d.fraction);
			}
		}
		std::vector<std::uint64_t> linked[3];
		in.podVector(linked[0], "vertex shells");
		in.podVector(linked[1], "edge shells");
		in.podVector(linked[2], "face shells");
		if (built && (linked[0].size() != static_cast<std::size_t>(nv) || linked[1].size() != static_cast<std::size_t>(ne) ||
		              linked[2].size() != blocks[b].shape->faces.size()))
			in.fail("MSC cover of block " + std::to_string(b) + " does not match the block's topology");
		if (!built) {
			c.shellCount = 0;  // (built at the next call)
			continue;
		}
		// Kept as built (MSCCollider.hpp): linked shells as ranges, corners
		// as the vertices linked to a shell, division points once per plane.
		// Covers as buildCover makes them fit that; other data is corrupt.
		const auto bad = [&](const char* what) {
			in.fail("MSC cover of block " + std::to_string(b) + ": " + what);
		};
		c.firstSubUnit = static_cast<int>(m.shellRanges_.size());
		c.vertexCount = nv;
		c.edgeCount = ne;
		c.faceCount = static_cast<int>(linked[2].size());
		for (const std::vector<std::uint64_t>& masks : linked)
			for (std::uint64_t mask : masks) {
				const ShellRange range = ShellRange::of(mask);
				if (range.mask() != mask || (c.shellCount < 64 && mask >> c.shellCount))
					bad("linked shells are not consecutive slabs of the block");
				m.shellRanges_.push_back(range);
			}
		const ShellRange* vertexShells = m.shellRanges_.data() + c.firstSubUnit;
		const auto same = [](const DivisionPoint& x, const DivisionPoint& y) {
			return x.from == y.from && x.to == y.to && std::memcmp(&x.fraction, &y.fraction, sizeof(double)) == 0;
		};
		// Shell j lists the points on its lower plane (none for the first),
		// the last plane appended to m.divisions_ (`lower` points), then
		// those on its upper plane (none for the last), appended for shell j + 1.
		if (c.shellCount > 0) m.divisionStart_.push_back(static_cast<int>(m.divisions_.size()));
		std::size_t lower = 0;
		for (int j = 0; j < c.shellCount; ++j) {
			std::vector<int> linkedCorners;
			for (int v = 0; v < nv; ++v)
				if (vertexShells[v].contains(j)) linkedCorners.push_back(v);
			if (corners[j] != linkedCorners) bad("shell corners are not the vertices linked to the shell");
			const std::vector<DivisionPoint>& points = divisions[j];
			if (points.size() < lower || !std::equal(points.begin(), points.begin() + lower, m.divisions_.end() - lower, same))
				bad("a shell's division points do not start with those of the shell below");
			if (j + 1 == c.shellCount) {
				if (points.size() != lower) bad("the last shell has division points above it");
				break;
			}
			m.divisionStart_.push_back(static_cast<int>(m.divisions_.size()));
			m.divisions_.insert(m.divisions_.end(), points.begin() + lower, points.end());
			lower = points.size() - lower;
		}
	}
	m.divisionStart_.resize(m.divisionStart_.size() + 2, static_cast<int>(m.divisions_.size()));
	m.shellRanges_.shrink_to_fit();
	m.divisions_.shrink_to_fit();
	m.divisionStart_.shrink_to_fit();
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
