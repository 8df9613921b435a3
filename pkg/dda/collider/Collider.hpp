// The broad phase of contact detection: which block pairs may be within the
// contact distance. Colliders only propose pairs; the narrow phase
// (contact/PairDetection.hpp) decides, and the ContactStore keeps history.
// Every strategy must return a superset of the pairs within the contact
// distance; AllPairsCollider, which returns every pair, is the oracle the
// others are tested against.
#pragma once

#include "dda/block/Block.hpp"

#include <Eigen/Geometry>

#include <utility>
#include <vector>

namespace dda {

struct BroadPhaseStatistics {
	long candidatePairs = 0;  // block pairs handed to the narrow phase
	long shellPairs = 0;      // bounding-volume pairs tested (strategy-specific)
};

class Collider {
public:
	virtual ~Collider() = default;
	virtual const char* name() const = 0;
	// Candidate pairs (a, b), a < b, never both fixed, in increasing order of
	// (a, b) (so that results do not depend on the strategy's internals).
	virtual void findPairs(const std::vector<Block>& blocks, double contactDistance,
	                       std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) = 0;
};

// Every pair of blocks that are not both fixed: O(n^2), the reference.
class AllPairsCollider : public Collider {
public:
	const char* name() const override { return "AllPairs"; }
	void findPairs(const std::vector<Block>& blocks, double contactDistance, std::vector<std::pair<int, int>>& pairs,
	               BroadPhaseStatistics& stats) override;
};

// Double-ended spatial sorting (Perkins & Williams): one axis-aligned box per
// block, widened by half the contact distance on every side so that two boxes
// overlap exactly when the blocks' boxes are within the contact distance on
// all three axes; the box ends are sorted along the axis of largest spread
// and swept, pairs overlapping there are checked on the other two axes.
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

}  // namespace dda
