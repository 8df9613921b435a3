// MSCCollider's covers (the method: MSCCollider.hpp). Per block its cover,
// built once from the block's geometry: slabs across its main axis, per
// vertex, edge and face the slabs it touches, per inner plane its division
// points, and the faces of its frame. Per call the shells' boxes, their
// extents in the block's frame and the frame itself, recomputed from the
// corners of moving blocks (and of fixed blocks once). Shells are numbered
// flat, block after block.
#pragma once

#include "dda/block/Block.hpp"
#include "dda/collider/Collider.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

namespace dda {

class StateWriter;
class StateReader;

namespace msc {

// Shells are widened, beyond kBroadPhaseMarginFactor x d0, by this x the
// block's bounding-box diagonal [-]. Rule: the two widenings of a pair sum
// to at least 2 x kDefaultRelativeLengthTolerance x the larger diagonal,
// above the sqrt(2) x lengthTolerance by which the narrow phase reaches
// past d0, and above the round-off of division points and of affine
// motion (~1e-16 relative per step); 4e-8 of a 10 m block is 0.4 um.
constexpr double kShellWideningRelative = 4e-8;
// A frame is used when its three unit face normals span at least this
// volume (|det|, 1 for orthogonal ones) when chosen, and half of it at each
// step (a strained block); else the coordinate axes are its frame [-].
constexpr double kMinFrameDeterminant = 0.5;

// A sub-unit's linked shells: slabs first..last (an interval's slabs are
// consecutive), none when first > last.
struct ShellRange {
	std::uint8_t first = 1, last = 0;
	// The range of a mask of consecutive slabs.
	static ShellRange of(std::uint64_t mask) {
		ShellRange r;
		for (int j = 0; j < kMaxCoverSegments; ++j)
			if (mask >> j & 1) {
				if (r.first > r.last) r.first = static_cast<std::uint8_t>(j);
				r.last = static_cast<std::uint8_t>(j);
			}
		return r;
	}
	bool contains(int j) const { return first <= j && j <= last; }
	std::uint64_t mask() const {
		return first > last ? 0 : (~std::uint64_t{0} >> (63 - last)) & (~std::uint64_t{0} << first);
	}
};

// A point where edge {from, to} crosses a slab's plane.
struct DivisionPoint {
	int from, to;
	double fraction;  // point = from + fraction x (to - from), in [0, 1]
};

struct BlockCover {
	// The cover is rebuilt when the block's shape changes (held: its
	// address is not reused, and saving finds division points' edges in it).
	// Blocks of one topology share one shape (TopologyPool), so this sees
	// a change of topology only; a world replaces its blocks only when it
	// reads a state, and then it has a new collider too.
	std::shared_ptr<const PolyhedronTopology> shape;
	double criticalLength = 0;                // [m], as built
	double widening = 0;                      // [m]: kShellWideningRelative x diagonal
	int segments = 0;                         // as asked (used when the block is long)
	int shellCount = 0;
	int firstShell = 0;    // into the flat shell arrays
	int firstSubUnit = 0;  // into shellRanges_: its vertices, then edges, then faces
	int vertexCount = 0, edgeCount = 0, faceCount = 0;
	int linkedSetCount = 0;  // its sets in LinkedSets (the chain starts in its frame)
	std::array<int, 3> frameFaces{-1, -1, -1};
	// The frame faces' corners, copied from the shape so that each step
	// reads them here rather than through the shape's face lists (three
	// dependent cache misses per block): per face its corner count, then
	// its corners. All zero when they do not fit (more than 256 vertices
	// or 16 bytes): the shape's faces are read then.
	std::array<std::uint8_t, 16> frameCorners{};
	// Boxes and frame computed while the block was fixed (kept until it moves).
	bool boxesBuilt = false;
};

// A block's frame at this step: rows of `axes` are unit face normals (or
// the coordinate axes), `dual` = axes^-1; a shell's extent is the range of
// axes x (p - origin) over its points p. With the cover's widening and
// first shell, what the frame test and the linked sets read of a pair's
// second block (taken in no particular order) lies in the first two of
// its three cache lines.
struct alignas(64) Frame {
	Eigen::Matrix3d dual = Eigen::Matrix3d::Identity();
	Vector3 origin = Vector3::Zero();
	double reach = 0;      // [m], largest |extent| of its shells (round-off scale)
	double widening = 0;   // [m], its cover's
	int firstShell = 0;    // its cover's
	// The block's linked sets in LinkedSets, most recently used first (a
	// chain through next), -1: none. Kept from call to call, unlike the
	// rest, and read with the frame for the same cache lines.
	int linkedSets = -1;
	Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
};

// A cover's parameters: critical length [m] and segments [-].
struct CoverParameters {
	double criticalLength;
	int segments;
};

class MultiShellCover {
public:
	// criticalLengthFactor > 0 [-], segments in [1, kMaxCoverSegments]; InputError otherwise.
	MultiShellCover(double criticalLengthFactor, int segments);

	// MSCCollider::setCover, setBlockCover (taken at the next update).
	void setCover(double criticalLength, int segments);
	void setBlockCover(int block, double criticalLength, int segments);
	double criticalLengthFactor() const { return criticalLengthFactor_; }
	double criticalLength() const { return criticalLength_; }  // [m], 0 = by block size
	int segments() const { return segments_; }

