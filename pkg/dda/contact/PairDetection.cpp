#include "PairDetection.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace dda {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using ExactPoint = Kernel::Point_3;
using ExactVector = Kernel::Vector_3;

// A double distance from a plane (or between two lines) below this fraction of
// the lengths it is computed from is round-off (dimensionless): its sign is
// then decided exactly by CGAL. Rule: the distance carries an error of a few
// DBL_EPSILON x (lengths involved) x (conditioning of the face triangle, which
// chooseFaceCorners keeps near 1); 1e-12 is ~4500 DBL_EPSILON, far above that
// and far below kDefaultRelativeLengthTolerance (1e-8).
constexpr double kRoundoffRelative = 1e-12;

// A crossing beside a vertex contact is that contact only if their normals
// are within about 25 degrees (dimensionless cosine).
constexpr double kSameNormalCosine = 0.9;

// Two face areas within this fraction of each other tie (dimensionless), so
// identical blocks are ordered by block and face index, not by round-off.
// Rule: above the round-off of an area (~1e-15), below any real difference.
constexpr double kAreaTieRelative = 1e-9;

// No sub-contact is deeper than the pair's penetration: a vertex-face or
// edge-edge gap is at least min(depthBound, 0) - lengthTolerance, depthBound
// the pair's separating-axis value (detectPairContacts, step 3). Rule, from
// geometry: for overlapping convex blocks a translation of the penetration
// depth PD separates them, and it changes any sub-contact's gap, n . (pI -
// pJ) for a unit n, by at most PD; a gap below -PD would still be negative
// with the blocks apart, so it measures no contact (a "ghost" the penalty
// spring pushes on). For blocks apart no gap may be negative. An edge
// crossing whose line distance is deeper than PD is an edge piercing a face
// steeply near its boundary, or passing another edge beyond the face's plane.
// Before, a crossing could be twice the entrance's penetration deep (the
// narrow-phase oracle, tests/cpp/test_narrow_phase_oracle.cpp, found
// crossings between 1 and 2 x PD deep in ~1.8% of random near pairs of
// slender blocks), and once d0 deeper (crossings 9 mm deep between blocks
// 0.3 to 4 mm apart).

// An edge-edge sub-contact of a face entrance must push within 60 degrees of
// the face's normal: cosine of that angle (dimensionless). An edge crossing a
// face's edge steeply (along the face normal) has its line distance in the
// face's plane; that contact belongs to the neighbouring face, and the
// vertex-face contacts of its corners already hold the pair along the normal.
constexpr double kEdgeNormalMinCosine = 0.5;

// Performance. The narrow phase runs for every pair the broad phase reports,
// so it avoids work whose result it does not need, without changing any
// result: the bounding boxes are tested before any face plane is built, face
// areas are computed only when a tie between faces needs them, edge data only
// when every face axis passed, per-call buffers are reused per thread (no heap
// allocation in the steady state), signs of triple products of unit normals
// and exact collinearity are settled by a double-precision filter with a
// proven round-off bound before falling back to CGAL's exact predicates, and a
// sub-contact's gap comes from its stencil without the full linearisation.
// Every double result is computed by the same expressions as before.

// |C . (B x A)| computed in double for unit vectors A, B, C (normalized face
// normals, components within 1 + 4 DBL_EPSILON of 1 in magnitude) is within
// about 21 DBL_EPSILON (~5e-15) of the exact triple product of those doubles;
// above this bound its sign is the exact sign (dimensionless).
constexpr double kUnitTripleRoundoff = 1e-13;

// A component a_j b_k - a_k b_j of a cross product computed in double is
// within 4 DBL_EPSILON max|a_i| max|b_i| of its exact value (barring
// underflow); above this factor the exact cross product is not zero.
constexpr double kCrossRoundoffRelative = 1e-14;

ExactPoint exactPoint(const Vector3& p) { return ExactPoint(p.x(), p.y(), p.z()); }
ExactVector exactVector(const Vector3& v) { return ExactVector(v.x(), v.y(), v.z()); }

// Face f's plane (FacePlane without firstNormal/firstNorm, which the returned
// triangle holds). Both the per-call path (ensurePlane) and
// BlockPlanes::compute use this one function, so a cached plane holds the
// same doubles as one built per call.
FaceTriangle buildFacePlane(const std::vector<Vector3>& v, const std::vector<int>& face, FacePlane& plane) {
	const FaceTriangle triangle = chooseFaceTriangle(v, face);
	plane.corners = triangle.corners;
	const Vector3& f0 = v[plane.corners[0]];
	// The triangle's (f1 - f0) x (f2 - f0), normalized as Eigen's normalized()
	// does: divided by its norm, sqrt(squaredNorm()), when that is > 0 (as the
	// squared norm then is), else unchanged.
	plane.normal = triangle.crossNorm > 0 ? Vector3(triangle.cross / triangle.crossNorm) : triangle.cross;
	plane.side1 = (v[plane.corners[1]] - f0).norm();
	plane.side2 = (v[plane.corners[2]] - f0).norm();
	return triangle;
}

// The normal of a face's first three corners (unnormalised), scored by
// likelySeparatingFace: (v1 - v0) x (v2 - v0), the triangle chooseFaceTriangle
// tries first (its firstCross).
Vector3 firstCornersNormal(const std::vector<Vector3>& v, const std::vector<int>& face) {
	const Vector3& f0 = v[face[0]];
	return (v[face[1]] - f0).cross(v[face[2]] - f0);
}

// Edge e's data from its corners and its faces' planes (shared as above).
void buildEdge(const std::vector<Vector3>& v, const PolyhedronTopology& shape, const FacePlane* faces, int e,
               EdgeData& d) {
	d.direction = v[shape.edges[e][1]] - v[shape.edges[e][0]];
	d.length = d.direction.norm();
	const auto& ef = shape.edgeFaces[e];
	d.arc = faces[ef[1]].normal.cross(faces[ef[0]].normal);
}

// Bounding box of the corners.
void cornerBounds(const std::vector<Vector3>& v, Vector3& lower, Vector3& upper) {
	lower = upper = v.front();
	for (const Vector3& x : v) {
		lower = lower.cwiseMin(x);
		upper = upper.cwiseMax(x);
	}
}

struct FaceCandidate {
	EntranceFeature feature;
	double separation = 0;
};

// Per-thread buffers reused between calls (detectPairContacts is not
// re-entrant within one thread).
struct Scratch {
	std::vector<FacePlane> faces[2];
	std::vector<double> areas[2];  // < 0 until computed
	std::vector<char> planeReady[2];
	std::vector<double> separations[2];  // face axes' separations
	std::vector<char> separationReady[2];
	std::vector<EdgeData> edges[2];
	std::vector<FaceCandidate> candidates;
	std::vector<double> cornerDistances;
	std::vector<char> cornerDistanceReady;
	std::vector<int> used, faceEdges;
	std::vector<int> edgeFacesB, arcSides;  // the edge axes' Gauss-map test
	std::vector<char> faceMark;
	std::vector<Vector3> pointsA, pointsB;
	std::vector<int> identity;  // 0, 1, 2, ...: "every sub-unit"
	std::vector<char> vertexLinked[2];
};

Scratch& scratch() {
	thread_local Scratch s;
	return s;
}

// A list of sub-unit indices (linked ones, or all of them).
struct Indices {
	const int* first = nullptr;
	int count = 0;
	const int* begin() const { return first; }
	const int* end() const { return first + count; }
};

// A block with the per-call data the narrow phase needs.
struct Prepared {
	const PolyhedronTopology* shape = nullptr;
	const std::vector<Vector3>* vertices = nullptr;
	Vector3 centroid = Vector3::Zero();
	// Face planes: the block's BlockPlanes (every plane built), or the
	// thread's buffer with planeReady flags (built when first needed).
	const FacePlane* faces = nullptr;
	FacePlane* ownFaces = nullptr;  // the buffer, nullptr with BlockPlanes
	char* planeReady = nullptr;     // nullptr with BlockPlanes
	const BlockPlanes* planes = nullptr;
	double* areas = nullptr;
	double* separations = nullptr;
	char* separationReady = nullptr;
	const EdgeData* edges = nullptr;
	int faceTotal = 0;
	Vector3 lower = Vector3::Zero(), upper = Vector3::Zero();  // bounding box [m]
	const std::vector<char>* internalFaces = nullptr;
	// The sub-units the narrow phase may use (all, or those a broad phase
	// linked to the pair), and per corner whether it is one of them.
	Indices vertexList, edgeList, faceList;
	const char* vertexLinked = nullptr;  // nullptr: every corner
	long* tests = nullptr;               // vertex-face and edge-edge tests made

