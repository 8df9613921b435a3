// Flush joints between fixed blocks: the faces of a polyhedron fully covered
// by a coplanar, opposed face of another (BlockGeometry::internalFaces, read by
// the narrow phase, which then finds no contact on them).
#pragma once

#include "ConvexPolyhedron.hpp"

#include <vector>

namespace dda {

// A polyhedron where it is now: its topology and current corners [m]. A null
// shape leaves the body out of the search (World: a block that is not fixed).
struct PlacedPolyhedron {
	const PolyhedronTopology* shape = nullptr;
	const std::vector<Vector3>* vertices = nullptr;
};

// What covers a face of a fixed block (markInternalFaces): `depth` [m], how
// far past the face's plane the covering body surely reaches over the whole
// face (0: not covered, or a cover that thins to nothing); `planes`, the
// covering body's face planes other than the covering face, each (unit
// outward normal, offset) with n.x - offset the signed distance of x [m].
// A point past the covered face within `depth`, projecting into the face,
// lies in the covering body, and min over `planes` of (offset - n.x) is how
// far it lies inside it from every face but the covering one.
struct FaceCover {
	double depth = 0;
	std::vector<Eigen::Vector4d> planes;
	// How far x lies inside the covering body from its faces other than the
	// covering one [m] (negative outside; -infinity with no planes).
	double depthInside(const Vector3& x) const;
};

// Whether point x lies in the convex polygon `face` of `vertices` (outward
// normal n, counter-clockwise seen from outside), within `tolerance` [m] of
// each of its edges (the coverage test of flush faces here and of concave
// blocks' shared faces, ConvexParts.cpp).
bool insideFacePolygon(const Vector3& x, const std::vector<Vector3>& vertices, const std::vector<int>& face,
                       const Vector3& n, double tolerance);

// Marks, for every body given (World: every fixed block), the faces fully
// covered by a coplanar, opposed face of another given body (flush joints):
// see BlockGeometry::internalFaces. internal[b] is empty for a body left out,
// else one flag per face. Two faces are opposed when their normals are within
// parallelAngleTolerance [rad] of opposite, coplanar and covering within
// relativeLengthTolerance x the larger bounding-box diagonal [m]. Pairs are
// found by sorting boxes along x.
//
// With `covers`, also per face its cover (FaceCover): the depth [m]: for a covered
// face, how far past its plane (along its outward normal) the covering
// body surely reaches over the whole face (0 for a face not covered). It
// is the shortest chord of the covering body along that normal from the
// face's corners: the chord from a point of the covering face is a concave
// function of the point (the covering body is convex), so over the face it
// is least at a corner, and every point that projects into the face no
// farther past it than the depth lies in the covering body. The largest
// over the bodies covering the face. A covered face whose cover thins to
// nothing at one of its corners (two parts of a concave block meeting at a
// ridge) has depth 0. And the planes of that covering body's other faces,
// which bound how deep a point past the covered face lies inside it.
void markInternalFaces(const std::vector<PlacedPolyhedron>& bodies, double relativeLengthTolerance,
                       double parallelAngleTolerance, std::vector<std::vector<char>>& internal,
                       std::vector<std::vector<FaceCover>>* covers = nullptr);

}  // namespace dda
