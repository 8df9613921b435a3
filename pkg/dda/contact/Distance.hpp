// Geometric distance kernels of DDA contacts (Wu et al. 2014, Eq. 10-11).
//
// Pure functions on coordinates [m]; no blocks, no physics. Two contact types
// between a block i and a block j:
//   - vertex-face: a corner P of block i against a face of block j;
//   - edge-edge:   an edge P1P2 of block i against an edge P3P4 of block j.
//
// Sign convention (shared with Linearization.hpp): a normal distance is
// POSITIVE when the two features are SEPARATED (the vertex lies on the outer
// side of the face; edge j lies on the "outside" side of edge i) and NEGATIVE
// when they interpenetrate. The distance is measured along a unit normal n
// that points from block i's feature towards block j's "outside":
//   - vertex-face: n is the outward unit normal of block j's face, and the
//     distance is n . (P - m), m the mean of the face's corners;
//   - edge-edge: n = +-(P1P2 x P3P4)/|P1P2 x P3P4|, the sign chosen so that
//     n . reference >= 0, where `reference` is a direction the caller knows
//     points from block i into the side where block j should be (for example
//     the sum of the outward normals of the two faces of block i that share
//     the edge); the distance is n . (P3 - P1).
//
// Tolerances. All length tolerances are absolute [m]. They must be chosen by
// the caller from the scene's length scale:
//   - above the round-off of the coordinates, about 1e-15 x the largest
//     coordinate magnitude (points 1 km from the origin carry ~1e-12 m noise);
//   - above the face planarity allowed by buildConvexPolyhedron, 2 x
//     kCoplanarRelativeTolerance x the block's bounding-box diagonal;
//   - far below any real geometric feature.
// kDefaultRelativeLengthTolerance x (block bounding-box diagonal) satisfies all
// three for blocks up to ~1e5 of their own size from the origin.
// The angle tolerance is dimensionless [rad] and independent of the length
// scale; see kDefaultParallelAngleTolerance.
#pragma once

#include "dda/geometry/ConvexPolyhedron.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace dda {

// Multiply by a block's bounding-box diagonal [m] to get a length tolerance [m]
// (dimensionless). 1e-8 of a 1 m block is 10 nm: far above double round-off of
// coordinates up to 1e5 m from the origin, 5x the face planarity allowed by
// kCoplanarRelativeTolerance, and far below the size of any rock feature.
inline constexpr double kDefaultRelativeLengthTolerance = 1e-8;

// Two edges whose directions make an angle below this [rad] are treated as
// parallel: their cross product gives no reliable normal. Scale-free. Rules:
//   - it must exceed the direction error of an edge computed from rounded
//     coordinates, ~1e-16 x (distance from the origin / edge length), so
//     1e-6 is safe for edges down to ~1e-9 of their distance from the origin;
//   - the contact normal of an edge-edge contact turns by ~(rotation in a
//     step)/angle when a block turns, so a caller linearising over a step may
//     want a tolerance of the order of the largest rotation per step instead.
inline constexpr double kDefaultParallelAngleTolerance = 1e-6;

// ------------------------------------------------------------ vertex-face

struct VertexFaceResult {
	// Signed distance [m] of P from the face plane, > 0 on the outer side.
	double distance = 0;
	// Outward unit normal of the face (Newell normal, dda::faceNormal).
	Vector3 normal = Vector3::Zero();
	// Orthogonal projection of P on the face plane [m].
	Vector3 projection = Vector3::Zero();
	// True when the projection lies inside the polygon or within the
	// tolerance outside any of its edges (on an edge or corner: inside).
	bool inside = false;
	// Smallest in-plane distance [m] from the projection to the lines of the
	// face's edges, positive inside, negative outside (the most violated edge).
	double insideMargin = 0;
};

// Distance of the point p from the plane of the convex polygon `face` (vertex
// indices into `vertices`, counter-clockwise seen from outside, as produced by
// buildConvexPolyhedron), plane through the mean of the corners with normal
// faceNormal(vertices, face). `insideTolerance` [m] >= 0 widens the polygon
// for the inside test. Throws InputError (from faceNormal) for a face with
// fewer than 3 corners, bad indices or zero area; never returns NaN for finite
// input.
VertexFaceResult vertexFaceDistance(const Vector3& p, const std::vector<Vector3>& vertices,
                                    const std::vector<int>& face, double insideTolerance);

// ------------------------------------------------------------ edge-edge

struct EdgeEdgeResult {
	// Signed normal distance [m], > 0 separated (see the header comment).
	// For parallel edges (see `parallel`) n has no cross-product definition; it
	// is then the unit vector perpendicular to the edge direction towards the
	// line of the other edge (or, for collinear edges, the part of `reference`
	// perpendicular to the edges), oriented by `reference`, and the distance is
	// the signed distance between the two lines. Always finite.
	double distance = 0;
	Vector3 normal = Vector3::UnitZ();  // unit, always finite
	// Parameters in [0, 1] of the closest points P1 + s (P2 - P1) and
	// P3 + t (P4 - P3) of the two SEGMENTS (one closest pair when not unique).
	double s = 0, t = 0;
	Vector3 closestI = Vector3::Zero(), closestJ = Vector3::Zero();
	// |P1P2 x P3P4| <= sin(angleTolerance) |P1P2| |P3P4|; set as well when an
	// edge has zero length.
	bool parallel = false;
	// An edge has zero length (exactly coincident endpoints).
	bool degenerate = false;
	// Not parallel, and the closest points of the two infinite LINES fall on
	// both segments, within `lengthTolerance` [m] of an endpoint counting as on
	// (the on-segment condition of an edge-edge contact). Then s, t are those
	// line parameters clamped to [0, 1].
	bool interior = false;
};

// Edge P1P2 of block i against edge P3P4 of block j. `reference` orients the
// normal (n . reference >= 0; when reference is perpendicular to the edges'
// cross product, or zero, the cross product's own orientation is kept).
// `lengthTolerance` [m] >= 0 for the on-segment condition, `angleTolerance`
// [rad] in [0, pi/2) for the parallel flag. Never returns NaN for finite input.
EdgeEdgeResult edgeEdgeDistance(const Vector3& p1, const Vector3& p2, const Vector3& p3, const Vector3& p4,
                                const Vector3& reference, double lengthTolerance,
                                double angleTolerance = kDefaultParallelAngleTolerance);

}  // namespace dda
