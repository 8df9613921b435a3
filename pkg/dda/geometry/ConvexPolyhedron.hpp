// Convex polyhedron topology for DDA blocks.
//
// A DDA block is a convex polyhedron given by its vertices. Contact rules need
// true polygonal faces and edges, not the triangles a hull algorithm returns, so
// the builder merges the hull triangles of one face plane into one polygon and
// orients every polygon counter-clockwise seen from outside. Geometry only: no
// physics here. Units: whatever length unit the caller uses (SI metres in
// yade-dda).
//
// Faces are merged within a tolerance, not exactly. A box rotated by a general
// angle, its corners rounded to double, has sides whose 4 corners are almost
// never exactly coplanar; an exact merge would leave it with 12 triangles. So a
// point counts as lying on a face plane when it is exactly coplanar with it, or
// within kCoplanarRelativeTolerance x (bounding-box diagonal) of it. As a
// consequence the faces of a block built from rounded input are nearly, not
// exactly, planar: consumers must not take a face's plane from any 3 of its
// corners, but from its Newell normal (faceNormal below) through the mean of
// its corners.
#pragma once

#include "dda/core/Errors.hpp"
#include "dda/core/Types.hpp"

#include <array>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace dda {

// Distance, as a fraction of the block's bounding-box diagonal, within which a
// point lies on a face plane (dimensionless). Rule: rotating or translating
// coordinates in double precision moves them by round-off of about 1e-16 x the
// coordinate magnitude, i.e. about 1e-16 x (distance from the origin / block
// size) relative to the block; 1e-9 stays far above that for blocks up to ~1e6
// of their own size from the origin (a 1 mm block 1 km away), and far below any
// real geometric feature of a rock block (1e-9 of a 1 m block is 1 nm). Two
// faces meeting at a dihedral angle within ~1e-9 rad of 180 degrees are one
// face; a corner closer than this to the plane of a face is rejected (the
// block is too flat there), never silently dropped.
inline constexpr double kCoplanarRelativeTolerance = 1e-9;

// The faces and edges of a convex polyhedron, without the positions of its
// vertices: all that contact rules and colliders need besides the corners. A
// DDA block holds its own corners and shares this with every block of the same
// topology (TopologyPool): the boxes of a scene, all given corner by corner in
// one order, have one.
struct PolyhedronTopology {
	// One polygon per face plane: vertex indices, counter-clockwise seen from
	// outside by the face's Newell normal, no vertex repeated, strictly convex
	// (every corner turns left). Every corner of a face lies within
	// kCoplanarRelativeTolerance x (bounding-box diagonal) of the plane of the
	// face's largest hull triangle, hence within about twice that of the plane
	// through the mean of its corners with normal faceNormal(vertices, face).
	std::vector<std::vector<int>> faces;
	// Each undirected edge once, with the two faces that share it:
	// edges[e] = {a, b}, edgeFaces[e] = {f, g} where f traverses a->b and g b->a.
	std::vector<std::array<int, 2>> edges;
	std::vector<std::array<int, 2>> edgeFaces;
	// V = E - F + 2 (Euler's formula, which buildConvexPolyhedron checks).
	int vertexCount() const { return static_cast<int>(edges.size()) - static_cast<int>(faces.size()) + 2; }
	bool operator==(const PolyhedronTopology& other) const {
		return faces == other.faces && edges == other.edges && edgeFaces == other.edgeFaces;
	}
};

struct ConvexPolyhedron : PolyhedronTopology {
	// Vertices in the order of the caller's input points (every input point is a
	// hull vertex, or construction fails).
	std::vector<Vector3> vertices;
};

// Hands out one shared PolyhedronTopology per distinct topology, so that
// blocks of equal faces and edges hold one copy: a box's own took 704 bytes of
// heap in 10 allocations (faces, edges, edge faces and the shared_ptr block, in
// malloc's chunk sizes), 35 MB on 50,000 boxes. Keeps every topology it handed
// out for its own lifetime.
class TopologyPool {
public:
	// The pool's topology equal to `topology`, which joins the pool if none is.
	std::shared_ptr<const PolyhedronTopology> intern(std::shared_ptr<const PolyhedronTopology> topology);

private:
	std::unordered_multimap<std::size_t, std::shared_ptr<const PolyhedronTopology>> byHash_;
};

// Builds the convex polyhedron whose vertices are exactly `points`.
// Throws InputError (never crashes, never returns a partial result) when:
//   - fewer than 4 points;
//   - a coordinate is NaN or infinite (names point and coordinate);
//   - two points coincide (names both indices);
//   - all points are coplanar (zero volume, decided exactly);
//   - a point is not a corner of the hull: strictly inside (non-convex input),
//     or on the hull surface without being a corner, i.e. within the coplanar
//     tolerance of the plane of one face (inside a face) or of two (inside an
//     edge). A real corner that close to a face plane is rejected the same way,
//     the message says the block is too flat there;
//   - the block is thinner than the tolerance, or the hull triangles within
//     the tolerance of one plane do not form one convex polygon.
// The hull and the exact-coplanarity test use CGAL's exact predicates; the
// tolerance test compares a double distance with the scaled tolerance. Each
// face's plane is that of its largest hull triangle, fixed before the face is
// grown, so a chain of slightly tilted triangles (a finely tessellated sphere)
// never merges into one curved face.
ConvexPolyhedron buildConvexPolyhedron(const std::vector<Vector3>& points);

// The corners of the convex hull of any points [m]: indices into `points`,
// in input order, of the points that buildConvexPolyhedron accepts as the
// corners of that hull. Dropped: points inside the hull (decided exactly),
// repeats (closer than the coincidence tolerance: the first stays), and
// points on the hull surface that are no corner of its faces merged within
// the coplanar tolerance (inside a face or an edge, or a corner so flat that
// the faces around it merge). Those last drops change the volume by at most
// the tolerance times the hull's area. Throws InputError for fewer than 4
// points, NaN or inf, or no volume.
std::vector<int> hullCorners(const std::vector<Vector3>& points);

// Unit outward normal of a face by Newell's method (the polygon's vector area,
// taken about the mean of its corners to limit round-off far from the origin).
// Well defined for the nearly planar faces of buildConvexPolyhedron; outward
// when the face is counter-clockwise seen from outside. Throws InputError for a
// face with fewer than 3 corners, an index out of range, or zero area.
Vector3 faceNormal(const std::vector<Vector3>& vertices, const std::vector<int>& face);

}  // namespace dda
