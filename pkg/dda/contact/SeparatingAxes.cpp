#include "SeparatingAxes.hpp"

#include <cmath>

namespace dda::narrow {

namespace {

// A face faces an internal face of the other block (searchFaceAxes) when
// their outward normals are opposed within about 8 degrees: a block turned
// that little against a seam still lies on the neighbour's side of it.
constexpr double kFacingInternalCosine = 0.99;

// Do the Gauss-map arcs of edge ea of A (A, B its faces' outward normals)
// and of edge eb of B (C, D: minus its faces' normals) cross (strictly)?
// With A . (D x C) = adc, B . (D x C) = bdc, C . (B x A) = cba and
// D . (B x A) = dba, exactly when cba dba < 0, adc bdc < 0 and cba bdc > 0
// (Gregorius, "The separating axis test between convex polyhedra", GDC
// 2013). Each sign is a triple product of unit normals decided exactly
// (unitOrientation: a double filter, CGAL below its round-off bound). The
// first two depend on ea and one face of B, the last two on eb and one face
// of A, so searchEdgeAxes computes each once per (edge, face of the other
// block) instead of per edge pair (signOfTriple below, the same expression
// and the same exact fallback as unitOrientation).
inline int filteredSign(double approx) {
	return (approx > kUnitTripleRoundoff) - (approx < -kUnitTripleRoundoff);  // 0: not settled
}
inline int signOfTriple(const Vector3& x, const Vector3& y, const Vector3& z, const Vector3& yz) {
	const int sign = filteredSign(x.dot(yz));  // x . (y x z), yz = y x z
	return sign != 0 ? sign : unitOrientationExact(x, y, z);
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
	const double bound = planeRoundoffBound(owner, f, other.lower, other.upper);
	double separation = std::numeric_limits<double>::infinity();
	for (int v = 0; v < other.cornerCount(); ++v) {
		separation = std::min(separation, planeDistanceInBox(owner, f, other.corner(v), bound));
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
// Called for the edge pairs whose Gauss-map arcs cross (searchEdgeAxes).
EdgeAxis edgeAxis(const Prepared& a, int ea, const Prepared& b, int eb, double sinTolerance) {
	EdgeAxis axis;
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
	// 1.0 -> 0.34 m/s; tests/py/blocks/test_concave_blocks.py). The face ties
	// with the internal face it opposes (for opposed normals both axes are the
	// blocks' projected separation on that line), so it is the entrance
	// whenever that axis separates the pair the most: a cube sunk e into a
	// two-part slab, its front face within d0 before the seam or less than e
	// past it, had the seam edge's crossings with normals along the slab
	// (tests/cpp/contact/test_internal_face_rules.cpp); a frictionless block
	// crossing a flush joint of two fixed blocks at 5 m/s kept 26% of its
	// kinetic energy (tests/py/contact/test_flush_joint.py). The rule only
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

// The edge pairs whose Gauss-map arcs cross, by the signs of arcsCross's
// four triple products (above), each computed once per (edge, face of the
// other block) in a table: cba, dba per face g of B for the current edge of
// A (side[g] = sign of -n_g . arc(ea)), adc, bdc per face f of A and edge
// of B (rows of faceSigns: sign of n_f . arc(eb)). The same expressions and
// exact fallback as when each pair computed them (unitOrientation's filter
// written without branches), so each pair gets the same verdict; the pairs
// that cross are listed in order (their positions in s.edgesB), written
// and kept by the test's value rather than by a branch, and their axes
// computed in the same order as before.
//
// Edges of internal faces (a face shared with another part of a concave
// block, or covered by a flush fixed neighbour) give axes as every edge does,
// but no entrance: like an internal face, such an axis rejects the pair and
// bounds its penetration (axes.deepestBound), and is never bestEdge. The
// two blocks of a pair are convex whatever their neighbours, and the axis of
// an edge pair whose arcs cross is a face of their Minkowski difference: left
// out, the largest separation can miss the one that separates them, and the
// depth bound of step 3 then lets through sub-contacts as deep as a wrong
// axis says the blocks overlap. A roof's part lying across another roof's
// ridge (tests/cpp/contact/test_contact_coverage.cpp, roofs at E = 1e8 Pa,
// seed 3) was 1.8 cm from the part it met along the axis of that ridge (an
// edge of the seam face) and another part's corner, 3.2 cm outside the
// whole roof, took a gap of -9.2 cm on a face whose plane runs on past the
// ridge: 20 such corner contacts in the oracle's roofs and concave piles
// (seeds 3 and 17), none after (and the closed form of
// InternalEdgesBoundThePenetrationOfAPartAcrossItsRidge). The axis only removes what no overlap measures: a rejected pair
// has no contact, and a sub-contact below minus the true penetration would
// still have a negative gap after a translation that separates the blocks.
// Removing a contact leaves no spring, so it creates no energy.
namespace {
// searchEdgeAxes' first part: the faces of B at its usable edges (their
// planes are built: prepareEdges), minus their normals (C, D), and those
// edges with their two faces, in edgeList order (s.edgeFacesB,
// s.inwardNormalsB, s.edgesB).
void gatherEdgesOfB(const Prepared& b, Scratch& s) {
	std::vector<int>& bFaces = s.edgeFacesB;
	std::vector<Vector3>& inward = s.inwardNormalsB;
	std::vector<std::array<int, 3>>& bEdges = s.edgesB;
	std::vector<char>& mark = s.faceMark;
	mark.assign(b.faceCount(), 0);
	bFaces.clear();
	inward.clear();
	bEdges.clear();
	for (int eb : b.edgeList) {
		const auto& fb = b.shape->edgeFaces[eb];
		bEdges.push_back({eb, fb[0], fb[1]});
		for (int g : fb) {
			if (mark[g]) continue;
			mark[g] = 1;
			bFaces.push_back(g);
			inward.push_back(-b.faces[g].normal);
		}
	}
}

// Its second: adc, bdc, per face of A at a usable edge of A (row
// s.faceRows[f]), the signs of n_f . (D x C) for each of the `usable` edges
// of B (s.faceSigns).
void faceSignsOfA(const Prepared& a, const Prepared& b, int usable, Scratch& s) {
	std::vector<int>& faceRow = s.faceRows;
	std::vector<int>& faceSigns = s.faceSigns;
	const std::vector<std::array<int, 3>>& bEdges = s.edgesB;
	faceRow.assign(a.faceCount(), -1);
	int rows = 0;
	for (int ea : a.edgeList) {
		for (int f : a.shape->edgeFaces[ea])
			if (faceRow[f] < 0) faceRow[f] = rows++;
	}
	faceSigns.resize(static_cast<std::size_t>(rows) * usable);
	for (int f = 0; f < a.faceCount(); ++f) {
		if (faceRow[f] < 0) continue;
		const Vector3& normal = a.faces[f].normal;
		int* row = faceSigns.data() + static_cast<std::size_t>(faceRow[f]) * usable;
		for (int k = 0; k < usable; ++k) {
			const std::array<int, 3>& edge = bEdges[k];
			int sign = filteredSign(normal.dot(b.edges[edge[0]].arc));  // (-D) x (-C) = D x C
			if (sign == 0) {
				const Vector3 C = -b.faces[edge[1]].normal, D = -b.faces[edge[2]].normal;
				sign = unitOrientationExact(normal, D, C);
			}
			row[k] = sign;
		}
	}
}
}  // namespace

bool searchEdgeAxes(const Prepared& a, const Prepared& b, double d0, double sinTolerance,
                    const EntranceFeature& previous, Scratch& s, AxisSearch& axes) {
	gatherEdgesOfB(b, s);
	const std::vector<int>& bFaces = s.edgeFacesB;
	const std::vector<Vector3>& inward = s.inwardNormalsB;
	const std::vector<std::array<int, 3>>& bEdges = s.edgesB;
	std::vector<int>& side = s.arcSides;
	side.resize(b.faceCount());
	const int usable = static_cast<int>(bEdges.size());
	const int faceTotal = static_cast<int>(bFaces.size());
	s.crossingEdges.resize(usable);
	int* crossing = s.crossingEdges.data();
	faceSignsOfA(a, b, usable, s);
	const std::vector<int>& faceRow = s.faceRows;
	const std::vector<int>& faceSigns = s.faceSigns;
	for (int ea : a.edgeList) {
		const bool internalA = a.internalEdge(ea);
		const auto& fa = a.shape->edgeFaces[ea];
		const Vector3& faceA0 = a.faces[fa[0]].normal;  // A
		const Vector3& faceA1 = a.faces[fa[1]].normal;  // B
		const Vector3& ba = a.edges[ea].arc;            // B x A
		for (int k = 0; k < faceTotal; ++k) side[bFaces[k]] = signOfTriple(inward[k], faceA1, faceA0, ba);
		const int* signsA0 = faceSigns.data() + static_cast<std::size_t>(faceRow[fa[0]]) * usable;
		const int* signsA1 = faceSigns.data() + static_cast<std::size_t>(faceRow[fa[1]]) * usable;
		int count = 0;
		for (int k = 0; k < usable; ++k) {
			const int cba = side[bEdges[k][1]], dba = side[bEdges[k][2]];
			const int adc = signsA0[k], bdc = signsA1[k];
			crossing[count] = k;
			count += (cba * dba < 0) & (adc * bdc < 0) & (cba * bdc > 0);
		}
		// Each usable edge of B counts one test (as when each was tested in
		// turn): all of them, or those up to a rejecting one.
		for (int c = 0; c < count; ++c) {
			const int eb = bEdges[crossing[c]][0];
			const EdgeAxis axis = edgeAxis(a, ea, b, eb, sinTolerance);
			if (!axis.valid) continue;
			if (axis.nearParallel) {
				if (axis.separation > axes.nearParallelBest) {
					axes.nearParallelBest = axis.separation;
					axes.nearParallelEdgeA = ea;
					axes.nearParallelEdgeB = eb;
				}
				continue;
			}
			if (axis.separation > d0) {
				*a.tests += crossing[c] + 1;
				return false;
			}
			axes.deepestBound = std::max(axes.deepestBound, axis.separation);
			if (internalA || b.internalEdge(eb)) continue;  // no entrance
			if (previous.kind == EntranceFeature::EdgePair && previous.feature == ea && previous.other == eb)
				axes.previousEdge = axis;
			if (!axes.bestEdge.valid || axis.separation > axes.bestEdge.separation) {
				axes.bestEdge = axis;
				axes.bestEdgeA = ea;
				axes.bestEdgeB = eb;
			}
		}
		*a.tests += usable;
	}
	return true;
}

}  // namespace dda::narrow