	bool linkedVertex(int v) const { return !vertexLinked || vertexLinked[v]; }

	// A face covered by a coplanar face of a neighbouring fixed block: never an
	// entrance, and its edges give no edge axes.
	bool internal(int f) const { return internalFaces && (*internalFaces)[f]; }
	bool internalEdge(int e) const {
		return internalFaces && ((*internalFaces)[shape->edgeFaces[e][0]] || (*internalFaces)[shape->edgeFaces[e][1]]);
	}

	const Vector3& corner(int v) const { return (*vertices)[v]; }
	int cornerCount() const { return static_cast<int>(vertices->size()); }
	int faceCount() const { return faceTotal; }
	int edgeCount() const { return static_cast<int>(shape->edges.size()); }
	const Vector3& edgeStart(int e) const { return corner(shape->edges[e][0]); }
	const Vector3& edgeEnd(int e) const { return corner(shape->edges[e][1]); }
	// Sum of the outward normals of the two faces sharing edge e: points out
	// of the block at the edge.
	Vector3 edgeOutward(int e) const {
		return faces[shape->edgeFaces[e][0]].normal + faces[shape->edgeFaces[e][1]].normal;
	}
	// The polygon's area [m^2], from the fan about its first corner.
	double area(int f) const {
		double& a = areas[f];
		if (a < 0) {
			const std::vector<int>& face = shape->faces[f];
			const std::vector<Vector3>& v = *vertices;
			Vector3 vectorArea = Vector3::Zero();
			for (std::size_t k = 1; k + 1 < face.size(); ++k)
				vectorArea += (v[face[k]] - v[face[0]]).cross(v[face[k + 1]] - v[face[0]]);
			a = 0.5 * vectorArea.norm();
		}
		return a;
	}
};

// Step 0 data: the block and its bounding box.
Prepared prepareBounds(const BlockGeometry& block) {
	Prepared p;
	p.shape = block.shape;
	p.vertices = block.vertices;
	p.centroid = block.centroid;
	p.internalFaces = block.internalFaces;
	p.planes = block.planes;
	if (p.planes) {
		p.lower = p.planes->lower;
		p.upper = p.planes->upper;
	} else {
		cornerBounds(*block.vertices, p.lower, p.upper);
	}
	return p;
}

// Face planes (into the thread's buffer `slot`), each built when first needed
// (ensurePlane): a pair rejected by one face axis builds few of them.
void prepareFaces(Prepared& p, Scratch& s, int slot) {
	const std::size_t count = p.shape->faces.size();
	if (p.planes) {
		p.faces = p.planes->faces.data();
		p.ownFaces = nullptr;
		p.planeReady = nullptr;
	} else {
		s.faces[slot].resize(count);
		s.planeReady[slot].assign(count, 0);
		p.faces = p.ownFaces = s.faces[slot].data();
		p.planeReady = s.planeReady[slot].data();
	}
	s.areas[slot].assign(count, -1.0);
	s.separations[slot].resize(count);
	s.separationReady[slot].assign(count, 0);
	p.areas = s.areas[slot].data();
	p.separations = s.separations[slot].data();
	p.separationReady = s.separationReady[slot].data();
	p.faceTotal = static_cast<int>(count);
}

void ensurePlane(const Prepared& p, int f) {
	if (!p.planeReady || p.planeReady[f]) return;
	buildFacePlane(*p.vertices, p.shape->faces[f], p.ownFaces[f]);
	p.planeReady[f] = 1;
}

// Edge data of the edges the pair may use (after prepareSubUnits).
void prepareEdges(Prepared& p, Scratch& s, int slot) {
	if (p.planes) {
		p.edges = p.planes->edges.data();
		return;
	}
	std::vector<EdgeData>& edges = s.edges[slot];
	edges.resize(p.edgeCount());
	for (int e : p.edgeList) {
		const auto& ef = p.shape->edgeFaces[e];
		ensurePlane(p, ef[0]);
		ensurePlane(p, ef[1]);
		buildEdge(*p.vertices, *p.shape, p.faces, e, edges[e]);
	}
	p.edges = edges.data();
}

// Signed distance [m] of x from the plane of face f of `block`, > 0 outside.
// Below round-off the sign is decided exactly: a point exactly on the
// triangle's plane gets exactly 0, a point whose double distance has the
// wrong sign gets 0.
double planeDistanceNearPlane(const Prepared& block, int f, const Vector3& x, const Vector3& offset, double d);

inline double planeDistance(const Prepared& block, int f, const Vector3& x) {
	const FacePlane& plane = block.faces[f];
	const Vector3& f0 = block.corner(plane.corners[0]);
	const Vector3 offset = x - f0;
	const double d = plane.normal.dot(offset);
	// The round-off test below, |d| > kRoundoffRelative (|offset| + side1 +
	// side2), first with a cheap upper bound of |offset| in place of its
	// sqrt: the 1-norm, times 1 + 1e-6 to cover its rounding and that of the
	// computed 2-norm (each within a few DBL_EPSILON relative). Every step
	// (+, x by a positive constant) is monotone in floating point, so a |d|
	// above the larger threshold is above the exact test's too, and the
	// function returns d as before; otherwise the exact test decides as before.
	const double normBound = (std::abs(offset.x()) + std::abs(offset.y()) + std::abs(offset.z())) * (1 + 1e-6);
	if (std::abs(d) > kRoundoffRelative * (normBound + plane.side1 + plane.side2)) return d;
	return planeDistanceNearPlane(block, f, x, offset, d);
}

// planeDistance's exact test, for a point near the plane (out of line).
[[gnu::noinline]] double planeDistanceNearPlane(const Prepared& block, int f, const Vector3& x, const Vector3& offset,
                                                double d) {
	const FacePlane& plane = block.faces[f];
	const Vector3& f0 = block.corner(plane.corners[0]);
	const double scale = offset.norm() + plane.side1 + plane.side2;
	if (std::abs(d) > kRoundoffRelative * scale) return d;
	const Vector3& f1 = block.corner(plane.corners[1]);
	const Vector3& f2 = block.corner(plane.corners[2]);
	const CGAL::Orientation side = CGAL::orientation(exactPoint(f0), exactPoint(f1), exactPoint(f2), exactPoint(x));
	if (side == CGAL::COPLANAR) return 0;
	const bool outside = side == CGAL::POSITIVE;
	return (outside == (d > 0)) ? d : 0;
}

// Smallest in-plane distance [m] of x's projection from the lines of face f's
// edges, positive inside the polygon (as vertexFaceDistance's insideMargin).
double insideMargin(const Prepared& block, int f, const Vector3& x) {
	const std::vector<int>& face = block.shape->faces[f];
	const Vector3& n = block.faces[f].normal;
	double margin = std::numeric_limits<double>::infinity();
	for (std::size_t k = 0; k < face.size(); ++k) {
		const Vector3& a = block.corner(face[k]);
		const Vector3& b = block.corner(face[(k + 1) % face.size()]);
		const Vector3 inward = n.cross(b - a);
		const double length = inward.norm();
		if (!(length > 0)) continue;
		margin = std::min(margin, inward.dot(x - a) / length);
	}
	return margin;
}

double segmentDistance(const Vector3& x, const Vector3& p, const Vector3& q) {
	const Vector3 d = q - p;
	const double dd = d.squaredNorm();
	const double s = dd > 0 ? std::clamp(d.dot(x - p) / dd, 0.0, 1.0) : 0.0;
	return (x - (p + s * d)).norm();
}

// Does x's projection on the plane of face f lie within `reach` [m] of the
// polygon? (A corner just past a face's edge or corner makes a contact with
// it; measured as a distance, not per edge line, so that near an acute corner
// of the face, too, the corner is within sqrt(2) reach of the face.)
bool projectionNearFace(const Prepared& block, int f, const Vector3& x, double reach) {
	const double margin = insideMargin(block, f, x);
	if (margin >= 0) return true;
	if (margin < -reach) return false;
	const std::vector<int>& face = block.shape->faces[f];
	const Vector3& n = block.faces[f].normal;
	const Vector3 projected = x - n * n.dot(x - block.corner(face[0]));
	double nearest = std::numeric_limits<double>::infinity();
	for (std::size_t k = 0; k < face.size(); ++k)
		nearest = std::min(nearest, segmentDistance(projected, block.corner(face[k]),
		                                            block.corner(face[(k + 1) % face.size()])));
	return nearest <= reach;
}

