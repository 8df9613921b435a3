#include "SeparatingAxes.hpp"

#include <cmath>

namespace dda::narrow {

namespace {

// A face faces an internal face of the other block (searchFaceAxes) when
// their outward normals are opposed within about 8 degrees: a block turned
// that little against a seam still lies on the neighbour's side of it.
constexpr double kFacingInternalCosine = 0.99;

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
	    exactOrientation(a0, a1, b0, b1) == 0)
		separation = 0;
	axis.valid = true;
	axis.separation = separation;
	axis.normal = n;
	return axis;
}

}  // namespace

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
bool searchFaceAxes(const Prepared& a, const Prepared& b, double d0, double hysteresis,
                    std::vector<FaceCandidate>& faces, AxisSearch& axes) {
	double known = -std::numeric_limits<double>::infinity();
	const auto likelyFace = [&](const Prepared& owner, const Prepared& other, const Vector3& direction) {
		const int f = likelySeparatingFace(owner, direction);
		if (f < 0) return true;
		const double sep = faceSeparation(owner, f, other);
		if (sep > d0) return false;
		if (!owner.internal(f)) known = std::max(known, sep);
		return true;
	};
	const Vector3 towardsB = b.centroid - a.centroid;
	if (!likelyFace(a, b, towardsB) || !likelyFace(b, a, -towardsB)) return false;
	faces.clear();
	// An internal face still rejects (its plane separates), but is no entrance.
	// Nor is a face of one block that faces an internal face of the other
	// (opposed normals within kFacingInternalCosine): it can separate the
	// pair only from the far side of that internal face's plane, where the
	// flush neighbour covering the face (a fixed block, or another part of
	// the same concave block) stands between them and its own pair holds the
	// block. Taken as the entrance, its sub-contacts measured the other's
	// seam corners and edges across it: a cube sliding over the seam of a
	// free two-part slab met the seam edge as a step (1.1e5 N, its speed
	// 1.0 -> 0.34 m/s; tests/py/blocks/test_concave_blocks.py). The rule only
	// leaves contacts out (no force, no work); the face still rejects.
	const auto facesInternal = [&](const Prepared& owner, int f, const Prepared& other) {
		if (!other.internalFaces) return false;
		ensurePlane(owner, f);
		for (int g = 0; g < other.faceCount(); ++g) {
			if (!other.internal(g)) continue;
			ensurePlane(other, g);
			if (owner.faces[f].normal.dot(other.faces[g].normal) <
			    -kFacingInternalCosine * owner.faces[f].normal.norm() * other.faces[g].normal.norm())
				return true;
		}
		return false;
	};
	const auto faceAxes = [&](const Prepared& owner, const Prepared& other, EntranceFeature::Kind kind) {
		for (int f : owner.faceList) {
			const double sep = faceSeparation(owner, f, other, known - hysteresis);
			if (sep > d0) return false;
			axes.deepestBound = std::max(axes.deepestBound, sep);
			if (owner.internal(f) || facesInternal(owner, f, other)) continue;
			faces.push_back({{kind, f, -1}, sep});
			known = std::max(known, sep);
		}
		return true;
	};
	if (!faceAxes(a, b, EntranceFeature::FaceOfA) || !faceAxes(b, a, EntranceFeature::FaceOfB)) return false;
	for (const FaceCandidate& c : faces) axes.bestFace = std::max(axes.bestFace, c.separation);
	return true;
}

bool searchEdgeAxes(const Prepared& a, const Prepared& b, double d0, double sinTolerance,
                    const EntranceFeature& previous, Scratch& s, AxisSearch& axes) {
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
			++*a.tests;
			// Gauss-map arcs that cannot cross (arcsCross's first test).
			const auto& fb = b.shape->edgeFaces[eb];
			if (!(side[fb[0]] * side[fb[1]] < 0)) continue;
			const EdgeAxis axis = edgeAxis(a, ea, b, eb, sinTolerance, side[fb[0]]);
			if (!axis.valid) continue;
			if (axis.nearParallel) {
				axes.nearParallelBest = std::max(axes.nearParallelBest, axis.separation);
				continue;
			}
			if (axis.separation > d0) return false;
			axes.deepestBound = std::max(axes.deepestBound, axis.separation);
			if (previous.kind == EntranceFeature::EdgePair && previous.feature == ea && previous.other == eb)
				axes.previousEdge = axis;
			if (!axes.bestEdge.valid || axis.separation > axes.bestEdge.separation) {
				axes.bestEdge = axis;
				axes.bestEdgeA = ea;
				axes.bestEdgeB = eb;
			}
		}
	}
	return true;
}

}  // namespace dda::narrow
