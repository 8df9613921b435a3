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
void markInternalFaces(const std::vector<PlacedPolyhedron>& bodies, double relativeLengthTolerance,
                       double parallelAngleTolerance, std::vector<std::vector<char>>& internal);

}  // namespace dda