// Two edge directions are parallel: exactly (cross product of the double
// vectors zero, decided by CGAL) or within the angle tolerance.
// sinTolerance = sin(angleTolerance); la = |da|, lb = |db|.
// `cross` = da x db and `crossNorm` = |cross| as computed by the callers
// (Eigen's cross() and norm()).
bool parallelDirections(const Vector3& da, const Vector3& db, const Vector3& cross, double crossNorm, double la,
                        double lb, double sinTolerance) {
	if (crossNorm <= sinTolerance * la * lb) return true;
	// Not within the angle: parallel only when exactly collinear. A component
	// of the double cross product above its round-off bound proves it is not.
	const double scale = da.cwiseAbs().maxCoeff() * db.cwiseAbs().maxCoeff();
	if (scale > 1e-250 && scale < 1e250 && cross.cwiseAbs().maxCoeff() > kCrossRoundoffRelative * scale) return false;
	return CGAL::collinear(ExactPoint(0, 0, 0), exactPoint(da), exactPoint(db));
}

bool parallelDirections(const Vector3& da, const Vector3& db, double sinTolerance) {
	const Vector3 cross = da.cross(db);
	return parallelDirections(da, db, cross, cross.norm(), da.norm(), db.norm(), sinTolerance);
}

// Exact sign of the triple product x . (y x z) of three unit vectors, given
// its double value `approx`.
int unitOrientation(double approx, const Vector3& x, const Vector3& y, const Vector3& z) {
	if (approx > kUnitTripleRoundoff) return 1;
	if (approx < -kUnitTripleRoundoff) return -1;
	// Exactly zero when each of the determinant's six terms x_i y_j z_k has a
	// zero factor (axis-aligned normals).
	bool zero = true;
	for (const auto& [i, j, k] : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{1, 2, 0}, std::array<int, 3>{2, 0, 1},
	                              std::array<int, 3>{0, 2, 1}, std::array<int, 3>{1, 0, 2}, std::array<int, 3>{2, 1, 0}})
		zero = zero && (x[i] == 0 || y[j] == 0 || z[k] == 0);
	if (zero) return 0;
	return static_cast<int>(CGAL::orientation(exactVector(x), exactVector(y), exactVector(z)));
}

// Do the Gauss-map arcs of edge ea of A (a1, a2 its faces' normals) and of
// edge eb of B (c, d: minus its faces' normals) cross (strictly)? Signs of
// triple products decided exactly (Gregorius, "The separating axis test
// between convex polyhedra", GDC 2013).
//
// The first two signs depend on ea and on one face of B only: the caller
// computes them once per (ea, face of B) with arcSide and passes
// cba = arcSide(a, ea, b, fb[0]), dba = arcSide(a, ea, b, fb[1]) (the same
// expressions the test evaluated per edge pair), having checked
// cba * dba < 0.
int arcSide(const Prepared& a, int ea, const Prepared& b, int g) {
	const auto& fa = a.shape->edgeFaces[ea];
	const Vector3& A = a.faces[fa[0]].normal;
	const Vector3& B = a.faces[fa[1]].normal;
	const Vector3 C = -b.faces[g].normal;
	const Vector3& ba = a.edges[ea].arc;                // B x A
	return unitOrientation(C.dot(ba), C, B, A);  // C . (B x A)
}

bool arcsCross(const Prepared& a, int ea, const Prepared& b, int eb, int cba) {
	const auto& fa = a.shape->edgeFaces[ea];
	const auto& fb = b.shape->edgeFaces[eb];
	const Vector3& A = a.faces[fa[0]].normal;
	const Vector3& B = a.faces[fa[1]].normal;
	const Vector3 C = -b.faces[fb[0]].normal, D = -b.faces[fb[1]].normal;
	const Vector3& dc = b.edges[eb].arc;  // (-D) x (-C) = D x C
	const int adc = unitOrientation(A.dot(dc), A, D, C);  // A . (D x C)
	const int bdc = unitOrientation(B.dot(dc), B, D, C);
	return adc * bdc < 0 && cba * bdc > 0;
}

// Separation [m] along the outward normal of face f of `owner`: the smallest
// signed distance of `other`'s corners from the face's plane (computed once).
//
// With a `floor`, the corners stop at the first one below it: the result is
// then the smallest distance of the corners so far, below `floor` and at
// least the separation (not kept as the face's). The corners are taken in the
// same order, so a separation at or above the floor is the same double
// (std::min keeps the earlier of two equal values: +0 and -0 in the same
// order). The face's plane tests are counted in full either way, so the
// counter keeps the value it has without the floor.
double faceSeparation(const Prepared& owner, int f, const Prepared& other,
                      double floor = -std::numeric_limits<double>::infinity()) {
	if (owner.separationReady[f]) return owner.separations[f];
	ensurePlane(owner, f);
	*owner.tests += other.cornerCount();
	double separation = std::numeric_limits<double>::infinity();
	for (int v = 0; v < other.cornerCount(); ++v) {
		separation = std::min(separation, planeDistance(owner, f, other.corner(v)));
		if (separation < floor) return separation;
	}
	owner.separations[f] = separation;
	owner.separationReady[f] = 1;
	return separation;
}

// The face of `owner` whose normal (from its first three corners) points
// most along `direction`: the likeliest separating face axis, tried first.
int likelySeparatingFace(const Prepared& owner, const Vector3& direction) {
	const std::vector<Vector3>& v = *owner.vertices;
	int best = -1;
	double bestScore = -std::numeric_limits<double>::infinity();
	for (int f : owner.faceList) {
		double score;
		if (owner.planes) {
			const FacePlane& plane = owner.faces[f];
			score = plane.firstNormal.dot(direction) / plane.firstNorm;
		} else {
			const Vector3 n = firstCornersNormal(v, owner.shape->faces[f]);
			score = n.dot(direction) / n.norm();
		}
		if (score > bestScore) {
			bestScore = score;
			best = f;
		}
	}
	return best;
}

struct EdgeAxis {
	bool valid = false;
	// Parallel within the angle tolerance, not exactly: the axis bounds the
	// pair's penetration but is no entrance (its crossing has no stable
	// position).
	bool nearParallel = false;
	double separation = 0;              // [m]
	Vector3 normal = Vector3::UnitZ();  // unit, from A towards B
};

// Separation [m] of the two blocks along unit n (from A towards B): the
// smallest projection of B's corners minus the largest of A's. A lower bound
// of their distance (or minus their overlap along n) for any n.
double projectedSeparation(const Prepared& a, const Prepared& b, const Vector3& n) {
	double highA = -std::numeric_limits<double>::infinity(), lowB = std::numeric_limits<double>::infinity();
	for (int v = 0; v < a.cornerCount(); ++v) highA = std::max(highA, n.dot(a.corner(v)));
	for (int v = 0; v < b.cornerCount(); ++v) lowB = std::min(lowB, n.dot(b.corner(v)));
	return lowB - highA;
}

// Edge axis of edge ea of A and eb of B when the two edges form a face of the
// Minkowski difference and are not exactly parallel (nearParallel when they
// are within the angle tolerance).
// `cba`: arcSide(a, ea, b, first face of eb), after the caller's check that
// the two faces of eb are on opposite sides (arcsCross).
EdgeAxis edgeAxis(const Prepared& a, int ea, const Prepared& b, int eb, double sinTolerance, int cba) {
	EdgeAxis axis;
	if (!arcsCross(a, ea, b, eb, cba)) return axis;
	const EdgeData& ed = a.edges[ea];
	const EdgeData& fd = b.edges[eb];
	const Vector3& da = ed.direction;
	const Vector3& db = fd.direction;
	const Vector3 cross = da.cross(db);
	const double crossNorm = cross.norm();
	if (parallelDirections(da, db, cross, crossNorm, ed.length, fd.length, sinTolerance)) {
		if (!(crossNorm > 0) || parallelDirections(da, db, cross, crossNorm, ed.length, fd.length, 0.0)) return axis;
		// Within the angle tolerance, not exactly parallel. Its normal is
		// ill-conditioned for tiny angles, so its separation is the blocks'
		// full projection on it, valid for any direction.
		Vector3 n = cross / crossNorm;
		if (n.dot(a.edgeStart(ea) - a.centroid) < 0) n = -n;
		axis.valid = true;
		axis.nearParallel = true;
		axis.separation = projectedSeparation(a, b, n);
		axis.normal = n;
		return axis;
	}
	const Vector3& a0 = a.edgeStart(ea);
	const Vector3& a1 = a.edgeEnd(ea);
	const Vector3& b0 = b.edgeStart(eb);
	const Vector3& b1 = b.edgeEnd(eb);
	// da.cross(db).normalized(): Eigen divides by sqrt(squaredNorm()) = norm()
	// when that is > 0, which it is for directions that are not parallel.
	Vector3 n = cross / crossNorm;
	if (n.dot(a0 - a.centroid) < 0) n = -n;
	const Vector3 offset = b0 - a0;
	double separation = n.dot(offset);
	// The round-off test with an upper bound of |offset| first (as in
	// planeDistance): a separation above it is above the exact test's too.
	const double normBound = (std::abs(offset.x()) + std::abs(offset.y()) + std::abs(offset.z())) * (1 + 1e-6);
	const bool clear = std::abs(separation) > kRoundoffRelative * (normBound + ed.length + fd.length);
	if (!clear && std::abs(separation) <= kRoundoffRelative * (offset.norm() + ed.length + fd.length) &&
	    CGAL::orientation(exactPoint(a0), exactPoint(a1), exactPoint(b0), exactPoint(b1)) == CGAL::COPLANAR)
		separation = 0;
	axis.valid = true;
	axis.separation = separation;
	axis.normal = n;
	return axis;
}