	// Builds the covers of new blocks, of blocks whose shape changed and of
	// blocks whose parameters changed (all when the block count changed);
	// true when it did, and the shells were laid out anew.
	bool update(const std::vector<Block>& blocks);
	// Boxes, frames, extents and fixed flags of this call's shells: moving
	// blocks' every call, fixed blocks' once. Returns the shells updated.
	long updateShells(const std::vector<Block>& blocks);

	int shellTotal() const { return static_cast<int>(shellBlock_.size()); }
	const BlockCover& cover(int block) const { return covers_[block]; }
	const BlockCover& coverAt(int block) const { return covers_.at(block); }
	const Frame& frame(int block) const { return frames_[block]; }
	const std::vector<Frame>& frames() const { return frames_; }
	// Per flat shell: its box (not widened) [m], its extent in its block's
	// frame [m], its block, its block's fixed flag.
	const std::vector<Eigen::AlignedBox3d>& boxes() const { return boxes_; }
	const std::vector<Vector3>& extentLow() const { return extentLow_; }
	const std::vector<Vector3>& extentHigh() const { return extentHigh_; }
	const std::vector<int>& shellBlock() const { return shellBlock_; }
	const std::vector<char>& shellFixed() const { return shellFixed_; }
	// The linked shells of a block's vertices, then edges, then faces.
	const ShellRange* subUnitShells(int block) const { return shellRanges_.data() + covers_[block].firstSubUnit; }
	// The block's linked-set chain head (in its frame) and set count (in its
	// cover), which LinkedSets keeps.
	int& linkedSetChain(int block) { return frames_[block].linkedSets; }
	int& linkedSetCount(int block) { return covers_[block].linkedSetCount; }
	// Every block's chain emptied and count zeroed (LinkedSets cleared).
	void forgetLinkedSets();

	long totalShellUpdates() const { return totalShellUpdates_; }
	long coverBuilds() const { return coverBuilds_; }

	// Saving (MultiShellCoverState.cpp: the file layout, kept since covers were first saved).
	void write(StateWriter& out) const;
	// Reads into a fresh cover and lays its shells out; the boxes of blocks
	// whose shells were built while fixed are computed again.
	void read(StateReader& in, const std::vector<Block>& blocks);
	std::size_t memoryBytes() const;

private:
	// The covers to build, with their parameters, in block order.
	std::vector<std::pair<int, CoverParameters>> coversToBuild(const std::vector<Block>& blocks) const;
	// Appends the block's cover to shellRanges and divisions (divisionStart:
	// one entry per shell).
	void buildCover(const Block& block, const CoverParameters& parameters, BlockCover& cover,
	                std::vector<ShellRange>& shellRanges, std::vector<DivisionPoint>& divisions,
	                std::vector<int>& divisionStart) const;
	// Appends a kept cover's parts, moved from the current arrays.
	void copyCover(BlockCover& cover, std::vector<ShellRange>& shellRanges, std::vector<DivisionPoint>& divisions,
	               std::vector<int>& divisionStart) const;
	// Takes new flat parts (their two end entries added) and lays the shells out.
	void adopt(std::vector<ShellRange>& shellRanges, std::vector<DivisionPoint>& divisions,
	           std::vector<int>& divisionStart);
	// Lays the covers' shells out in the flat arrays (after covers changed).
	void layoutShells();
	// Sets cover.frameCorners from its frame faces in `shape`.
	static void copyFrameCorners(const PolyhedronTopology& shape, BlockCover& cover);
	// The block's frame for this step, from its cover's frame faces.
	void updateFrame(const Block& block, const BlockCover& cover, Frame& frame) const;
	int updateBoxes(const Block& block, BlockCover& cover, Frame& frame);  // returns the shells updated
	// Reading (MultiShellCoverState.cpp): one block's cover, and the check
	// and conversion of its per-shell lists to the compact form.
	void readCover(StateReader& in, const Block& block, int b, BlockCover& c, bool& boxesBuilt);
	void adoptShellLists(StateReader& in, int b, BlockCover& c, const std::vector<std::vector<int>>& corners,
	                     const std::vector<std::vector<DivisionPoint>>& divisions, const std::vector<std::uint64_t> (&linked)[3]);

	double criticalLengthFactor_;
	double criticalLength_ = 0;
	int segments_;
	std::map<int, CoverParameters> overrides_;
	bool coverChanged_ = false;
	std::vector<BlockCover> covers_;
	// The covers' parts, block after block. Per sub-unit its linked shells.
	// Per flat shell, divisionStart_ is where the division points on its
	// lower plane start in divisions_ (none on a block's first shell's);
	// a shell's points are its corners (the vertices linked to it) and
	// divisions_[divisionStart_[s], divisionStart_[s + 2]): the points on its
	// lower plane, then on its upper one (kept once per plane; two end entries).
	std::vector<ShellRange> shellRanges_;
	std::vector<DivisionPoint> divisions_;
	std::vector<int> divisionStart_;
	std::vector<Frame> frames_;                    // per block
	std::vector<Eigen::AlignedBox3d> boxes_;       // per flat shell, not widened
	std::vector<Vector3> extentLow_, extentHigh_;  // per flat shell, in its block's frame [m]
	std::vector<int> shellBlock_;                  // per flat shell
	std::vector<char> shellFixed_;  // per flat shell, its block's fixed flag (set as boxes are updated)
	long totalShellUpdates_ = 0;
	long coverBuilds_ = 0;
};

}  // namespace msc
}  // namespace dda
