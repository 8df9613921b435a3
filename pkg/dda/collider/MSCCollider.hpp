// Multi-shell cover (Wu et al. 2014, Sec. 4), a robust variant. A block whose
// longest edge exceeds the critical length lambda is cut across its main axis
// (largest principal axis of its corners) into N equal slabs; each slab's slice
// of the block gets one axis-aligned box, its *shell*: the box of the corners
// in the slab and of the points where edges cross the slab's planes (the
// paper's division points). Slices tile the block, so shells cover any convex
// block exactly. Built once per block: per vertex, edge and face the shells
// whose closed slab it touches (its linked shells: consecutive slabs, kept as
// a range), and per inner plane its division points as (edge, fraction),
// kept once for the two slabs it bounds (a shell's corners are the vertices
// linked to it). DDA moves blocks by affine maps, which keep fractions and
// slab membership: the cover moves with the block, and each step only moving
// blocks' boxes are recomputed. Shells widened by d0 are entered in the
// cells of a uniform grid (the paper's subspaces) and compared within cells.
//
// Two shells whose boxes overlap are then compared along the block's own
// axes: each block has a frame of three of its face normals (chosen once,
// the first across the main axis; a box's frame is its edges' directions),
// and each shell its extent along them (the slab of a box is exactly its
// extent box there). Two shells apart by more than the boxes' widening along
// an axis of either frame do not overlap, whatever the boxes say: a slender
// block turned 45 degrees has boxes far larger than its slabs. A pair is a
// candidate when two of its shells overlap in both tests. Where the paper lets
// the nearest shell decide, a pair here links the union of its overlapping
// shells' sub-units, each once (lists built once per block and shell set,
// shared by the pairs, and kept once per content: blocks of one topology
// share them): every feature of its contacts while penetration stays
// below d0 / 2 (argued in the .cpp). The narrow phase (detectPairContacts with
// the linked sets) loops over those only and searches a deeper pair again
// with every sub-unit, so its contacts are exactly the full search's.
//
// Shell-pair cache (on unless setPairReuse(false)), as DESS's: the grid is
// searched with boxes widened by D = d0 (1 + kVerletSkinFactor), and every
// shell pair whose D-boxes meet is kept with the D-boxes; a block whose
// d0-boxes all lie in their D-boxes needs no search, the others are compared
// with every shell (a full grid search when more than kVerletPartialFactor x
// log2(n) blocks moved). The shell pairs then tested are the cached ones whose
// d0-boxes meet, on the same floats as without cache: the pairs, linked sets
// and their order never depend on the cache.
#pragma once

#include "Collider.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

namespace dda {

class MSCCollider : public Collider {
public:
	// Default critical length: this x the block's size (cube root of its
	// volume) [-]. A 3:1:1 box stays one shell, a 5:1:1 box gets N.
	static constexpr double kDefaultCriticalLengthFactor = 3;
	// Default number of slabs of a long block [-] (the paper uses 2-3).
	static constexpr int kDefaultSegments = 3;
	// Most slabs per block (shell sets are 64-bit masks).
	static constexpr int kMaxSegments = 64;
	// Shells are widened, beyond kBroadPhaseMarginFactor x d0, by this x the
	// block's bounding-box diagonal [-]. Rule: the two widenings of a pair sum
	// to at least 2 x kDefaultRelativeLengthTolerance x the larger diagonal,
	// above the sqrt(2) x lengthTolerance by which the narrow phase reaches
	// past d0, and above the round-off of division points and of affine
	// motion (~1e-16 relative per step); 4e-8 of a 10 m block is 0.4 um.
	static constexpr double kShellWideningRelative = 4e-8;
	// Subspaces: at most this many cells per axis (cell keys are 3 x 21 bits)
	// and a shell spanning more cells than kMaxCellsPerShell is compared with
	// every shell rather than entered in each.
	static constexpr long kMaxCellsPerAxis = 1 << 20;
	static constexpr long kMaxCellsPerShell = 64;
	// The grid's cells are keyed by their index (and sorted by counting) when
	// there are at most this x the entries plus kDenseCellsFloor cells.
	static constexpr double kDenseCellsPerEntry = 4;
	static constexpr double kDenseCellsFloor = 4096;
	// A frame is used when its three unit face normals span at least this
	// volume (|det|, 1 for orthogonal ones) when chosen, and half of it at each
	// step (a strained block); else the coordinate axes are its frame [-].
	static constexpr double kMinFrameDeterminant = 0.5;
	// The frame test's own round-off: this x the lengths it is computed from
	// [-] is added to the widening (~1e-14 is the bound with the frames above).
	static constexpr double kFrameRoundoffRelative = 1e-12;
	// Shell-pair cache, as DESSCollider's: skin x d0, and the most blocks
	// (x log2(n)) re-searched one by one instead of a full grid search.
	static constexpr double kVerletSkinFactor = 1.0;
	static constexpr double kVerletPartialFactor = 4.0;
	// Linked sets kept per block (one per shell set met); when a block has
	// more, every block's are dropped at the next call.
	static constexpr std::size_t kMaxLinkedSetsPerBlock = 64;