// The entrance face among the face axes: largest separation; within
// lengthTolerance of it, the previous entrance face if it is one of them, else
// the larger area, then A before B, then the lower face index (the order of
// `faces`).
const FaceCandidate& chooseFace(const std::vector<FaceCandidate>& faces, const Prepared& a, const Prepared& b,
                                double lengthTolerance, const EntranceFeature& previous) {
	double best = -std::numeric_limits<double>::infinity();
	for (const FaceCandidate& c : faces) best = std::max(best, c.separation);
	const FaceCandidate* chosen = nullptr;
	double chosenArea = 0;
	for (const FaceCandidate& c : faces) {
		if (c.separation < best - lengthTolerance) continue;
		if (c.feature == previous) return c;
		const double area = (c.feature.kind == EntranceFeature::FaceOfA ? a : b).area(c.feature.feature);
		if (!chosen || area > chosenArea * (1 + kAreaTieRelative)) {
			chosen = &c;
			chosenArea = area;
		}
	}
	return *chosen;
}

// ------------------------------------------------------------ sub-contacts

// The stencil's start-of-step normal distance, as linearizeNormalDistance's
// d0 (0 and invalid when S is not positive and finite).
double stencilGap(const ContactStencil& stencil, bool& valid) {
	const double area = stencilArea(stencil.kind, stencil.points);
	const double delta = stencilDeterminant(stencil.points);
	valid = area > 0 && std::isfinite(area);
	if (!valid) return 0;
	return stencil.sigma * delta / area;
}

SubContact vertexFaceContact(bool firstIsA, const Prepared& blockI, int vertex, const Prepared& blockJ, int face) {
	SubContact c;
	c.kind = ContactKind::VertexFace;
	c.firstIsA = firstIsA;
	c.feature1 = vertex;
	c.feature2 = face;
	const FacePlane& plane = blockJ.faces[face];
	const Vector3& p = blockI.corner(vertex);
	c.stencil = vertexFaceStencil(p, blockJ.corner(plane.corners[0]), blockJ.corner(plane.corners[1]),
	                              blockJ.corner(plane.corners[2]));
	bool valid = false;
	c.gap = stencilGap(c.stencil, valid);
	c.normal = plane.normal;
	c.pointI = p;
	c.pointJ = p - c.gap * plane.normal;
	return c;
}

// Gap and normal bounds a caller will require of an edge-edge sub-contact;
// checking them before the closest points saves work, not results.
struct EdgeContactLimits {
	double highestGap = std::numeric_limits<double>::infinity();   // [m]
	double deepestGap = -std::numeric_limits<double>::infinity();  // [m]
	const Vector3* direction = nullptr;  // normal . direction >= minCosine when set
	double minCosine = 0;
};

// Edge-edge sub-contact of edge e1 of block i and e2 of block j, or nothing
// when the edges are parallel or their closest points are not strictly inside
// both segments (more than lengthTolerance from every endpoint), or it fails
// `limits`.
std::optional<SubContact> edgeEdgeContact(bool firstIsA, const Prepared& blockI, int e1, const Prepared& blockJ,
                                          int e2, const DetectionSettings& settings, double sinTolerance,
                                          const EdgeContactLimits& limits = {}) {
	const Vector3& p1 = blockI.edgeStart(e1);
	const Vector3& p2 = blockI.edgeEnd(e1);
	const Vector3& p3 = blockJ.edgeStart(e2);
	const Vector3& p4 = blockJ.edgeEnd(e2);
	const Vector3 da = p2 - p1, db = p4 - p3;
	const Vector3 cross = da.cross(db);
	// The closest points of the two lines must lie strictly inside both
	// segments (checked last below, on edgeEdgeDistance's s and t). Most edge
	// pairs fail that, so it is checked first, on the line parameters
	// edgeEdgeDistance computes by these same expressions: for edges that are
	// not parallel its s, t are these when both lie in [0, 1], and otherwise a
	// value clamped to 0 or 1, which the endpoint test rejects
	// (lengthTolerance > 0). The same pairs are rejected, only sooner.
	// Every test below only rejects, so their order changes no result.
	const Vector3 w = p3 - p1;
	const double sNumerator = w.cross(db).dot(cross), tNumerator = w.cross(da).dot(cross);
	{
		// First without a square root: sLine = sNumerator / nn with nn > 0
		// (nn = 0 gives no rejection here), so a negative numerator gives a
		// negative sLine, or -0 for an underflow, which the endpoint test
		// rejects; and nn is cross.squaredNorm() to within a few DBL_EPSILON
		// (|cross| rounded, then squared), so a numerator above
		// (1 + 1e-12) squaredNorm gives sLine > 1.
		const double bound = (1 + 1e-12) * cross.squaredNorm();
		if (sNumerator < 0 || tNumerator < 0 || sNumerator > bound || tNumerator > bound) return std::nullopt;
	}
	const double la = da.norm(), lb = db.norm();
	const double crossNorm = cross.norm();
	if (parallelDirections(da, db, cross, crossNorm, la, lb, sinTolerance)) return std::nullopt;
	const double tol = settings.lengthTolerance;
	{
		const double nn = crossNorm * crossNorm;
		const double sLine = sNumerator / nn;
		const double tLine = tNumerator / nn;
		if (!(sLine >= 0 && sLine <= 1 && tLine >= 0 && tLine <= 1)) return std::nullopt;
		if (sLine * la <= tol || (1 - sLine) * la <= tol || tLine * lb <= tol || (1 - tLine) * lb <= tol)
			return std::nullopt;
	}
	{
		// The gap limits, on the distance of the two lines before the stencil:
		// the stencil's |gap| is |Delta| / S with S = crossNorm (the same
		// expression) and Delta = da . (w x (p4 - p1)), whose exact value is
		// -w . cross. Each of the two triple products is within 10
		// DBL_EPSILON x (the product of its factors' lengths) of its exact
		// value; `margin` bounds both errors, with 1-norms for lengths and
		// 1e-12 for 10 DBL_EPSILON (a factor of ~450 to spare), so a line
		// distance above a limit's magnitude by more than it means a gap
		// outside that limit.
		const auto norm1 = [](const Vector3& v) { return std::abs(v.x()) + std::abs(v.y()) + std::abs(v.z()); };
		const double w1 = norm1(w);
		const double margin = 1e-12 * norm1(da) * w1 * (w1 + 2 * norm1(db)) / crossNorm;
		const double lineGap = std::abs(w.dot(cross)) / crossNorm;
		if (lineGap - margin > std::max(limits.highestGap, -limits.deepestGap)) return std::nullopt;
	}
	// From block i towards block j: out of i at its edge, into j at its edge.
	const Vector3 reference = blockI.edgeOutward(e1) - blockJ.edgeOutward(e2);
	SubContact c;
	c.stencil = edgeEdgeStencil(p1, p2, p3, p4, reference);
	bool valid = false;
	c.gap = stencilGap(c.stencil, valid);
	if (!valid) return std::nullopt;
	if (c.gap > limits.highestGap || c.gap < limits.deepestGap) return std::nullopt;
	// The stencil's n = -sigma (a x b)/|a x b| points from i to j.
	c.normal = c.stencil.sigma * (cross / crossNorm);  // da.cross(db).normalized(), as in edgeAxis
	if (limits.direction && c.normal.dot(*limits.direction) < limits.minCosine) return std::nullopt;
	const EdgeEdgeResult r =
	    edgeEdgeDistance(p1, p2, p3, p4, reference, settings.lengthTolerance, settings.angleTolerance);
	if (r.parallel || !r.interior) return std::nullopt;
	if (r.s * la <= tol || (1 - r.s) * la <= tol || r.t * lb <= tol || (1 - r.t) * lb <= tol) return std::nullopt;
	c.kind = ContactKind::EdgeEdge;
	c.firstIsA = firstIsA;
	c.feature1 = e1;
	c.feature2 = e2;
	c.pointI = r.closestI;
	c.pointJ = r.closestJ;
	return c;
}

