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
// Shell-pair cache (PairCache.hpp, DESS's too; on unless setPairReuse(false)):
// the grid is searched with boxes widened by D = d0 (1 +
// PairCache::kVerletSkinFactor), and every shell pair whose D-boxes meet is
// kept; a block whose d0-boxes all lie in their D-boxes needs no search, the
// others are compared with every shell. The shell pairs then tested are the
// cached ones whose d0-boxes meet, on the same floats as without cache: the
// pairs, linked sets and their order never depend on the cache.
//
// The parts, one a file: MultiShellCover (the covers, the shells' boxes,
// extents and frames; MultiShellCoverState.cpp saves them), ShellGrid (the
// subspaces), FrameTest, LinkedSets, and PairCache; MSCCollider.cpp runs them.
#pragma once

#include "Collider.hpp"
#include "LinkedSets.hpp"
#include "MultiShellCover.hpp"
#include "PairCache.hpp"
#include "ShellGrid.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace dda {

// Its constants live with the part that uses them: kShellWideningRelative and
// kMinFrameDeterminant (MultiShellCover.hpp), the grid's (ShellGrid.hpp),
// kFrameRoundoffRelative (FrameTest.hpp), kMaxLinkedSetsPerBlock
// (LinkedSets.hpp), the cache's (PairCache.hpp).
class MSCCollider : public Collider {
public:
	// Default critical length: this x the block's size (cube root of its
	// volume) [-]. A 3:1:1 box stays one shell, a 5:1:1 box gets N.
	static constexpr double kDefaultCriticalLengthFactor = 3;
	// Default number of slabs of a long block [-] (the paper uses 2-3).
	static constexpr int kDefaultSegments = 3;
	// Most slabs per block (Collider.hpp's kMaxCoverSegments).
	static constexpr int kMaxSegments = kMaxCoverSegments;

	// criticalLengthFactor > 0 [-], segments in [1, kMaxSegments]; InputError otherwise.
	explicit MSCCollider(double criticalLengthFactor = kDefaultCriticalLengthFactor,
	                     int segments = kDefaultSegments)
	    : cover_(criticalLengthFactor, segments) {}

	const char* name() const override { return "MSC"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;
	const LinkedSubUnits* linked(int pairIndex) const override;
	void setPairReuse(bool reuse) override { cache_.setReuse(reuse); }
	std::size_t memoryBytes() const override;

	// The scene's cover (what yade_dda's MSCCollider engine sets): critical
	// length [m] >= 0, 0 = criticalLengthFactor x each block's size; segments
	// in [1, kMaxSegments]. InputError otherwise; taken at the next findPairs.
	void setCover(double criticalLength, int segments) override { cover_.setCover(criticalLength, segments); }
	// One block's own cover: critical length [m] > 0 and segments in
	// [1, kMaxSegments] (InputError otherwise); taken at the next findPairs.
	void setBlockCover(int block, double criticalLength, int segments) {
		cover_.setBlockCover(block, criticalLength, segments);
	}

	double criticalLengthFactor() const { return cover_.criticalLengthFactor(); }
	double criticalLength() const { return cover_.criticalLength(); }  // [m], 0 = by block size
	int segments() const { return cover_.segments(); }

	// After a findPairs: the shells of a block and their current boxes, not
	// widened [m] (diagnostics and tests).
	int shellCount(int block) const { return cover_.coverAt(block).shellCount; }
	const Eigen::AlignedBox3d& shellBox(int block, int shell) const;
	// Shell boxes computed from corners since construction (fixed blocks'
	// once per topology build, moving blocks' every call).
	long totalShellUpdates() const { return cover_.totalShellUpdates(); }
	// Topology builds (block covers) since construction.
	long coverBuilds() const { return cover_.coverBuilds(); }

	// Whether the last grid search keyed its cells densely (counting sort)
	// or by packed coordinates (a sparse domain; diagnostics and tests).
	bool denseGrid() const { return grid_.dense(); }

	// The faces whose normals make a block's frame, or -1s (coordinate axes).
	const std::array<int, 3>& frameFaces(int block) const { return cover_.coverAt(block).frameFaces; }

	// Saving (MultiShellCoverState.cpp): parameters, overrides and every block's
	// cover as built (a cover is built from the block's geometry at that
	// time, so rebuilding it later would give other slabs). Boxes, frames and
	// the cache are recomputed from the blocks (fixed blocks have not moved).
	void writeState(StateWriter& out) const override;
	void readState(StateReader& in, const std::vector<Block>& blocks) override;

private:
	struct Volumes;  // what the pair cache sees of it (MSCCollider.cpp)
	// The shell pairs whose d0-boxes meet, sorted, into hits_ (from the
	// cache, or a grid search without it).
	void findShellHits(const std::vector<Block>& blocks, double margin, BroadPhaseStatistics& stats);
	// Per block pair of hits_: the shell pairs that also pass the frame test;
	// a pair with any is a candidate, with the linked sets of its shells.
	void testBlockPairs(double margin, std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats);
	// linked_ from the candidates' linked sets.
	void fillLinked(std::size_t candidates, BroadPhaseStatistics& stats);
	// The items k < count with keep(k), in order, into out as make(k) (on the
	// step's threads, the same for any number of them: MSCCollider.cpp).
	template <class T, class Keep, class Make>
	void orderedSelect(std::size_t count, std::vector<T>& out, const Keep& keep, const Make& make);
	// Sorts shell pairs by first block, then (t, s): by block pair
	// (`scratch`: work space, its contents lost).
	void sortShellPairs(std::vector<ItemPair>& pairs, int blocks, std::vector<ItemPair>& scratch);
	// Index of the block's linked set for `shells` (built when new).
	int linkedSet(int block, std::uint64_t shells);
	void clearLinkedSets();

	msc::MultiShellCover cover_;
	msc::ShellGrid grid_;
	msc::LinkedSets linkedSets_;
	PairCache cache_{PairCache::Growth::Eighths};
	std::vector<Eigen::AlignedBox3d> widened_;  // per flat shell, widened by d0 and its cover's widening
	std::vector<std::size_t> pairStart_;        // sortShellPairs' buckets
	std::vector<ItemPair> hits_;                // the shell pairs whose d0-boxes meet, sorted
	// Per candidate its two linked sets, until linked_ is filled.
	std::vector<std::array<int, 2>> candidateSets_;
	std::vector<std::size_t> groupStart_;                               // testBlockPairs: runs of hits_ per block pair
	std::vector<std::pair<std::uint64_t, std::uint64_t>> groupShells_;  // and their near shells (bit masks)
	std::vector<std::pair<int, int>> groupSets_;  // and those shells' linked sets when they had one, else -1
	std::vector<char> selectKept_;                // orderedSelect: per item, whether it is kept
	std::vector<std::size_t> segmentStart_;       // and where each segment's kept items start
	std::vector<LinkedSubUnits> linked_;  // the first linkedCount_ are valid
	int linkedCount_ = 0;
};

}  // namespace dda
