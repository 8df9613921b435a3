// The broad phase of contact detection: which block pairs may be within the
// contact distance. Colliders only propose pairs; the narrow phase
// (contact/PairDetection.hpp) decides, and the ContactStore keeps history.
// Every strategy must return a superset of the pairs within the contact
// distance; AllPairsCollider, which returns every pair, is the oracle the
// others are tested against.
#pragma once

#include "dda/block/Block.hpp"
#include "dda/core/CapacityBytes.hpp"
#include "dda/geometry/SubUnits.hpp"

#include <Eigen/Geometry>

#include <cstdint>
#include <utility>
#include <vector>

namespace dda {

class StateWriter;
class StateReader;

// Bounding volumes are widened by this x the contact distance d0 on every
// side, so two volumes meet whenever the blocks are within 2 d0. The narrow
// phase accepts a corner within d0 of a face's plane whose projection falls
// within d0 of the face, i.e. a corner up to sqrt(2) d0 from the other block:
// half of d0 per side would miss those pairs (the collider test caught it).
constexpr double kBroadPhaseMarginFactor = 1.0;

// Counters of one findPairs call (they describe that call only).
struct BroadPhaseStatistics {
	long candidatePairs = 0;  // block pairs handed to the narrow phase
	long shellPairs = 0;      // overlapping bounding-volume pairs found (MSC: shell pairs, as boxes and in frames)
	long shellTests = 0;      // bounding-volume comparisons made (cached pairs re-checked and MSC's frame tests included)
	long shells = 0;          // bounding volumes (DESS, NBS: one per block; AllPairs: none)
	long shellUpdates = 0;    // bounding volumes recomputed from corners this call
	// The narrow phase's "sub-unit loops" (Wu et al. 2014, Sec. 4.2): over the
	// candidate pairs (a, b), Va x Fb + Vb x Fa + Ea x Eb, with V, E, F the
	// vertices, edges and faces each block offers the pair (MSC: the linked
	// sub-units of the overlapping shells; other strategies: all of them).
	long subUnitPairs = 0;
	// Candidate-pair reuse (DESS's and MSC's Verlet caches; 0 for other strategies).
	long broadPhaseSkipped = 0;  // 1 when no sort-and-sweep was made this call (pairs from the cache)
	long pairsReused = 0;        // cached pairs re-checked instead of searched for
	long blocksResearched = 0;   // blocks searched against the others this call (all of them on a full search)
};

class Collider {
public:
	virtual ~Collider() = default;
	virtual const char* name() const = 0;
	// Candidate pairs (a, b), a < b, never both fixed, in increasing order of
	// (a, b) (so that results do not depend on the strategy's internals).
	virtual void findPairs(const std::vector<Block>& blocks, double contactDistance,
	                       std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) = 0;
	// The sub-units linked to candidate pair pairIndex of the last findPairs
	// (its index in `pairs`), or nullptr: strategies without sub-block volumes
	// link every sub-unit. Valid until the next findPairs.
	virtual const LinkedSubUnits* linked(int /*pairIndex*/) const { return nullptr; }
	// Saving: state kept from call to call that changes later results (MSC's
	// covers); caches rebuilt identically from the blocks need not be saved.
	// readState gets the restored blocks (StateError on bad data).
	virtual void writeState(StateWriter& /*out*/) const {}
	virtual void readState(StateReader& /*in*/, const std::vector<Block>& /*blocks*/) {}
	// Whether the strategy may reuse candidates of earlier calls (strategies
	// without a cache ignore it). The pairs returned never depend on it.
	virtual void setPairReuse(bool /*reuse*/) {}
	// Heap bytes the strategy holds between calls (its arrays' capacities:
	// boxes, shells, grid, caches, linked lists) [bytes], for stats().
	virtual std::size_t memoryBytes() const { return 0; }
};

// Every pair of blocks that are not both fixed: O(n^2), the reference.
class AllPairsCollider : public Collider {
public:
	const char* name() const override { return "AllPairs"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;
};

// Double-ended spatial sorting (Perkins & Williams): one axis-aligned box per
// block, widened by kBroadPhaseMarginFactor x d0 on every side; the box ends
// are sorted along the axis of largest spread and swept, pairs overlapping
// there are checked on the other two axes.
// O(n log n + pairs) per step.
//
// Verlet cache (on unless setPairReuse(false)): a search sweeps boxes widened
// by D = d0 (1 + kVerletSkinFactor) and keeps every pair whose widened boxes
// meet, and each block's tight box B_b then. A block's D-box contains its
// d0-box of a later step as long as its tight box stays inside B_b widened by
// D - d0 (minus a round-off slack), so while that holds for both blocks of a
// pair whose d0-boxes meet now, the pair is in the cache. Each call therefore
// (1) computes the tight boxes, (2) re-searches only the blocks that left
// their allowance, against every block's D-box (a full sort-and-sweep instead
// when more than kVerletPartialFactor x log2(n) blocks left), and (3) returns
// the cached pairs whose d0-boxes meet now, with the same floating-point
// test as a search without cache. The pairs returned are therefore exactly
// those of a search without cache, in the same order; only the work differs.
// Blocks at rest are not searched again until something moves past its
// allowance.
class DESSCollider : public Collider {
public:
	// Skin of the Verlet cache, x d0 [-]: a block may move this far (per
	// coordinate of its box) before it is searched again.
	static constexpr double kVerletSkinFactor = 1.0;
	// Blocks re-searched one by one (O(n) each) when at most this x log2(n)
	// left their allowance; else a full sort-and-sweep.
	static constexpr double kVerletPartialFactor = 4.0;
	const char* name() const override { return "DESS"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;
	void setPairReuse(bool reuse) override;
	std::size_t memoryBytes() const override {
		return capacityBytes(boxes_) + capacityBytes(order_) + capacityBytes(fixed_) + capacityBytes(searchedBoxes_) + capacityBytes(cached_) +
		       capacityBytes(kept_) + capacityBytes(searchedFixed_) + capacityBytes(moved_) + capacityBytes(movers_);
	}

private:
	// Sort-and-sweep of `boxes` (pairs not both fixed) into `pairs`, sorted;
	// returns the box comparisons made.
	long sweep(const std::vector<Block>& blocks, const std::vector<Eigen::AlignedBox3d>& boxes,
	           std::vector<std::pair<int, int>>& pairs);
	std::vector<Eigen::AlignedBox3d> boxes_;  // this call's boxes, widened by d0
	std::vector<int> order_;
	std::vector<char> fixed_;  // per block, for the sweep
	bool reuse_ = true;
	// The cache: each block's D-box from when it was last searched, every
	// pair (not both fixed) whose D-boxes meet, sorted, and the fixed flags.
	bool cacheValid_ = false;
	std::vector<Eigen::AlignedBox3d> searchedBoxes_;
	std::vector<std::pair<int, int>> cached_, kept_;
	std::vector<char> searchedFixed_, moved_;
	std::vector<int> movers_;
};

// No binary search (Munjiza & Andrews): one bounding sphere per block (centre
// the box centre of its corners, radius to the farthest corner, plus
// kBroadPhaseMarginFactor x d0); spheres are binned by centre into cubic cells as large
// as the largest diameter, so overlapping spheres sit in the same or adjacent
// cells, and only those are compared. O(n) for blocks of similar size; a few
// large blocks make the cells coarse (the method's known weakness).
class NBSCollider : public Collider {
public:
	const char* name() const override { return "NBS"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;
	std::size_t memoryBytes() const override {
		return capacityBytes(centres_) + capacityBytes(radii_) + capacityBytes(cellOf_);
	}

private:
	std::vector<Vector3> centres_;
	std::vector<double> radii_;
	std::vector<std::pair<std::uint64_t, int>> cellOf_;  // (cell key, block), sorted
};

}  // namespace dda