// An edge-edge contact within `merge` [m] of the point of a vertex-face contact
// that pushes the same way (normals within acos(kSameNormalCosine)); a
// crossing whose normal differs is a different contact, even beside a corner
// (two turned logs side by side: a corner just below the other log's bottom
// face, an edge crossing into its side face).
bool besideVertexContact(const SubContact& crossing, const std::vector<SubContact>& found, double merge) {
	for (const SubContact& other : found) {
		if (other.kind != ContactKind::VertexFace) continue;
		if (std::abs(other.normal.dot(crossing.normal)) < kSameNormalCosine) continue;
		if ((other.pointI - crossing.pointI).norm() <= merge || (other.pointI - crossing.pointJ).norm() <= merge)
			return true;
	}
	return false;
}

// The vertex-face contact of corner q of `block` against its own entrance
// face G of `other`, the face whose plane q lies farthest above, when that
// distance is within `reach` [m] and q's projection within `reach` of G;
// appended to `out`. The gap is then at least minus the pair's penetration:
// for q outside `other` it is positive (some face plane separates a point
// from a convex block), for q inside it is minus q's distance to the
// boundary, which a translation of the penetration depth carries q across.
void ownEntranceContact(const Prepared& block, bool blockIsA, int q, const Prepared& other, double reach,
                        std::vector<SubContact>& out) {
	const Vector3& x = block.corner(q);
	int bestFace = -1;
	double bestDistance = -std::numeric_limits<double>::infinity();
	for (int g = 0; g < other.faceCount(); ++g) {
		if (other.internal(g)) continue;
		++*block.tests;
		ensurePlane(other, g);
		const double d = planeDistance(other, g, x);
		if (d > bestDistance) {
			bestDistance = d;
			bestFace = g;
		}
	}
	if (bestFace < 0 || bestDistance > reach) return;
	if (!projectionNearFace(other, bestFace, x, reach)) return;
	out.push_back(vertexFaceContact(blockIsA, block, q, other, bestFace));
}

// Step 3 for a face entrance: face f of block `owner` (block j of every
// vertex-face contact of the other block's corners) entered by block `other`.
// `depthBound` is the pair's separation (<= 0 when they overlap) as step 3
// of detectPairContacts takes it: no sub-contact is deeper than the pair's
// penetration allows (min(depthBound, 0), to the length tolerance; for edge
// crossings min(crossingBound, 0), crossingBound >= depthBound). It is
// f's own separation, the lowest corner's distance from f's plane, only when
// f bounds the pair's penetration (f is the best axis, or kept by
// hysteresis); for the face search of an edge entrance, and for the face an
// edge entrance falls back to, f's plane may lie far inside the other block:
// two crossed logs a few mm apart have face axes a log's width deep, and
// corners and edge crossings that deep below f are no contact of theirs (they
// gave sub-contacts 1 m deep between logs that did not touch).
void faceEntranceContacts(const Prepared& owner, bool ownerIsA, int f, const Prepared& other, double depthBound,
                          double crossingBound, const DetectionSettings& settings, double sinTolerance, Scratch& s,
                          std::vector<SubContact>& out) {
	// Within d0, to the length tolerance: a face is planar only to within it, so
	// a corner touching a face may lie that far off the face's triangle plane.
	const double reach = settings.contactDistance + settings.lengthTolerance;

	// The other block's corners' distances from the face's plane, each
	// computed when first needed.
	std::vector<double>& distances = s.cornerDistances;
	std::vector<char>& ready = s.cornerDistanceReady;
	distances.resize(other.cornerCount());
	ready.assign(other.cornerCount(), 0);
	const auto distance = [&](int v) {
		if (!ready[v]) {
			distances[v] = planeDistance(owner, f, other.corner(v));
			ready[v] = 1;
			++*owner.tests;
		}
		return distances[v];
	};

	// Corners of the other block on the face, none deeper below its plane than
	// the pair's penetration (to the length tolerance): when f bounds the
	// penetration every corner is at least `depthBound` above the plane, so
	// this bound only acts when it does not (an edge entrance's face search, or
	// its fallback face), where a corner below f's plane of a pair that does
	// not overlap lies past another face of f's block (its gap would have the
	// wrong sign).
	const double lowest = std::min(depthBound, 0.0) - settings.lengthTolerance;
	std::vector<int>& used = s.used;
	used.clear();
	for (int v : other.vertexList) {
		if (distance(v) > reach || distance(v) < lowest) continue;
		if (!projectionNearFace(owner, f, other.corner(v), reach)) continue;
		out.push_back(vertexFaceContact(!ownerIsA, other, v, owner, f));
		used.push_back(v);
	}

	// Corners of the face near the other block, against their own entrance face.
	const double merge = std::max(settings.cornerMergeDistance, settings.lengthTolerance);
	for (int q : owner.shape->faces[f]) {
		if (!owner.linkedVertex(q)) continue;
		const Vector3& x = owner.corner(q);
		bool coincident = false;  // with a corner used above
		for (int v : used) {
			if ((other.corner(v) - x).norm() <= merge) {
				coincident = true;
				break;
			}
		}
		if (coincident) continue;
		ownEntranceContact(owner, ownerIsA, q, other, reach, out);
	}

	// Edges of the other block crossing the face's edges, no deeper than the
	// pair's penetration allows (the rule at the top of this file; for
	// crossings `crossingBound`, which near-parallel edge axes may raise).
	const double deepest = std::min(crossingBound, 0.0) - settings.lengthTolerance;
	std::vector<int>& faceEdges = s.faceEdges;
	faceEdges.clear();
	for (int e : owner.edgeList) {
		const auto& ef = owner.shape->edgeFaces[e];
		if (ef[0] == f || ef[1] == f) faceEdges.push_back(e);
	}
	// A crossing beside a vertex contact found above is that corner's contact
	// (two squares offset by a little drift cross each other's edges right
	// beside their corners); a crossing with no vertex contact near it stays.
	// (`merge` is the corner merge distance above.)
	EdgeContactLimits limits;
	limits.highestGap = reach;
	limits.deepestGap = deepest;
	limits.direction = &owner.faces[f].normal;
	limits.minCosine = kEdgeNormalMinCosine;
	const auto& otherEdges = other.shape->edges;
	for (int e : other.edgeList) {
		const double low = std::min(distance(otherEdges[e][0]), distance(otherEdges[e][1]));
		if (low > reach) continue;
		for (int g : faceEdges) {
			++*owner.tests;
			std::optional<SubContact> c =
			    edgeEdgeContact(!ownerIsA, other, e, owner, g, settings, sinTolerance, limits);
			if (!c) continue;
			if (planeDistance(owner, f, c->pointI) > reach) continue;  // crosses far from the face
			if (besideVertexContact(*c, out, merge)) continue;
			out.push_back(*c);
		}
	}
}

// Step 3 for an edge entrance, after its crossing (out[0]): the features the
// best face axis finds within d0 elsewhere. Two blocks touching edge on edge
// near one corner can have a far corner within d0 too (a cube tilting onto
// another: it rocks on the crossing and its far corner comes down); with the
// crossing alone that corner would enter the other block unopposed in the
// step. What the face finds at the crossing itself (the same edge pair, or a
// corner or crossing within the corner merge distance of it) is the crossing's
// contact and is left out. `depthBound` is the edge axis's separation (the
// pair's), `crossingBound` as for faceEntranceContacts.
void otherFeaturesOfEdgeEntrance(const Prepared& a, const Prepared& b, const FaceCandidate& face, double depthBound,
                                 double crossingBound, const DetectionSettings& settings, double sinTolerance,
                                 Scratch& s, std::vector<SubContact>& out) {
	const SubContact crossing = out.front();
	const std::size_t first = out.size();
	if (face.feature.kind == EntranceFeature::FaceOfA)
		faceEntranceContacts(a, true, face.feature.feature, b, depthBound, crossingBound, settings, sinTolerance, s,
		                     out);
	else
		faceEntranceContacts(b, false, face.feature.feature, a, depthBound, crossingBound, settings, sinTolerance, s,
		                     out);
	const double merge = std::max(settings.cornerMergeDistance, settings.lengthTolerance);
	const auto sameAsCrossing = [&](const SubContact& c) {
		if (c.kind == ContactKind::EdgeEdge) {
			const int edgeA = c.firstIsA ? c.feature1 : c.feature2, edgeB = c.firstIsA ? c.feature2 : c.feature1;
			if (edgeA == crossing.feature1 && edgeB == crossing.feature2) return true;
		}
		for (const Vector3* p : {&c.pointI, &c.pointJ})
			if ((*p - crossing.pointI).norm() <= merge || (*p - crossing.pointJ).norm() <= merge) return true;
		return false;
	};
	out.erase(std::remove_if(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(), sameAsCrossing), out.end());
}