	// criticalLengthFactor > 0 [-], segments in [1, kMaxSegments]; InputError otherwise.
	explicit MSCCollider(double criticalLengthFactor = kDefaultCriticalLengthFactor,
	                     int segments = kDefaultSegments);

	const char* name() const override { return "MSC"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;
	const LinkedSubUnits* linked(int pairIndex) const override;
	void setPairReuse(bool reuse) override;
	std::size_t memoryBytes() const override;

	// The scene's cover (what yade_dda's MSCCollider engine sets): critical
	// length [m] >= 0, 0 = criticalLengthFactor x each block's size; segments
	// in [1, kMaxSegments]. InputError otherwise; taken at the next findPairs.
	void setCover(double criticalLength, int segments);
	// One block's own cover: critical length [m] > 0 and segments in
	// [1, kMaxSegments] (InputError otherwise); taken at the next findPairs.
	void setBlockCover(int block, double criticalLength, int segments);

	double criticalLengthFactor() const { return criticalLengthFactor_; }
	double criticalLength() const { return criticalLength_; }  // [m], 0 = by block size
	int segments() const { return segments_; }

	// After a findPairs: the shells of a block and their current boxes, not
	// widened [m] (diagnostics and tests).
	int shellCount(int block) const { return covers_.at(block).shellCount; }
	const Eigen::AlignedBox3d& shellBox(int block, int shell) const;
	// Shell boxes computed from corners since construction (fixed blocks'
	// once per topology build, moving blocks' every call).
	long totalShellUpdates() const { return totalShellUpdates_; }
	// Topology builds (block covers) since construction.
	long coverBuilds() const { return coverBuilds_; }

	// Whether the last grid search keyed its cells densely (counting sort)
	// or by packed coordinates (a sparse domain; diagnostics and tests).
	bool denseGrid() const { return denseGrid_; }

	// The faces whose normals make a block's frame, or -1s (coordinate axes).
	const std::array<int, 3>& frameFaces(int block) const { return covers_.at(block).frameFaces; }

	// Saving (MSCColliderState.cpp): parameters, overrides and every block's
	// cover as built (a cover is built from the block's geometry at that
	// time, so rebuilding it later would give other slabs). Boxes, frames and
	// the cache are recomputed from the blocks (fixed blocks have not moved).
	void writeState(StateWriter& out) const override;
	void readState(StateReader& in, const std::vector<Block>& blocks) override;

private:
	// A sub-unit's linked shells: slabs first..last (an interval's slabs are
	// consecutive), none when first > last.
	struct ShellRange {
		std::uint8_t first = 1, last = 0;
		// The range of a mask of consecutive slabs.
		static ShellRange of(std::uint64_t mask) {
			ShellRange r;
			for (int j = 0; j < kMaxSegments; ++j)
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
		int linkedSetCount = 0;  // its sets in linkedSets_ (the chain starts in its frame)
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
	// The sub-units linked to a set of a block's shells: indices into lists_
	// of its vertices, edges and faces.
	struct LinkedSet {
		std::uint64_t shells;
		int next;  // the block's next set in its chain, -1: none
		std::array<int, 3> lists;
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
		// The block's linked sets in linkedSets_, most recently used first (a
		// chain through next), -1: none. Kept from call to call, unlike the
		// rest, and read with the frame for the same cache lines.
		int linkedSets = -1;
		Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
	};
	struct Override {
		double criticalLength;
		int segments;
	};
	// A shell pair (flat indices): s of the pair's first block, t of the second.
	struct ShellPair {
		int s, t;
	};

	// Appends the block's cover to shellRanges and divisions (divisionStart:
	// one entry per shell).
	void buildCover(const Block& block, double criticalLength, int segments, BlockCover& cover,
	                std::vector<ShellRange>& shellRanges, std::vector<DivisionPoint>& divisions,
	                std::vector<int>& divisionStart) const;
	// Lays the covers' shells out in the flat arrays (after covers changed).
	void layoutShells();
	// Sets cover.frameCorners from its frame faces in `shape`.
	static void copyFrameCorners(const PolyhedronTopology& shape, BlockCover& cover);
	void updateBoxes(const Block& block, BlockCover& cover, Frame& frame);
	// Grid search: every shell pair (different blocks, not both fixed as
	// shellFixed_ says) whose `boxes` meet, into `out` (unsorted); returns
	// the box comparisons made.
	long gridSearch(const std::vector<Eigen::AlignedBox3d>& boxes, std::vector<ShellPair>& out);
	// Whether shells s of block a and t of block b are apart by more than
	// `limit` [m] along an axis of a's frame (m = a.axes x b.dual, size = |m|
	// elementwise, offset = a.axes x (b.origin - a.origin)).
	bool apartInFrame(int s, int t, const Eigen::Matrix3d& m, const Eigen::Matrix3d& size, const Vector3& offset,
	                  double limit) const;
	// Sorts shell pairs by first block, then (t, s): by block pair
	// (`scratch`: work space, its contents lost).
	void sortShellPairs(std::vector<ShellPair>& pairs, int blocks, std::vector<ShellPair>& scratch);
	// Index into linkedSets_ of the block's set for `shells` (built when new).
	int linkedSet(int block, std::uint64_t shells);
	// Index into lists_ of a list equal to `list` (added when new).
	int internList(const std::vector<int>& list);
	void clearLinkedSets();

	double criticalLengthFactor_;
	double criticalLength_ = 0;
	int segments_;
	std::map<int, Override> overrides_;
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
	std::vector<Frame> frames_;               // per block
	std::vector<Eigen::AlignedBox3d> boxes_;  // per flat shell, not widened
	std::vector<Vector3> extentLow_, extentHigh_;  // per flat shell, in its block's frame [m]
	std::vector<int> shellBlock_;                  // per flat shell
	std::vector<Eigen::AlignedBox3d> widened_;
	using Cell = Eigen::Array<int, 3, 1>;   // a subspace's integer coordinates
	// Per flat shell the cells its box spans: from cellLow_ on, span more per
	// axis (at most kMaxCellsPerShell - 1), unless it is oversize.
	struct CellSpan {
		std::uint8_t x, y, z;
		bool oversize;
	};
	std::vector<Cell> cellLow_;
	std::vector<CellSpan> cellSpan_;
	// A cell's entry as its pairs are compared (gridSearch).
	struct CellEntry {
		Vector3 low, high;  // the shell's box
		int shell, block;
		bool fixed;
		std::uint8_t bits;  // bits 0-2 of its entry
	};
	std::vector<std::pair<std::uint64_t, std::uint32_t>> cellEntries_;  // sparse keys: (cell key, entry), sorted
	// Every cell's entries, cell after cell: shell << 3 | the axes along
	// which the cell is the shell's lowest (bit 0: x, 1: y, 2: z).
	std::vector<std::uint32_t> cellShells_;
	std::vector<CellEntry> cellScratch_;      // one cell's entries (gridSearch)
	std::vector<std::uint32_t> cellStart_;    // dense keys: where each cell's shells start
	bool denseGrid_ = false;
	std::vector<int> oversize_;   // shells compared with every shell
	std::vector<char> shellFixed_;  // per flat shell, its block's fixed flag (set as boxes are updated)
	std::vector<std::size_t> pairStart_;  // sortShellPairs' buckets
	std::vector<ShellPair> hits_;  // the shell pairs whose d0-boxes meet, sorted
	// Per candidate its two linked sets, until linked_ is filled.
	std::vector<std::array<int, 2>> candidateSets_;
	std::vector<LinkedSubUnits> linked_;  // the first linkedCount_ are valid
	int linkedCount_ = 0;
	// Linked sets of every block, and the distinct sub-unit lists they use
	// (blocks of one topology share them), found by hashing their contents
	// (listTable_: open addressing, -1 = free).
	std::vector<LinkedSet> linkedSets_;
	std::vector<std::vector<int>> lists_;
	std::vector<int> listTable_, listScratch_;
	bool linkedSetsOverflow_ = false;  // a block has more than kMaxLinkedSetsPerBlock
	long totalShellUpdates_ = 0;
	long coverBuilds_ = 0;
	// The cache: each shell's D-box from its block's last search, every shell
	// pair whose D-boxes meet (sorted), and the fixed flags then.
	bool reuse_ = true;
	bool cacheValid_ = false;
	std::vector<Eigen::AlignedBox3d> searchBoxes_;
	std::vector<ShellPair> cached_, kept_;
	std::vector<char> searchedFixed_, moved_;
	std::vector<int> movers_;
};

}  // namespace dda
