// The broad phase of contact detection: which block pairs may be within the
// contact distance. Colliders only propose pairs; the narrow phase
// (contact/PairDetection.hpp) decides, and the ContactStore keeps history.
// Every strategy must return a superset of the pairs within the contact
// distance; AllPairsCollider, which returns every pair, is the oracle the
// others are tested against.
#pragma once

#include "dda/block/Block.hpp"
#include "dda/contact/SubUnits.hpp"

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
	long shellPairs = 0;      // overlapping bounding-volume pairs found (MSC: shell pairs)
	long shellTests = 0;      // bounding-volume comparisons made
	long shells = 0;          // bounding volumes (DESS, NBS: one per block; AllPairs: none)
	long shellUpdates = 0;    // bounding volumes recomputed from corners this call
	// The narrow phase's "sub-unit loops" (Wu et al. 2014, Sec. 4.2): over the
	// candidate pairs (a, b), Va x Fb + Vb x Fa + Ea x Eb, with V, E, F the
	// vertices, edges and faces each block offers the pair (MSC: the linked
	// sub-units of the overlapping shells; other strategies: all of them).
	long subUnitPairs = 0;
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
class DESSCollider : public Collider {
public:
	const char* name() const override { return "DESS"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;

private:
	std::vector<Eigen::AlignedBox3d> boxes_;
	std::vector<int> order_;
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

private:
	std::vector<Vector3> centres_;
	std::vector<double> radii_;
	std::vector<std::pair<std::uint64_t, int>> cellOf_;  // (cell key, block), sorted
};

}  // namespace dda