// Step 3 for an edge entrance whose two edges do not cross strictly inside,
// after the best face's contacts (the fallback): the ends of the two edges,
// each against its own entrance face of the other block (ownEntranceContact).
// The edge axis is the pair's best, so the blocks' closest features are then
// a corner at an end of one edge and the other edge (or its end); the best
// face, which the edge axis beat, may lie far from them (crossed slender
// blocks: a block's width deep), so its search alone can find nothing. Pairs
// within d0 were left without any sub-contact (9 of the oracle's 100,000
// random near pairs; the second pair of ghost_pairs.json, 6.5 mm apart), and a
// corner coming down on an edge would have met no contact. An end that already
// has a vertex-face contact, or lies within the corner merge distance of a
// contact point found, is that contact.
void cornersOfEdgeEntrance(const Prepared& a, int edgeA, const Prepared& b, int edgeB,
                           const DetectionSettings& settings, std::vector<SubContact>& out) {
	const double reach = settings.contactDistance + settings.lengthTolerance;
	const double merge = std::max(settings.cornerMergeDistance, settings.lengthTolerance);
	for (int side = 0; side < 2; ++side) {
		const Prepared& block = side == 0 ? a : b;
		const Prepared& other = side == 0 ? b : a;
		const bool blockIsA = side == 0;
		for (int q : block.shape->edges[side == 0 ? edgeA : edgeB]) {
			if (!block.linkedVertex(q)) continue;
			const Vector3& x = block.corner(q);
			const bool known = std::any_of(out.begin(), out.end(), [&](const SubContact& c) {
				if (c.kind == ContactKind::VertexFace && c.firstIsA == blockIsA && c.feature1 == q) return true;
				return (c.pointI - x).norm() <= merge || (c.pointJ - x).norm() <= merge;
			});
			if (!known) ownEntranceContact(block, blockIsA, q, other, reach, out);
		}
	}
}

// ------------------------------------------------------------ structural type

enum class FeatureKind { Vertex, Edge, Face };
struct Feature {
	FeatureKind kind = FeatureKind::Face;
	int index = -1;  // corner (Vertex) or edge (Edge)
};

// The smallest feature of `block` within `tolerance` [m] of all the points: one
// corner, else one edge, else a face.
//
// Most corners and edges are far from the points; a coordinate difference
// rejects them without a square root. The rejections are those of the
// distances themselves: a computed norm is at least any |component| of its
// vector to within 2 DBL_EPSILON relative, and a computed segment distance is
// at least x's distance from the segment's bounding box along an axis, to
// within a few DBL_EPSILON of the coordinates (the closest point is rounded);
// the margins 1e-12 cover both.
Feature featureOf(const Prepared& block, const std::vector<Vector3>& points, double tolerance) {
	Feature out;
	if (points.empty()) return out;
	const double reach = tolerance * (1 + 1e-12);
	double bestCorner = std::numeric_limits<double>::infinity();
	for (int v = 0; v < block.cornerCount(); ++v) {
		const Vector3& c = block.corner(v);
		bool far = false;
		for (const Vector3& x : points) far = far || (x - c).cwiseAbs().maxCoeff() > reach;
		if (far) continue;
		double worst = 0;
		for (const Vector3& x : points) worst = std::max(worst, (x - c).norm());
		if (worst <= tolerance && worst < bestCorner) {
			bestCorner = worst;
			out = {FeatureKind::Vertex, v};
		}
	}
	if (out.kind == FeatureKind::Vertex) return out;
	// The largest coordinate magnitude of the points and corners bounds the
	// rounding of a closest point's coordinates (and of the box's bounds).
	double largest = 0;
	for (const Vector3& x : points) largest = std::max(largest, x.cwiseAbs().maxCoeff());
	for (int v = 0; v < block.cornerCount(); ++v) largest = std::max(largest, block.corner(v).cwiseAbs().maxCoeff());
	const double margin = reach + 3e-12 * largest;
	double bestEdge = std::numeric_limits<double>::infinity();
	for (int e = 0; e < block.edgeCount(); ++e) {
		const Vector3& p = block.edgeStart(e);
		const Vector3& q = block.edgeEnd(e);
		const Vector3 lower = p.cwiseMin(q).array() - margin, upper = p.cwiseMax(q).array() + margin;
		bool far = false;
		for (const Vector3& x : points) far = far || (x.array() > upper.array()).any() || (x.array() < lower.array()).any();
		if (far) continue;
		double worst = 0;
		for (const Vector3& x : points) worst = std::max(worst, segmentDistance(x, p, q));
		if (worst <= tolerance && worst < bestEdge) {
			bestEdge = worst;
			out = {FeatureKind::Edge, e};
		}
	}
	return out;
}

ContactType structuralType(const Prepared& a, const Feature& fa, const Prepared& b, const Feature& fb,
                           double sinTolerance) {
	const FeatureKind ka = fa.kind, kb = fb.kind;
	auto either = [&](FeatureKind x, FeatureKind y) { return (ka == x && kb == y) || (ka == y && kb == x); };
	if (either(FeatureKind::Vertex, FeatureKind::Vertex)) return ContactType::VertexVertex;
	if (either(FeatureKind::Vertex, FeatureKind::Edge)) return ContactType::VertexEdge;
	if (either(FeatureKind::Vertex, FeatureKind::Face)) return ContactType::VertexFace;
	if (either(FeatureKind::Edge, FeatureKind::Face)) return ContactType::EdgeFace;
	if (either(FeatureKind::Face, FeatureKind::Face)) return ContactType::FaceFace;
	const Vector3 da = a.edgeEnd(fa.index) - a.edgeStart(fa.index);
	const Vector3 db = b.edgeEnd(fb.index) - b.edgeStart(fb.index);
	return parallelDirections(da, db, sinTolerance) ? ContactType::EdgeEdgeParallel : ContactType::EdgeEdgeCrossing;
}

// Corners of `block` within `tolerance` of its extreme along `direction`.
void supportCorners(const Prepared& block, const Vector3& direction, double tolerance, std::vector<Vector3>& out) {
	double extreme = -std::numeric_limits<double>::infinity();
	for (int v = 0; v < block.cornerCount(); ++v) extreme = std::max(extreme, direction.dot(block.corner(v)));
	out.clear();
	for (int v = 0; v < block.cornerCount(); ++v)
		if (direction.dot(block.corner(v)) >= extreme - tolerance) out.push_back(block.corner(v));
}

// Makes s.identity hold 0 .. n - 1 at least, for both blocks of a pair before
// either's lists point into it.
void ensureIdentity(Scratch& s, const Prepared& a, const Prepared& b) {
	const int largest = std::max({a.cornerCount(), a.edgeCount(), a.faceCount(), b.cornerCount(), b.edgeCount(),
	                              b.faceCount()});
	std::vector<int>& identity = s.identity;
	if (static_cast<int>(identity.size()) >= largest) return;
	identity.resize(largest);
	for (int i = 0; i < largest; ++i) identity[i] = i;
}

// The sub-units block `p` (slot 0: A, 1: B) offers the pair: the linked ones,
// or all (after ensureIdentity). Also points p.tests at the pair's counter.
void prepareSubUnits(Prepared& p, const LinkedSubUnits* linked, int slot, Scratch& s, long& tests) {
	p.tests = &tests;
	const int corners = p.cornerCount(), edges = p.edgeCount(), faces = p.faceCount();
	const std::vector<int>& identity = s.identity;
	if (!linked) {
		p.vertexList = {identity.data(), corners};
		p.edgeList = {identity.data(), edges};
		p.faceList = {identity.data(), faces};
		p.vertexLinked = nullptr;
		return;
	}
	const auto list = [](const SubUnitList& v) { return Indices{v.begin(), static_cast<int>(v.size())}; };
	p.vertexList = list(linked->vertices[slot]);
	p.edgeList = list(linked->edges[slot]);
	p.faceList = list(linked->faces[slot]);
	std::vector<char>& vertexMark = s.vertexLinked[slot];
	vertexMark.assign(corners, 0);
	for (int v : linked->vertices[slot]) vertexMark[v] = 1;
	p.vertexLinked = vertexMark.data();
}

// Whether the pair's previous entrance feature (if any) is among the sub-units
// the pair may use.
bool previousLinked(const Prepared& a, const Prepared& b, const EntranceFeature& previous) {
	const auto has = [](const Indices& list, int x) { return std::binary_search(list.begin(), list.end(), x); };
	switch (previous.kind) {
		case EntranceFeature::FaceOfA: return has(a.faceList, previous.feature);
		case EntranceFeature::FaceOfB: return has(b.faceList, previous.feature);
		case EntranceFeature::EdgePair: return has(a.edgeList, previous.feature) && has(b.edgeList, previous.other);
		case EntranceFeature::None: return true;
	}
	return true;
}

}  // namespace

