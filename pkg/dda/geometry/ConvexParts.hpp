// The convex parts of a concave block (World::addConcaveBlock; Wu et al.
// 2014, Section 4): the check that they make one solid, and the mass
// properties of their union. Geometry only. Units: m, m^3, m^5.
#pragma once

#include "ConvexPolyhedron.hpp"
#include "MassProperties.hpp"

#include <vector>

namespace dda {

// Throws InputError naming the parts when they do not make one solid:
//   - two parts overlap: no plane separates them, i.e. along every face
//     normal of either and every cross product of an edge of one with an edge
//     of the other (the separating-axis theorem for convex polyhedra, which
//     is exact with these axes) their extents overlap by more than the
//     length tolerance (kCoplanarRelativeTolerance x the larger bounding-box
//     diagonal); the message gives the smallest such overlap [m];
//   - two parts share a region of a face plane with positive area (opposed,
//     coplanar faces whose polygons overlap by more than tolerance^2) without
//     either face lying wholly on the other: such a face would be partly
//     inside the block and partly outside, and contacts on it could not be
//     told apart; the parts must be split so that each shared face is a whole
//     face of at least one of the two;
//   - the parts are not one piece: the graph of shared faces is not connected.
// A single part is accepted (a convex block).
void checkConvexParts(const std::vector<ConvexPolyhedron>& parts);

// The same solid as `parts` (convex corner lists [m] meeting face to face
// without overlapping), with parts split so that wherever two parts share a
// face region, one of the two faces lies wholly on the other (what
// checkConvexParts requires). A part b whose face g shares area with a face f
// of a part a, neither lying wholly on the other, is cut by the planes through
// f's edges perpendicular to f (those that cut b): the piece of b on f then has
// its face within f, the others touch f along lines at most. The two pieces of
// a cut share the cut's corners exactly (each edge crossing computed once).
// Parts that need no cut are returned unchanged, in order; a cut part's pieces
// take its place. Throws InputError naming the parts when a part is not a
// convex polyhedron, when a cut would leave a piece thinner than the
// tolerance that buildConvexPolyhedron refuses, or after 1000 parts.
std::vector<std::vector<Vector3>> conformParts(const std::vector<std::vector<Vector3>>& parts);

// Two faces of different polyhedra that are opposed, coplanar (within
// kCoplanarRelativeTolerance x the larger bounding-box diagonal) and overlap
// with positive area: face f of polyhedron a and face g of polyhedron b
// (a < b), the area they share [m^2] (cutRockMass's joining of blocks).
struct SharedFace {
	int a, f, b, g;
	double area;
};
// Every such pair among `polyhedra` (vertices and faces; edges are not read),
// pairs of bodies found by sorting boxes along x.
std::vector<SharedFace> sharedFaces(const std::vector<ConvexPolyhedron>& polyhedra);

// The volume, centroid and second moments about the centroid of the union of
// disjoint parts, each given with its own about its own centroid: volumes
// add, the centroid is the volume-weighted mean, and each part's second
// moments shift to the common centroid by V_p (c_p - c)(c_p - c)^T
// (the parallel-axis rule; exact).
MassProperties unionMassProperties(const std::vector<MassProperties>& parts);

}  // namespace dda
