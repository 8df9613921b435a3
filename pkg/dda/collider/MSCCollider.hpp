// Multi-shell cover (Wu et al. 2014, Sec. 4), a robust variant. A block whose
// longest edge exceeds the critical length lambda is cut across its main axis
// (largest principal axis of its corners) into N equal slabs; each slab's slice
// of the block gets one axis-aligned box, its *shell*: the box of the corners
// in the slab and of the points where edges cross the slab's planes (the
// paper's division points). Slices tile the block, so shells cover any convex
// block exactly. Built once per block: division points as (edge, fraction),
// and per vertex, edge and face the shells whose closed slab it touches (its
// linked shells). DDA moves blocks by affine maps, which keep fractions and
// slab membership: the cover moves with the block, and each step only moving
// blocks' boxes are recomputed. Shells widened by d0 are entered in the
// cells of a uniform grid (the paper's subspaces) and compared within cells;
// a pair is a candidate when two of its shells overlap. Where the paper lets the
// nearest shell decide, a pair here links the union of its overlapping shells'
// sub-units, each once: every feature of its contacts while penetration stays
// below d0 / 2 (argued in the .cpp). The narrow phase (detectPairContacts with
// the linked sets) loops over those only and searches a deeper pair again
// with every sub-unit, so its contacts are exactly the full search's.
#pragma once

#include "Collider.hpp"

#include <Eigen/Geometry>

#include <cstdint>
#include <map>
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

	// criticalLengthFactor > 0 [-], segments in [1, kMaxSegments]; InputError otherwise.
	explicit MSCCollider(double criticalLengthFactor = kDefaultCriticalLengthFactor,
	                     int segments = kDefaultSegments);

	const char* name() const override { return "MSC"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;
	const LinkedSubUnits* linked(int pairIndex) const override;

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

	// Saving (MSCColliderState.cpp): parameters, overrides and every block's
	// cover as built (a cover is built from the block's geometry at that
	// time, so rebuilding it later would give other slabs).
	void writeState(StateWriter& out) const override;
	void readState(StateReader& in, const std::vector<Block>& blocks) override;

private:
	struct DivisionPoint {
		int edge;
		double fraction;  // point = start + fraction x (end - start), in [0, 1]
	};
	struct Shell {
		std::vector<int> corners;             // vertices inside the slab
		std::vector<DivisionPoint> divisions;  // edges crossing the slab's planes
	};
	struct BlockCover {
		const ConvexPolyhedron* shape = nullptr;  // the cover is rebuilt when it changes
		double criticalLength = 0;                // [m], as built
		int segments = 0;                         // as asked (used when the block is long)
		int shellCount = 0;
		int firstShell = 0;  // into the flat shell arrays
		double widening = 0;  // [m]: kShellWideningRelative x diagonal
		bool boxesBuilt = false;
		std::vector<Shell> shells;
		// Bit s: linked to shell s (touches its slab).
		std::vector<std::uint64_t> vertexShells, edgeShells, faceShells;
	};
	struct Override {
		double criticalLength;
		int segments;
	};
	// One overlapping shell pair, as the block pair (a < b) and the shells of each.
	struct ShellHit {
		int a, b;
		std::uint64_t shellsA, shellsB;
		bool operator<(const ShellHit& o) const { return a < o.a || (a == o.a && b < o.b); }
	};

	void buildCover(const Block& block, double criticalLength, int segments, BlockCover& cover) const;
	void updateBoxes(const Block& block, BlockCover& cover);
	static void collect(const std::vector<std::uint64_t>& linkedShells, std::uint64_t shells, std::vector<int>& out);

	double criticalLengthFactor_;
	double criticalLength_ = 0;
	int segments_;
	std::map<int, Override> overrides_;
	bool coverChanged_ = false;
	std::vector<BlockCover> covers_;
	std::vector<Eigen::AlignedBox3d> boxes_;  // per flat shell, not widened
	std::vector<int> shellBlock_, shellIndex_;  // per flat shell
	std::vector<Eigen::AlignedBox3d> widened_;
	std::vector<std::pair<std::uint64_t, int>> cellEntries_;  // (cell key, shell), sorted
	std::vector<int> oversize_;   // shells compared with every shell
	std::vector<char> isOversize_;
	std::vector<ShellHit> hits_;
	std::vector<LinkedSubUnits> linked_;  // pool: the first linkedCount_ are valid
	int linkedCount_ = 0;
	long totalShellUpdates_ = 0;
	long coverBuilds_ = 0;
};

}  // namespace dda