void BlockPlanes::compute(const PolyhedronTopology& shape, const std::vector<Vector3>& vertices) {
	const int faceCount = static_cast<int>(shape.faces.size());
	faces.resize(faceCount);
	for (int f = 0; f < faceCount; ++f) {
		FacePlane& plane = faces[f];
		const FaceTriangle triangle = buildFacePlane(vertices, shape.faces[f], plane);
		plane.firstNormal = triangle.firstCross;  // firstCornersNormal
		plane.firstNorm = triangle.firstCrossNorm;
	}
	const int edgeCount = static_cast<int>(shape.edges.size());
	edges.resize(edgeCount);
	for (int e = 0; e < edgeCount; ++e) buildEdge(vertices, shape, faces.data(), e, edges[e]);
	cornerBounds(vertices, lower, upper);
}

const char* contactTypeName(ContactType type) {
	switch (type) {
		case ContactType::VertexVertex: return "VV";
		case ContactType::VertexEdge: return "VE";
		case ContactType::VertexFace: return "VF";
		case ContactType::EdgeEdgeCrossing: return "EE";
		case ContactType::EdgeEdgeParallel: return "EEp";
		case ContactType::EdgeFace: return "EF";
		case ContactType::FaceFace: return "FF";
	}
	return "?";
}

bool detectPairContacts(const BlockGeometry& blockA, const BlockGeometry& blockB, const DetectionSettings& settings,
                        PairContacts& out, const EntranceFeature& previous, const LinkedSubUnits* linked,
                        NarrowPhaseWork* work) {
	const double d0 = settings.contactDistance, tol = settings.lengthTolerance;
	NarrowPhaseWork ownWork;
	if (!work) work = &ownWork;
	long& tests = work->subUnitTests;

	// Bounding boxes widened by d0.
	Prepared a = prepareBounds(blockA);
	Prepared b = prepareBounds(blockB);
	for (int k = 0; k < 3; ++k) {
		if (b.lower(k) > a.upper(k) + d0 || a.lower(k) > b.upper(k) + d0) return false;
	}
	Scratch& s = scratch();
	prepareFaces(a, s, 0);
	prepareFaces(b, s, 1);
	ensureIdentity(s, a, b);
	prepareSubUnits(a, linked, 0, s, tests);
	prepareSubUnits(b, linked, 1, s, tests);
	const double sinTolerance = std::sin(settings.angleTolerance);

	// 1. Face axes, stopping at the first one farther than d0. Any axis
	// farther than d0 rejects the pair, so the likeliest separating face of
	// each block (along the line of centroids) is tried first.
	//
	// A face axis far below the best face found so far is neither the
	// entrance nor a rejection, and its exact separation is not needed: with
	// `known` the largest separation of an entrance-eligible (non-internal)
	// face computed in full so far, a face's corners stop once one lies below
	// floor = known - hysteresis (faceSeparation), and the face is listed with
	// that corner's distance p, floor > p >= its separation. Every use of the
	// list then decides as with the separation (rounding is monotone:
	// fl(x - y) grows with x and falls with y; hysteresis >= tol; and known <=
	// bestFace <= best below): p cannot reject (p < known <= d0, and a face
	// with a corner below d0 does not reject either), cannot raise
	// deepestBound or bestFace (p < known, itself in both), is not the kept
	// previous face (p < fl(known - hysteresis) <= fl(best - hysteresis)) and
	// is passed over by chooseFace (p < fl(bestFace - tol)), as is any
	// separation below p. A face that rejects has every corner above d0 >=
	// known, hence above the floor, and is computed in full.
	const double hysteresis = std::max(settings.hysteresis, tol);
	double known = -std::numeric_limits<double>::infinity();
	{
		const Vector3 towardsB = b.centroid - a.centroid;
		const int fa = likelySeparatingFace(a, towardsB);
		if (fa >= 0) {
			const double sep = faceSeparation(a, fa, b);
			if (sep > d0) return false;
			if (!a.internal(fa)) known = sep;
		}
		const int fb = likelySeparatingFace(b, -towardsB);
		if (fb >= 0) {
			const double sep = faceSeparation(b, fb, a);
			if (sep > d0) return false;
			if (!b.internal(fb)) known = std::max(known, sep);
		}
	}
	std::vector<FaceCandidate>& faces = s.candidates;
	faces.clear();
	// Largest separation over every axis tested, internal faces included: minus
	// the pair's penetration depth, or less.
	double deepestBound = -std::numeric_limits<double>::infinity();
	// An internal face still rejects (its plane separates), but is no entrance.
	for (int f : a.faceList) {
		const double sep = faceSeparation(a, f, b, known - hysteresis);
		if (sep > d0) return false;
		deepestBound = std::max(deepestBound, sep);
		if (a.internal(f)) continue;
		faces.push_back({{EntranceFeature::FaceOfA, f, -1}, sep});
		known = std::max(known, sep);
	}
	for (int f : b.faceList) {
		const double sep = faceSeparation(b, f, a, known - hysteresis);
		if (sep > d0) return false;
		deepestBound = std::max(deepestBound, sep);
		if (b.internal(f)) continue;
		faces.push_back({{EntranceFeature::FaceOfB, f, -1}, sep});
		known = std::max(known, sep);
	}
	double bestFace = -std::numeric_limits<double>::infinity();
	for (const FaceCandidate& c : faces) bestFace = std::max(bestFace, c.separation);

	// Edge axes of the Minkowski difference's faces.
	prepareEdges(a, s, 0);
	prepareEdges(b, s, 1);
	EdgeAxis bestEdge, previousEdge;
	int bestEdgeA = -1, bestEdgeB = -1;
	// Largest separation along the axes of edge pairs parallel within the
	// angle tolerance (not exactly): no entrance and no rejection, as before,
	// but a bound of the pair's penetration (step 3).
	double nearParallelBest = -std::numeric_limits<double>::infinity();
	// The faces of B at its edges (their planes are built: prepareEdges).
	std::vector<int>& bFaces = s.edgeFacesB;
	std::vector<int>& side = s.arcSides;
	{
		std::vector<char>& mark = s.faceMark;
		mark.assign(b.faceCount(), 0);
		bFaces.clear();
		for (int eb : b.edgeList) {
			if (b.internalEdge(eb)) continue;
			for (int g : b.shape->edgeFaces[eb]) {
				if (mark[g]) continue;
				mark[g] = 1;
				bFaces.push_back(g);
			}
		}
		side.resize(b.faceCount());
	}
	for (int ea : a.edgeList) {
		if (a.internalEdge(ea)) continue;
		for (int g : bFaces) side[g] = arcSide(a, ea, b, g);
		for (int eb : b.edgeList) {
			if (b.internalEdge(eb)) continue;
			++tests;
			// Gauss-map arcs that cannot cross (arcsCross's first test).
			const auto& fb = b.shape->edgeFaces[eb];
			if (!(side[fb[0]] * side[fb[1]] < 0)) continue;
			const EdgeAxis axis = edgeAxis(a, ea, b, eb, sinTolerance, side[fb[0]]);
			if (!axis.valid) continue;
			if (axis.nearParallel) {
				nearParallelBest = std::max(nearParallelBest, axis.separation);
				continue;
			}
			if (axis.separation > d0) return false;
			deepestBound = std::max(deepestBound, axis.separation);
			if (previous.kind == EntranceFeature::EdgePair && previous.feature == ea && previous.other == eb)
				previousEdge = axis;
			if (!bestEdge.valid || axis.separation > bestEdge.separation) {
				bestEdge = axis;
				bestEdgeA = ea;
				bestEdgeB = eb;
			}
		}
	}
	const double best = bestEdge.valid ? std::max(bestFace, bestEdge.separation) : bestFace;
	// Linked sub-units hold every contact feature while the pair penetrates by
	// at most d0 / 2; the linked axes bound the depth from above (the full
	// search's best axis separates at least as much), so a deeper bound sends
	// the pair to the full search.
	if (linked && !(deepestBound >= -0.5 * d0)) {
		++work->fullSearches;
		return detectPairContacts(blockA, blockB, settings, out, previous, nullptr, work);
	}

	// 2. The entrance feature.
	EntranceFeature entrance;
	double separation = 0;
	bool keptPrevious = false;  // the previous entrance, kept by hysteresis
	if (previous.kind == EntranceFeature::EdgePair && previousEdge.valid &&
	    previousEdge.separation >= best - hysteresis) {
		entrance = previous;
		separation = previousEdge.separation;
		keptPrevious = true;
	} else {
		const FaceCandidate* previousFace = nullptr;
		for (const FaceCandidate& c : faces)
			if (c.feature == previous) previousFace = &c;
		if (previousFace && previousFace->separation >= best - hysteresis) {
			entrance = previousFace->feature;
			separation = previousFace->separation;
			keptPrevious = true;
		} else if (bestEdge.valid && bestEdge.separation > bestFace + tol) {
			entrance = {EntranceFeature::EdgePair, bestEdgeA, bestEdgeB};
			separation = bestEdge.separation;
		} else {
			const FaceCandidate& c = chooseFace(faces, a, b, tol, previous);
			entrance = c.feature;
			separation = c.separation;
		}
	}

	// The same bound holds for the entrance itself, which may be the previous
	// one kept by hysteresis a little deeper than the best axis; and a
	// previous entrance that is not linked could have been kept by the full
	// search: both go to the full search too.
	if (linked && (!(separation >= -0.5 * d0) || !previousLinked(a, b, previous))) {
		++work->fullSearches;
		return detectPairContacts(blockA, blockB, settings, out, previous, nullptr, work);
	}

	// 3. Sub-contacts, into `out` as into a new PairContacts, but `contacts`
	// keeps its capacity (World reuses its results from chunk to chunk).
	// No sub-contact may be deeper than the pair's penetration (the rule at
	// the top of this file); `depthBound` is the entrance axis's separation,
	// the pair's best axis (or the previous entrance, kept while within
	// `hysteresis` of it). It stays the edge axis's when an edge entrance falls
	// back to the best face below. That face's own separation bounds nothing:
	// the edge axis beat it by more than lengthTolerance, and for crossed
	// slender blocks a face axis lies a block's width deep while the blocks are
	// mm apart. Taking the face's separation as the bound, as before, let
	// corners and crossings that deep count as contacts: the ghosts of the
	// 50,000-block deposit (an edge crossing 0.25 m deep and a corner 2.6 mm
	// deep between blocks 5.65 and 6.5 mm apart, ghost_pairs.json;
	// `GhostPairsOfTheDepositHaveNoNegativeGap`), 13 of the oracle's 100,000
	// random near pairs, and 257 of 16,613 calls with a previous entrance.
	// An edge pair parallel within the angle tolerance is no entrance, but
	// its axis bounds the penetration as well: when it separates the blocks
	// more than the entrance, it bounds the edge crossings (a box lying along
	// a slender block, edge along edge 0.01 rad apart: the entrance crossing of
	// two other edges was 6.12 mm deep where the blocks overlapped by 5.84 mm;
	// 1 of 2 million random near pairs of the oracle). Not the corners: the
	// contact of two such edges is the vertex contacts at their ends, measured
	// along the entrance face's normal, which lie deeper than the overlap
	// across the edges (a bar resting edge on edge 1e-4 rad from parallel
	// sank 0.13 mm into the other, tests/py/test_hard_cases.py, when its
	// corners were bound by it).
	// The bound is the largest separation over every axis tested
	// (deepestBound: faces, internal ones too, and the edge pairs that are not
	// near-parallel), never the entrance's own when that lies deeper: a
	// previous entrance kept by hysteresis may lie up to `hysteresis` (0.1 d0)
	// deeper than the best axis, and bounding by it let corners that deep below
	// its plane count as contacts. In a pile of 200 cubes at E = 1e11 Pa a cube
	// landing on another was given a corner contact 0.43 mm deep while the
	// cubes overlapped by 1.8 um: 363 kJ in its penalty spring, 37 times the
	// cube's kinetic energy (core 90eae68, the account's contactChanges).
	const double depthBound = std::max(separation, deepestBound);
	const double crossingBound = std::max(depthBound, nearParallelBest);
	std::optional<std::array<int, 2>> fallbackEdges;  // the edge entrance's edges, when it falls back
	out.normal = Vector3::UnitZ();  // the default, kept when no entrance sets it
	out.contacts.clear();
	if (entrance.kind == EntranceFeature::EdgePair) {
		EdgeContactLimits limits;  // the crossing, too, no deeper than the bound
		limits.deepestGap = std::min(crossingBound, 0.0) - tol;
		std::optional<SubContact> c =
		    edgeEdgeContact(true, a, entrance.feature, b, entrance.other, settings, sinTolerance, limits);
		if (c) {
			out.normal = (previousEdge.valid && entrance == previous) ? previousEdge.normal : bestEdge.normal;
			out.contacts.push_back(*c);
			otherFeaturesOfEdgeEntrance(a, b, chooseFace(faces, a, b, tol, previous), depthBound, crossingBound,
			                            settings, sinTolerance, s, out.contacts);
		} else {
			// The edges do not cross strictly inside (a corner meets an edge),
			// or their crossing is deeper than the bound: the best face is the
			// entrance, its separation the pair's reported one, but the depth
			// bound stays the edge axis's.
			fallbackEdges = {entrance.feature, entrance.other};
			const FaceCandidate& f = chooseFace(faces, a, b, tol, previous);
			entrance = f.feature;
			separation = f.separation;
		}
	}
	if (entrance.kind == EntranceFeature::FaceOfA) {
		out.normal = a.faces[entrance.feature].normal;
		faceEntranceContacts(a, true, entrance.feature, b, depthBound, crossingBound, settings, sinTolerance, s,
		                     out.contacts);
	} else if (entrance.kind == EntranceFeature::FaceOfB) {
		out.normal = -b.faces[entrance.feature].normal;
		faceEntranceContacts(b, false, entrance.feature, a, depthBound, crossingBound, settings, sinTolerance, s,
		                     out.contacts);
	}
	if (fallbackEdges) cornersOfEdgeEntrance(a, (*fallbackEdges)[0], b, (*fallbackEdges)[1], settings, out.contacts);
	// A face entrance that found nothing, among faces tied with the best
	// (within lengthTolerance): the next tied face that finds something is the
	// entrance. Two halves of a nearly planar side tie, and the one of larger
	// area may not be the one the other block's corners lie over: a pair 9.2
	// mm apart and one overlapping by 0.38 mm had no sub-contact at all (2 of
	// 2 million random near pairs of the oracle).
	if (out.contacts.empty() && entrance.kind != EntranceFeature::EdgePair) {
		for (const FaceCandidate& c : faces) {
			if (c.separation < bestFace - tol || c.feature == entrance) continue;
			if (c.feature.kind == EntranceFeature::FaceOfA)
				faceEntranceContacts(a, true, c.feature.feature, b, depthBound, crossingBound, settings, sinTolerance,
				                     s, out.contacts);
			else
				faceEntranceContacts(b, false, c.feature.feature, a, depthBound, crossingBound, settings, sinTolerance,
				                     s, out.contacts);
			if (out.contacts.empty()) continue;
			entrance = c.feature;
			separation = c.separation;
			out.normal = entrance.kind == EntranceFeature::FaceOfA ? a.faces[entrance.feature].normal
			                                                        : Vector3(-b.faces[entrance.feature].normal);
			break;
		}
	}
	// A previous entrance kept by hysteresis whose contacts all lie deeper
	// than the pair's penetration (or beyond d0) holds nothing: the pair takes
	// the entrance a first contact would (no previous), so that a pair within
	// d0 keeps its sub-contacts.
	if (out.contacts.empty() && keptPrevious)
		return detectPairContacts(blockA, blockB, settings, out, EntranceFeature{}, linked, work);
	out.entrance = entrance;
	out.separation = separation;

	// 4. Structural type from the contact points of the sub-contacts.
	const double featureTolerance = d0 + tol;
	std::vector<Vector3>& pointsA = s.pointsA;
	std::vector<Vector3>& pointsB = s.pointsB;
	pointsA.clear();
	pointsB.clear();
	for (const SubContact& c : out.contacts) {
		pointsA.push_back(c.firstIsA ? c.pointI : c.pointJ);
		pointsB.push_back(c.firstIsA ? c.pointJ : c.pointI);
	}
	if (out.contacts.empty()) {
		supportCorners(a, out.normal, featureTolerance, pointsA);
		supportCorners(b, -out.normal, featureTolerance, pointsB);
	}
	out.type = structuralType(a, featureOf(a, pointsA, featureTolerance), b, featureOf(b, pointsB, featureTolerance),
	                          sinTolerance);
	return true;
}

std::optional<PairContacts> detectPairContacts(const BlockGeometry& blockA, const BlockGeometry& blockB,
                                               const DetectionSettings& settings, const EntranceFeature& previous,
                                               const LinkedSubUnits* linked, NarrowPhaseWork* work) {
	PairContacts out;
	if (!detectPairContacts(blockA, blockB, settings, out, previous, linked, work)) return std::nullopt;
	return out;
}

}  // namespace dda
