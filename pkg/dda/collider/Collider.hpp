// The broad phase of contact detection: which block pairs may be within the
// contact distance. Colliders only propose pairs; the narrow phase
// (contact/PairDetection.hpp) decides, and the ContactStore keeps history.
// Every strategy must return a superset of the pairs within the contact
// distance; AllPairsCollider, which returns every pair, is the oracle the
// others are tested against.
#pragma once

#include "BroadPhaseStatistics.hpp"
#include "PairCache.hpp"

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

// Most slabs per block of a multi-shell cover (MSCCollider.hpp; its shell
// sets are 64-bit masks) [-].
constexpr int kMaxCoverSegments = 64;

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
	// The scene's multi-shell cover (MSCCollider.hpp): critical length [m]
	// >= 0, 0 = by each block's size, and segments in [1, kMaxCoverSegments].
	// Strategies without a cover raise InputError (the binding calls this
	// without knowing the strategy).
	virtual void setCover(double criticalLength, int segments);
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
// Pair cache (PairCache.hpp, on unless setPairReuse(false)): the sweep is
// made with boxes widened by D = d0 (1 + PairCache::kVerletSkinFactor) and
// its pairs kept; each call re-searches only the blocks whose d0-box left
// their D-box (a full sort-and-sweep when many did) and returns the cached
// pairs whose d0-boxes meet now, with the same floating-point test as a
// search without cache. The pairs returned are therefore exactly those of a
// search without cache, in the same order; only the work differs. Blocks at
// rest are not searched again until something moves past its allowance.
class DESSCollider : public Collider {
public:
	const char* name() const override { return "DESS"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;
	void setPairReuse(bool reuse) override { cache_.setReuse(reuse); }
	std::size_t memoryBytes() const override {
		return capacityBytes(boxes_) + capacityBytes(order_) + capacityBytes(fixed_) + cache_.memoryBytes();
	}

private:
	struct Volumes;  // what the pair cache sees of it (DESSCollider.cpp)
	// Sort-and-sweep of `boxes` (pairs not both fixed) into `pairs`, sorted;
	// returns the box comparisons made.
	long sweep(const std::vector<Block>& blocks, const std::vector<Eigen::AlignedBox3d>& boxes,
	           std::vector<std::pair<int, int>>& pairs);
	std::vector<Eigen::AlignedBox3d> boxes_;  // this call's boxes, widened by d0
	std::vector<int> order_;
	std::vector<char> fixed_;  // per block, for the sweep
	PairCache cache_{PairCache::Growth::Doubling};
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
