// Step 1 of the narrow phase (PairDetection.hpp): the separation of a pair of
// convex blocks along every candidate axis, the outward normals of their faces
// and the cross products of edge pairs whose Gauss-map arcs cross (the faces
// of the Minkowski difference). An axis farther than d0 rejects the pair.
// Units: m.
#pragma once

#include "PreparedBlock.hpp"

#include <algorithm>
#include <limits>
#include <vector>

namespace dda::narrow {

struct EdgeAxis {
	bool valid = false;
	// Parallel within the angle tolerance, not exactly: the axis bounds the
	// pair's penetration but is no entrance (its crossing has no stable
	// position).
	bool nearParallel = false;
	double separation = 0;              // [m]
	Vector3 normal = Vector3::UnitZ();  // unit, from A towards B
};

// What step 1 found besides the face candidates.
struct AxisSearch {
	// Largest separation over every axis tested, internal faces and the edges
	// of internal faces included: minus
	// the pair's penetration depth, or less [m].
	double deepestBound = -std::numeric_limits<double>::infinity();
	// Largest separation of an entrance-eligible (non-internal) face [m].
	double bestFace = -std::numeric_limits<double>::infinity();
	// The edge axis of largest separation (edges bestEdgeA of A, bestEdgeB of
	// B), and the previous entrance's axis when that was an edge pair.
	EdgeAxis bestEdge, previousEdge;
	int bestEdgeA = -1, bestEdgeB = -1;
	// Largest separation along the axes of edge pairs parallel within the
	// angle tolerance (not exactly): no entrance and no rejection, as before,
	// but a bound of the pair's penetration (step 3) [m].
	double nearParallelBest = -std::numeric_limits<double>::infinity();
	// The edge pair of nearParallelBest (edge of A, edge of B), -1 when none.
	int nearParallelEdgeA = -1, nearParallelEdgeB = -1;
	// The largest separation of an entrance-eligible axis [m].
	double best() const { return bestEdge.valid ? std::max(bestFace, bestEdge.separation) : bestFace; }
};

// The face axes of both blocks, the likeliest separating face of each (along
// the line of centroids) first: false as soon as one is farther than d0 [m].
// Else the entrance-eligible faces are listed in `faces` (A's, then B's, each
// in face order) and axes.deepestBound, axes.bestFace are set. `hysteresis`
// [m] is step 2's (>= lengthTolerance).
bool searchFaceAxes(const Prepared& a, const Prepared& b, double d0, double hysteresis,
                    std::vector<FaceCandidate>& faces, AxisSearch& axes);

// The edge axes (after prepareEdges of both blocks): false as soon as one is
// farther than d0 [m]; else the edge fields of `axes` are set and
// axes.deepestBound raised. `previous` is the pair's entrance of the last step.
bool searchEdgeAxes(const Prepared& a, const Prepared& b, double d0, double sinTolerance,
                    const EntranceFeature& previous, Scratch& s, AxisSearch& axes);

}  // namespace dda::narrow
