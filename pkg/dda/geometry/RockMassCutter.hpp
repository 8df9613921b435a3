// cutRockMass: the blocks of a rock domain cut by joint sets, single joints
// and excavations (doc/rock-mass.md).
//
// The domain is one convex corner list or several convex parts (a concave
// domain given as its convex pieces); each part is cut on its own and its
// blocks carry its index. A block is a convex polytope held as the planes
// that bound it (ConvexCell.hpp): every decision (which side of a plane a
// corner lies on, whether a plane cuts a block) is an exact sign, and every
// corner is the exact intersection of three planes rounded toward zero, a
// function of the point alone, so neighbouring blocks share faces exactly
// (bitwise equal corners). Order of the cut:
//   1. each part: a box around the domain clipped by the part's face planes;
//   2. fully persistent planes, in the order of the joint list (a set's
//      planes in ascending offset along its pole), then those with
//      persistence < 1 in the same order. A plane cuts every block it
//      crosses, or, with persistence p < 1, each block it crosses with
//      probability p, drawn from the seed, the plane and the block's own
//      planes (keyed: independent of the order blocks are visited). A cut
//      always splits a whole convex block, so no block is ever concave: a
//      joint that stops stops at a block's face, never inside it;
//   3. excavations, in list order: a half-space removes the side its normal
//      points to, a convex region its inside (blocks crossing its boundary
//      are cut by its face planes, only they);
//   4. corners closer than 1e-12 x the domain's diagonal are made one
//      (CornerSnap, RockBlocks.hpp: round-off of the input, far below any
//      real feature);
//   5. blocks below minVolume, or whose corners buildConvexPolyhedron (hence
//      ddaBlock) would refuse, are merged into a neighbour they share a face
//      with, the largest shared face first, when the union is convex
//      (decided exactly); the others are returned as slivers, never dropped.
// Units: m, m^3; angles in degrees (RockPlanes.hpp for the conventions).
#pragma once

#include "dda/geometry/RockBlocks.hpp"
#include "dda/geometry/RockPlanes.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace dda::rockmass {

// A sliver below this fraction of the domain's volume when no minVolume is given.
inline constexpr double kDefaultSliverFraction = 1e-6;

struct CutOptions {
	std::uint64_t seed = 0;
	// Blocks below this volume [m^3] are merged or reported; < 0: kDefaultSliverFraction x the domain's volume.
	double minVolume = -1;
	// Also merge or report blocks whose corners buildConvexPolyhedron refuses.
	bool checkShapes = true;
};

struct CutStatistics {
	int planes = 0;            // planes of the cut (bounds, domain faces, joints, excavations)
	long cuts = 0;             // blocks split by a joint plane
	long skippedCuts = 0;      // crossings a non-persistent plane did not cut
	long classified = 0;       // (block, plane) pairs classified exactly
	long vertices = 0;         // distinct plane triples made
	long mergedSlivers = 0;
	long snappedCorners = 0;   // corners made one with a nearer one (RockBlocks.hpp)
	PredicateCounters predicates;
	double secondsPlanes = 0, secondsCut = 0, secondsExcavate = 0, secondsSlivers = 0, secondsOutput = 0;
};

struct RockMass {
	std::vector<RockBlock> blocks;
	std::vector<RockBlock> slivers;
	std::vector<PlaneRecord> planes;
	double domainVolume = 0;  // [m^3], of the parts (before excavation)
	double minVolume = 0;     // [m^3], as applied
	CutStatistics stats;
};

// Throws InputError naming the problem (a part that is not a convex block,
// parts that overlap, a bad joint entry).
RockMass cutRockMass(const std::vector<std::vector<Vector3>>& parts, const std::vector<JointSpec>& joints,
                     const CutOptions& options);

}  // namespace dda::rockmass
