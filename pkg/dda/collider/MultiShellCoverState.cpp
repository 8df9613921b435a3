// Saving and restoring MSCCollider's covers (Collider::writeState/readState).
// A block's cover is built from its geometry when first seen (and again when
// the block count or the cover's parameters change), so it depends on the
// history of the scene; it is written as built, with its frame faces and
// whether the block's shell boxes were built while it was fixed (built once).
// Those boxes, frames and extents are not written: read computes them
// again from the restored vertices, which are the ones they were built from,
// so they come out the same (and are not counted as updates again). The
// shell-pair cache, which never changes the pairs, starts empty. Per-call work
// arrays are not written. The file keeps its first layout (per shell its
// corners and division points, per sub-unit its shells as a mask), which the
// compact one in memory (MultiShellCover.hpp) is converted to and from: files
// written before it load unchanged.
#include "MultiShellCover.hpp"

#include "dda/core/StateStream.hpp"

#include <algorithm>
#include <cstring>

namespace dda::msc {

void MultiShellCover::write(StateWriter& out) const {
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

void MultiShellCover::read(StateReader& in, const std::vector<Block>& blocks) {
	in.pod(criticalLengthFactor_);
	in.pod(criticalLength_);
	in.pod(segments_);
	const std::size_t overrides = in.size(4 + 8 + 4, "MSC cover overrides");
	for (std::size_t k = 0; k < overrides; ++k) {
		const int block = in.pod<int>();
		CoverParameters o{};
		in.pod(o.criticalLength);
		in.pod(o.segments);
		overrides_[block] = o;
	}
	coverChanged_ = in.pod<std::uint8_t>() != 0;
	covers_.resize(in.size(8, "MSC covers"));
	std::vector<char> boxesBuilt(covers_.size());
	if (covers_.size() > blocks.size()) in.fail("more MSC covers than blocks");
	for (std::size_t b = 0; b < covers_.size(); ++b) {
		bool built = false;
		readCover(in, blocks[b], static_cast<int>(b), covers_[b], built);
		boxesBuilt[b] = built;
	}
	divisionStart_.resize(divisionStart_.size() + 2, static_cast<int>(divisions_.size()));
	shellRanges_.shrink_to_fit();
	divisions_.shrink_to_fit();
	divisionStart_.shrink_to_fit();
	in.pod(totalShellUpdates_);
	in.pod(coverBuilds_);
	layoutShells();
	for (std::size_t b = 0; b < covers_.size(); ++b)
		if (boxesBuilt[b]) updateBoxes(blocks[b], covers_[b], frames_[b]);   // not counted: the saved count holds
}

void MultiShellCover::readCover(StateReader& in, const Block& block, int b, BlockCover& c, bool& boxesBuilt) {
	const bool built = in.pod<std::uint8_t>() != 0;
	if (built) c.shape = block.shape;
	in.pod(c.criticalLength);
	in.pod(c.segments);
	in.pod(c.shellCount);
	in.pod(c.widening);
	// (A block freed since is recomputed at the next call either way.)
	boxesBuilt = in.pod<std::uint8_t>() != 0 && built && block.fixed;
	for (int& f : c.frameFaces) in.pod(f);
	const int faces = static_cast<int>(block.shape->faces.size());
	const auto inRange = [faces](int f) { return f >= 0 && f < faces; };
	const auto& ff = c.frameFaces;
	if (!(ff[0] == -1 && ff[1] == -1 && ff[2] == -1) && !(inRange(ff[0]) && inRange(ff[1]) && inRange(ff[2])))
		in.fail("MSC frame faces of block " + std::to_string(b) + " out of range");
	copyFrameCorners(*block.shape, c);
	const std::size_t shellCount = in.size(16, "MSC shells");
	if (shellCount != static_cast<std::size_t>(c.shellCount) || c.shellCount > kMaxCoverSegments)
		in.fail("MSC cover of block " + std::to_string(b) + " has an inconsistent shell count");
	const int nv = static_cast<int>(block.vertices.size());
	const int ne = static_cast<int>(block.shape->edges.size());
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
			d.from = block.shape->edges[e][0];
			d.to = block.shape->edges[e][1];
			in.pod(d.fraction);
		}
	}
	std::vector<std::uint64_t> linked[3];
	in.podVector(linked[0], "vertex shells");
	in.podVector(linked[1], "edge shells");
	in.podVector(linked[2], "face shells");
	if (built && (linked[0].size() != static_cast<std::size_t>(nv) || linked[1].size() != static_cast<std::size_t>(ne) ||
	              linked[2].size() != block.shape->faces.size()))
		in.fail("MSC cover of block " + std::to_string(b) + " does not match the block's topology");
	if (!built) {
		c.shellCount = 0;  // (built at the next call)
		return;
	}
	c.vertexCount = nv;
	c.edgeCount = ne;
	adoptShellLists(in, b, c, corners, divisions, linked);
}

void MultiShellCover::adoptShellLists(StateReader& in, int b, BlockCover& c, const std::vector<std::vector<int>>& corners,
                                      const std::vector<std::vector<DivisionPoint>>& divisions,
                                      const std::vector<std::uint64_t> (&linked)[3]) {
	// Kept as built (MultiShellCover.hpp): linked shells as ranges, corners
	// as the vertices linked to a shell, division points once per plane.
	// Covers as buildCover makes them fit that; other data is corrupt.
	const auto bad = [&](const char* what) { in.fail("MSC cover of block " + std::to_string(b) + ": " + what); };
	const int nv = c.vertexCount;
	c.firstSubUnit = static_cast<int>(shellRanges_.size());
	c.faceCount = static_cast<int>(linked[2].size());
	for (const std::vector<std::uint64_t>& masks : linked)
		for (std::uint64_t mask : masks) {
			const ShellRange range = ShellRange::of(mask);
			if (range.mask() != mask || (c.shellCount < 64 && mask >> c.shellCount))
				bad("linked shells are not consecutive slabs of the block");
			shellRanges_.push_back(range);
		}
	const ShellRange* vertexShells = shellRanges_.data() + c.firstSubUnit;
	const auto same = [](const DivisionPoint& x, const DivisionPoint& y) {
		return x.from == y.from && x.to == y.to && std::memcmp(&x.fraction, &y.fraction, sizeof(double)) == 0;
	};
	// Shell j lists the points on its lower plane (none for the first),
	// the last plane appended to divisions_ (`lower` points), then
	// those on its upper plane (none for the last), appended for shell j + 1.
	if (c.shellCount > 0) divisionStart_.push_back(static_cast<int>(divisions_.size()));
	std::size_t lower = 0;
	for (int j = 0; j < c.shellCount; ++j) {
		std::vector<int> linkedCorners;
		for (int v = 0; v < nv; ++v)
			if (vertexShells[v].contains(j)) linkedCorners.push_back(v);
		if (corners[j] != linkedCorners) bad("shell corners are not the vertices linked to the shell");
		const std::vector<DivisionPoint>& points = divisions[j];
		if (points.size() < lower || !std::equal(points.begin(), points.begin() + lower, divisions_.end() - lower, same))
			bad("a shell's division points do not start with those of the shell below");
		if (j + 1 == c.shellCount) {
			if (points.size() != lower) bad("the last shell has division points above it");
			break;
		}
		divisionStart_.push_back(static_cast<int>(divisions_.size()));
		divisions_.insert(divisions_.end(), points.begin() + lower, points.end());
		lower = points.size() - lower;
	}
}

}  // namespace dda::msc
