// Convex polyhedron topology for DDA blocks.
//
// A DDA block is a convex polyhedron given by its vertices. Contact rules need
// true polygonal faces and edges, not the triangles a hull algorithm returns, so
// the builder merges coplanar hull triangles (decided with CGAL's exact
// orientation predicate) into one polygon per plane and orients every polygon
// counter-clockwise seen from outside. Geometry only: no physics here.
// Units: whatever length unit the caller uses (SI metres in yade-dda).
#pragma once

#include <Eigen/Core>

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace dda {

using Vector3 = Eigen::Vector3d;

// Raised for input that cannot be a DDA block. The message names the offending
// point index and value, e.g. "point 7 (0.5, 0.5, 0.5) lies strictly inside the
// convex hull of the others (non-convex input)".
class InputError : public std::invalid_argument {
public:
	using std::invalid_argument::invalid_argument;
};

struct ConvexPolyhedron {
	// Vertices in the order of the caller's input points (every input point is a
	// hull vertex, or construction fails).
	std::vector<Vector3> vertices;
	// One polygon per face plane: vertex indices, counter-clockwise seen from
	// outside (so (v1-v0)x(v2-v0) points outward for a convex polygon).
	std::vector<std::vector<int>> faces;
	// Each undirected edge once, with the two faces that share it:
	// edges[e] = {a, b}, edgeFaces[e] = {f, g} where f traverses a->b and g b->a.
	std::vector<std::array<int, 2>> edges;
	std::vector<std::array<int, 2>> edgeFaces;
};

// Builds the convex polyhedron whose vertices are exactly `points`.
// Throws InputError (never crashes, never returns a partial result) when:
//   - fewer than 4 points;
//   - a coordinate is NaN or infinite (names point and coordinate);
//   - two points coincide (names both indices);
//   - all points are coplanar (zero volume);
//   - a point is not a vertex of the hull: strictly inside (non-convex input) or
//     on the hull surface without being a corner (names the index).
// Face merging and all side-of tests use exact predicates, so the topology does
// not depend on round-off.
ConvexPolyhedron buildConvexPolyhedron(const std::vector<Vector3>& points);

}  // namespace dda
