#include "SubContacts.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace dda::narrow {

namespace {

// A crossing beside a vertex contact is that contact only if their normals
// are within about 25 degrees (dimensionless cosine).
constexpr double kSameNormalCosine = 0.9;

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
// narrow-phase oracle, tests/cpp/contact/test_narrow_phase_oracle.cpp, found
// crossings between 1 and 2 x PD deep in ~1.8% of random near pairs of
// slender blocks), and once d0 deeper (crossings 9 mm deep between blocks
// 0.3 to 4 mm apart).

// An edge-edge sub-contact of a face entrance must push within 60 degrees of
// the face's normal: cosine of that angle (dimensionless). An edge crossing a
// face's edge steeply (along the face normal) has its line distance in the
// face's plane; that contact belongs to the neighbouring face, and the
// vertex-face contacts of its corners already hold the pair along the normal.
constexpr double kEdgeNormalMinCosine = 0.5;

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

// Whether insideMargin(block, f, x) >= 0, told from signs alone where they
// suffice (true: it is; false: not known). Most projections lie inside the
// polygon: for an edge with length > 0 (finite or not), fl(dot / length) has
// the sign of dot (a rounded quotient keeps its sign; an underflow gives a
// zero of that sign, and -0 >= 0 as 0 >= 0), so the margin is >= 0 when every
// such edge has dot >= 0 (a NaN dot fails here and is passed over by
// insideMargin's std::min); and length = sqrt(squared norm) > 0 exactly when
// the squared norm is. The same inward vectors and dots, without the square
// roots and divisions; any other case takes the full margin as before.
bool insideByMarginSigns(const Prepared& block, int f, const Vector3& x) {
	const std::vector<int>& face = block.shape->faces[f];
	const Vector3& n = block.faces[f].normal;
	for (std::size_t k = 0; k < face.size(); ++k) {
		const Vector3& a = block.corner(face[k]);
		const Vector3& b = block.corner(face[(k + 1) % face.size()]);
		const Vector3 inward = n.cross(b - a);
		if (!(inward.squaredNorm() > 0)) continue;
		if (!(inward.dot(x - a) >= 0)) return false;
	}
	return true;
}

// Does x's projection on the plane of face f lie within `reach` [m] of the
// polygon? (A corner just past a face's edge or corner makes a contact with
// it; measured as a distance, not per edge line, so that near an acute corner
// of the face, too, the corner is within sqrt(2) reach of the face.)
bool projectionNearFace(const Prepared& block, int f, const Vector3& x, double reach) {
	if (insideByMarginSigns(block, f, x)) return true;
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
	const double sNumerator = w.cross(db).dot(cross);
	double tNumerator;
	{
		// First without a square root: sLine = sNumerator / nn with nn > 0
		// (nn = 0 gives no rejection here), so a negative numerator gives a
		// negative sLine, or -0 for an underflow, which the endpoint test
		// rejects; and nn is cross.squaredNorm() to within a few DBL_EPSILON
		// (|cross| rounded, then squared), so a numerator above
		// (1 + 1e-12) squaredNorm gives sLine > 1. s's test before t's
		// numerator is computed (the tests only reject).
		const double bound = (1 + 1e-12) * cross.squaredNorm();
		if (sNumerator < 0 || sNumerator > bound) return std::nullopt;
		tNumerator = w.cross(da).dot(cross);
		if (tNumerator < 0 || tNumerator > bound) return std::nullopt;
	}
	const double la = da.norm(), lb = db.norm();
	const double crossNorm = cross.norm();
	if (parallelDirections(da, db, cross, crossNorm, la, lb, sinTolerance)) return std::nullopt;
	const double tol = settings.lengthTolerance;
	const double nn = crossNorm * crossNorm;
	const double sLine = sNumerator / nn;
	const double tLine = tNumerator / nn;
	if (!(sLine >= 0 && sLine <= 1 && tLine >= 0 && tLine <= 1)) return std::nullopt;
	if (sLine * la <= tol || (1 - sLine) * la <= tol || tLine * lb <= tol || (1 - tLine) * lb <= tol)
		return std::nullopt;
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
	c.kind = ContactKind::EdgeEdge;
	c.firstIsA = firstIsA;
	c.feature1 = e1;
	c.feature2 = e2;
	// The closest points, as edgeEdgeDistance(p1, p2, p3, p4, reference, tol,
	// settings.angleTolerance) gives them, without calling it: it computes a =
	// da, b = db, w, la, lb, cross, crossNorm and (w x b) . cross, (w x a) .
	// cross by the expressions above, so its sLine, tLine are these. Its
	// `parallel` is la == 0 || lb == 0 || crossNorm <= sin(angleTolerance) la
	// lb, and sinTolerance is that sine (detectPairContacts computes it once
	// for every caller): false when la > 0, lb > 0 and crossNorm >
	// sinTolerance la lb (a NaN product fails the test). Its `interior` holds
	// for sLine, tLine in [0, 1] (checked above) and tol >= 0 (its tolerances
	// tol / la, tol / lb are >= 0 or +inf), and it then returns s = sLine, t =
	// tLine and the points p1 + s da, p3 + t db; its endpoint test on s, t is
	// the one above. Otherwise (never for valid settings and corners) it is
	// called as before.
	if (la > 0 && lb > 0 && crossNorm > sinTolerance * la * lb && tol >= 0) {
		c.pointI = p1 + sLine * da;
		c.pointJ = p3 + tLine * db;
		return c;
	}
	const EdgeEdgeResult r =
	    edgeEdgeDistance(p1, p2, p3, p4, reference, settings.lengthTolerance, settings.angleTolerance);
	if (r.parallel || !r.interior) return std::nullopt;
	if (r.s * la <= tol || (1 - r.s) * la <= tol || r.t * lb <= tol || (1 - r.t) * lb <= tol) return std::nullopt;
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
//
// Internal faces (a fixed block's faces covered whole by a flush fixed
// neighbour, markInternalFaces) are no entrance, but they count in finding
// how far q lies outside `other`: the farthest-above face over all faces.
// When an internal face beats every other face by more than `reach` (the
// contact distance), q lies across it, on the neighbour's side, farther
// than a contact's reach from `other`'s exposed surface: q touches the
// fixed mass there through the neighbour's faces, which the neighbour's own
// pair finds, and this pair gives it no contact. Within `reach` (a corner at
// the seam of a flush floor, on the plane of the two blocks' shared face and
// a little below their tops) both blocks hold it, as they always did, and
// share its load. Before, the best face among the others was taken whatever
// its distance, and a corner touching a fixed block only where that block's
// faces are internal was measured against its one outer face, metres away
// across the block (gaps of -2 to -4 m in a jointed 16 m cube;
// tests/py/geometry/test_rock_mass.py). A contact left out carries no
// spring, so leaving it out creates no energy; the one it replaces pushed
// with a spring stretched by metres. A contact kept has a gap of at least
// the farthest distance less `reach`: above -reach for q outside `other`.
// Since the depth bound below, gaps that deep are removed by it as well;
// what this rule alone decides is a corner below G's plane by e, at most
// the pair's penetration, more than reach - e across an internal face (the
// test compares with G's distance, -e, plus reach). Where the internal face
// meets G at a right angle, q projects within reach of G only up to reach
// past the seam, so the rule acts in a band of width e just inside reach (a
// block sunk e into a flush floor leaves a corner past the seam to the
// neighbour alone from reach - e on, not reach). Where it meets G at an
// acute ridge, q's projection can fall on G while q lies farther than d0
// from `other`: a slab sunk 0.45 to 0.9 d0 with corners 1.02 to 1.13 d0
// past a covered 45-degree ridge took gap -e there without the rule
// (tests/cpp/contact/test_internal_face_rules.cpp,
// ACornerMoreThanContactDistanceAcrossAnInternalFaceHasNoContact). Only
// corners measured here: a corner of the entering block lies on the
// entrance face, and outsideBeyondFaceEdge counts exposed faces only, so
// with the covered block's face as the entrance the same corner keeps -e.
// Energy: at the step the rule acts it only leaves a contact out; a
// compressed spring it drops leaves the account as a loss (contactChanges),
// never a gain.
//
// Nor is it deeper than the pair's penetration: `lowest` is min(s, 0) less
// the length tolerance, s the pair's largest separation over every axis
// tested (internal faces too), as for the other block's corners
// (faceEntranceContacts). The argument above that q's gap is positive
// outside `other` holds when G is the farthest face; when an internal face
// g is (q across it, within `reach`), G's plane can pass above q with q
// outside both `other` and the part beyond g: where two parts of a
// concave block meet at a ridge, G's plane runs on past the ridge above
// the neighbour's face, over the outside of the block. Such a gap measures
// no overlap. In the tunnel of
// tests/py/geometry/test_concave_rock_mass.py two corners of a part 155 um
// outside the face's part (85 um outside its neighbour, outside the whole
// block) were given gaps of -5.5 and -9.4 um and 4.0e6 and 4.5e6 N at once
// (78 J of contactChanges in one step), while the two parts overlapped by
// less (this bound removes both).
// A translation of the penetration depth separates the two convex parts and
// moves any gap by at most that much, so a gap below -depth is no contact
// of this pair; q inside the neighbour beyond g is that pair's contact,
// whose own faces measure it. Leaving a contact out carries no spring and
// creates no energy; at a flush seam the corner of a block resting on
// `other` keeps its contact, since the pair overlaps by as much as the
// corner lies below G. The one exception: a corner inside the fixed mass at
// a covered seam keeps it whatever the bound (the seam rule, above).
// Whether x lies in the fixed mass at a seam of `other`: past at most one
// internal face g of `other` (the one whose plane x is nearest to leaving
// through, or past), no farther past g's plane than g's flush neighbour
// surely reaches (BlockGeometry::coverDepths, less `tolerance`), and
// projecting into g (to `tolerance`). Then x is in `other` or in that
// neighbour: both are fixed, so x is inside the fixed mass (with every
// exposed face of `other` above it: the caller's corner is below its best
// exposed face).
//
// The seam rule (ownEntranceContact): such a corner keeps its contact on
// its own entrance face G of `other` even when it lies deeper below G than
// the pair's penetration. Physics: the depth bound holds for the two convex
// blocks alone; when the axis that bounds it is an internal one (a covered
// face, or an edge of one), the translation it stands for carries the corner
// out of `other` through the covered face, into the fixed neighbour, which
// is no way out of the fixed mass. A wall standing on a floor: a block's
// corner that slides into the foot of the wall dips below the floor's top by
// its penalty spring's compression (nanometres at E = 1e11 Pa); once behind
// the wall's face, under the wall's bottom edge, the axis of that edge
// separated the block from the wall, so its contact on the wall's face was
// dropped; the corner slid on under the wall, the floor pushed it up into
// the wall, and it was found there 175 um deep (8.2e3 J in one step, random
// hulls in a box at dt 2.5e-4 s; tests/cpp/contact/test_covered_seam.cpp).
// At a seam both blocks hold such a corner, each along its own exposed face,
// as at the seam of a flush floor (the rule below); the cover depth keeps
// out a corner past a neighbour that thins to nothing at the seam (two parts
// of a concave block meeting at a ridge: cover depth 0, the rule never
// acts), where it lies outside the fixed mass and the depth bound removes
// it as before. Energy: the rule adds no contact a corner outside the fixed
// mass could have, closes, opens or deepens none; it keeps a contact the
// depth bound would drop, at the gap it has (the corner's distance below G,
// above -reach). A corner reaching the seam from the open side has had G's
// contact since it came within d0 of G's plane, so the contact is kept
// from step to step and its spring measured again like any kept contact;
// without the rule the compressed spring was dropped (a loss) and the
// corner, unopposed, was found again far deeper (the gain it removes). A
// contact it adds anew is compressed by at most the corner's distance
// below G, a real overlap with the fixed mass, as Shi's entrance rule gives
// any corner entering a block.
//
// And the corner lies in the fixed mass at least as deep as below G: at
// least `below` inside the neighbour from every face but the covering one
// (FaceCover::depthInside). Then a ball of radius `below` about x stays in
// the fixed mass: its part past g is inside the neighbour, its part behind g
// is below every exposed face of `other`, so the gap -below against G is no
// deeper than the corner's true penetration of the fixed mass, and the
// spring stores no energy a real overlap does not. Without this a corner
// resting at a junction of fixed blocks (the apex of a fixed tetrahedron
// whose faces are all covered but its base, in a cut rock mass) was measured
// against that base 3.3 cm away: a compressed spring of 1e6 J where nothing
// overlapped. A corner only on or just past g is on the neighbour's surface
// (depth 0 there) and keeps no contact beyond the pair's bound.
bool insideCoveredSeam(const Prepared& other, const Vector3& x, double below, double tolerance) {
	int seam = -1, past = 0;
	double across = -std::numeric_limits<double>::infinity();
	for (int g = 0; g < other.faceCount(); ++g) {
		if (!other.internal(g)) continue;
		const double d = planeDistance(other, g, x);
		past += d > tolerance;
		if (d > across) {
			across = d;
			seam = g;
		}
	}
	return seam >= 0 && past <= 1 && across <= other.coverDepth(seam) - tolerance &&
	       insideMargin(other, seam, x) >= -tolerance && other.depthInCover(seam, x) >= below - tolerance;
}

void ownEntranceContact(const Prepared& block, bool blockIsA, int q, const Prepared& other, double reach,
                        double tolerance, double lowest, std::vector<SubContact>& out) {
	const Vector3& x = block.corner(q);
	int bestFace = -1;
	double bestDistance = -std::numeric_limits<double>::infinity();  // over the entrance-eligible faces
	double farthest = -std::numeric_limits<double>::infinity();     // over all faces
	for (int g = 0; g < other.faceCount(); ++g) {
		++*block.tests;
		ensurePlane(other, g);
		const double d = planeDistance(other, g, x);
		farthest = std::max(farthest, d);
		if (other.internal(g)) continue;
		if (d > bestDistance) {
			bestDistance = d;
			bestFace = g;
		}
	}
	if (bestFace < 0 || bestDistance > reach || bestDistance < farthest - reach) return;
	if (bestDistance < lowest && !insideCoveredSeam(other, x, -bestDistance, tolerance)) return;
	if (!projectionNearFace(other, bestFace, x, reach)) return;
	// q beyond two or more internal faces of `other` (each farther above than
	// q lies above the exposed face G), below G's plane and beyond G's
	// boundary (its projection on G's plane outside G): q sits at a ridge of
	// `other` whose faces are both covered by fixed neighbours, which hold it;
	// the gap against G's plane measures no overlap. A wedge's corner sliding
	// down the ridge edge of the fixed block below it was 1.3 cm "below" that
	// block's top face, beyond its corner, and a locked spring threw the wedge
	// up (tests/py/system/test_wedge.py). Beyond one internal face only (the
	// seam of a flush floor) both blocks hold the corner, as before: dropping
	// it there made the hand-over at the seam abrupt and cost a sliding block
	// 26% of its kinetic energy (tests/py/contact/test_flush_joint.py).
	// The wedge's corner, 1.3 cm below G, is now below the depth bound too;
	// the rule alone decides for q no deeper than the pair's penetration and
	// within reach - e across each covered face: a slab sunk e into a floor
	// of four flush blocks, its corner a few mm past the covered corner of
	// one, outside it and inside the diagonal neighbour, took gap -e against
	// that block's top without the rule, a compressed spring where the pair
	// does not overlap (tests/cpp/contact/test_internal_face_rules.cpp,
	// ACornerPastACoveredCornerOfAFloorBlockHasNoCompressedContact). Like the
	// rule above it only leaves a contact out: no spring, no energy created.
	if (bestDistance < -tolerance && bestDistance < farthest - tolerance &&
	    insideMargin(other, bestFace, x) < -tolerance) {
		int beyond = 0;
		for (int g = 0; g < other.faceCount(); ++g)
			if (other.internal(g) && planeDistance(other, g, x) > bestDistance + tolerance) ++beyond;
		if (beyond >= 2) return;
	}
	out.push_back(vertexFaceContact(blockIsA, block, q, other, bestFace));
}

// Whether corner v of `block`, below the plane of face f of `owner`, lies
// outside `owner` beyond the boundary of f where it crosses it: above the
// plane of an exposed (non-internal) face of `owner` by more than
// `tolerance` [m], its projection beyond an edge of f by more than
// `tolerance`, and no edge of `block` at v parallel (within the angle
// tolerance, sine `sinTolerance`) to an edge of f it lies beyond.
//
// Such a corner is measured against its own entrance face of `owner`
// (ownEntranceContact), not against f (faceEntranceContacts). Physics: a
// vertex-face gap is the corner's distance from f's plane, the penetration
// of the corner into `owner` only while the corner is in `owner`; a corner
// past f's edge and past an exposed face of `owner` is in no part of
// `owner`, so no overlap is there for a penalty spring to undo. Below the
// plane's extension (allowed down to minus the pair's penetration, and
// within d0 of f) it pushed along f's normal as if f reached on past its
// edge: a block hanging over the edge of another was held up to d0 beyond
// it, and a roof's corner 3.3 cm past the face it was measured on took
// -1.2 mm (tests/cpp/contact/test_contact_coverage.cpp: 19 such corners in
// 8 seeds of its piles, down to -2.1 mm, none after; the closed form
// CornerPastAFaceEdgeOutsideTheBlockHasNoNegativeGap). The overlap near
// such a corner has its own contacts: where its edges cross f's edge
// (edge-edge, as deep as the corner lies below f when the faces are
// parallel), or f's corners inside the other block (own entrance); its own
// entrance face G, the face it lies farthest above, has it at a positive
// gap (a plane separates a point from a convex block), an open contact
// that closes if the corner comes into `owner` through G within the step.
// Kept on f: a corner with an edge along an edge of f it lies past (within
// the angle tolerance). Near-parallel edges give no crossing, and the
// corner stands for the overlap's vertex where they meet, at its depth
// along f (the contact of two such edges is the vertex contacts at their
// ends, measured along the entrance face: a bar resting edge on edge sinks
// without them, tests/py/system/test_hard_cases.py). Measuring those
// against their own face too, whenever the corner's parallel edge stays
// past f (two flush cubes of an L slid apart by a little), turned the
// coverage oracle's flush faces into contacts that come and go: the
// account's gains rose from 1.6e5 to 6.0e6 J (convex pile, E = 1e10 Pa,
// seed 3). Also kept: a corner past no edge of f (it went through a block
// thinner than its depth below f): f pushes it back.
// Energy: at the step it acts the rule only opens a contact: a gap below
// -tolerance becomes a positive one (no spring energy) or none, and the
// compressed spring it replaces leaves the account as a loss
// (contactChanges), never a gain; it never closes a contact nor deepens a
// gap. Corners inside `owner`, or on its boundary to the tolerance, are
// measured against f as before, with the same gap and key. A corner that
// comes back into `owner` meets f's contact anew, compressed by its depth
// below f: the jump Shi's entrance rule gives any corner entering a block
// through a side face, which the contact it replaces made d0 before the
// edge instead (and, in between, pushed on nothing). Measured: the
// oracle's gains over 8 seeds, 2.43e5 -> 2.42e5 J (convex piles, E = 1e8
// Pa) and 1.56e5 -> 1.53e5 J (roofs); a dropped pile of 30 cubes at 1e5 Pa
// (tests/py/solver/test_energy_and_creep.py) 0.54% -> 0.37% of its largest
// change.
bool outsideBeyondFaceEdge(const Prepared& owner, int f, const Prepared& block, int v, double tolerance,
                           double sinTolerance) {
	const Vector3& x = block.corner(v);
	bool outside = false;
	for (int g = 0; g < owner.faceCount() && !outside; ++g) {
		if (g == f || owner.internal(g)) continue;
		ensurePlane(owner, g);
		outside = planeDistance(owner, g, x) > tolerance;
	}
	if (!outside) return false;
	const std::vector<int>& face = owner.shape->faces[f];
	const Vector3& n = owner.faces[f].normal;
	bool beyond = false;
	for (std::size_t k = 0; k < face.size(); ++k) {
		const Vector3& a = owner.corner(face[k]);
		const Vector3 edge = owner.corner(face[(k + 1) % face.size()]) - a;
		const Vector3 inward = n.cross(edge);
		const double length = inward.norm();
		if (!(length > 0) || !(inward.dot(x - a) < -tolerance * length)) continue;
		beyond = true;
		for (const std::array<int, 2>& e : block.shape->edges) {
			if (e[0] != v && e[1] != v) continue;
			if (parallelDirections(block.corner(e[1]) - block.corner(e[0]), edge, sinTolerance)) return false;
		}
	}
	return beyond;
}

// The fold rule's symmetric case, for the corners of f's own block: a corner
// q of `owner` not on f, within d0 of `other`, against its own entrance face
// of `other` (ownEntranceContact), appended to `out`. f's search measures
// the other block's corners, the crossings of f's edges and f's own corners;
// a corner of `owner` beside f is none of them. Across a shallow fold (the
// nearly planar sides of random hulls split at 1 to 3 degrees) it lies a
// little below f's plane, and a block resting on f near one end and reaching
// on over the face beside it (a slab across the fold, touching f at its near
// edge) can have its face G within d0 of it: rocking about its contact on f,
// G comes down on the corner, which had no contact while f stayed the
// entrance (until G's axis beat f's, by the hysteresis when f was the
// previous entrance), so it met G unopposed within the step. Closed form:
// tests/cpp/contact/test_fold_corner_owner.cpp (before this rule no
// sub-contact at a corner 9 to 16 mm from the slab at d0 = 20 mm).
// Candidates: `other` lies at least `above` [m] over f's plane (its lowest
// corner's distance from it), so a corner more than reach - above below
// f's plane is farther than d0 from `other` along f's normal and is passed
// over (a box's far corners, its height below). A corner within `merge` [m]
// of a contact point found is that contact's (a corner of `other` on it).
// The caller makes it only when f's search found a contact: a face that
// finds nothing stays no entrance (the tied faces are tried, or a previous
// entrance kept by hysteresis is given up, as before).
// Energy: it only adds contacts, and closes, deepens or drops no other.
// ownEntranceContact keeps a corner only within d0 of its face G and no
// deeper than the pair's penetration (`lowest`): one added open stores
// nothing, and open-close stops the corner at G; one added compressed is no
// deeper than the penetration, its first spring booked as a contact change,
// as any new contact's (such a pair then has a sub-contact pushing it apart,
// so nearParallelEdgeContact, made only when none does, is not: a contact
// not made, a spring that leaves as a loss if it was there).
// Measured: the coverage oracle's 48 scenes (8 seeds) unchanged (steps'
// gains 1.372e7 J, largest 1.009e7 J, before and after); random hulls
// (bench/energy.py --hulls 8, 1e9 and 1e11 Pa, 1 s) bit-identical energy
// accounts: the rule added 0 to 216 contact-steps per run (0.2 %), all
// open while there, none closed; the slender deposit's 1,214 sub-contacts
// the same (bench/narrow_phase.cpp).
void ownerCornersBesideFace(const Prepared& owner, bool ownerIsA, int f, const Prepared& other, double above,
                            double reach, double tolerance, double lowest, double merge, std::vector<SubContact>& out) {
	const std::vector<int>& face = owner.shape->faces[f];
	for (int q : owner.vertexList) {
		if (std::find(face.begin(), face.end(), q) != face.end()) continue;
		const Vector3& x = owner.corner(q);
		++*owner.tests;
		if (above - planeDistance(owner, f, x) > reach) continue;
		const bool known = std::any_of(out.begin(), out.end(), [&](const SubContact& c) {
			return (c.pointI - x).norm() <= merge || (c.pointJ - x).norm() <= merge;
		});
		if (!known) ownEntranceContact(owner, ownerIsA, q, other, reach, tolerance, lowest, out);
	}
}

// The usable edges of face f of `owner` (edgeList order) into `out`.
void edgesOfFace(const Prepared& owner, int f, std::vector<int>& out) {
	out.clear();
	for (int e : owner.edgeList) {
		const auto& ef = owner.shape->edgeFaces[e];
		if (ef[0] == f || ef[1] == f) out.push_back(e);
	}
}

// Whether a point of sub-contact c lies within `merge` [m] of a point of the
// edge entrance's crossing: the crossing's own contact.
bool atCrossing(const SubContact& c, const SubContact& crossing, double merge) {
	for (const Vector3* p : {&c.pointI, &c.pointJ})
		if ((*p - crossing.pointI).norm() <= merge || (*p - crossing.pointJ).norm() <= merge) return true;
	return false;
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
//
// The fold rule: a corner within d0 of f's plane that is not f's (its projection
// more than d0 from f, or below f's plane deeper than the pair's
// penetration) is measured against its own entrance face:
// ownEntranceContact keeps it when its own
// entrance face G of `owner` (the exposed face it lies farthest above)
// has it within d0, no deeper than the penetration (`lowest`), its
// projection within d0 of G: a corner within d0 of `owner`, where a
// contact is due, over a face beside f. Every such corner is in this
// band: f is exposed, so its distance from f's plane is at most its
// distance from G's. Before, only the entrance face's search measured
// the entering block's corners: a corner over the face beside the
// entrance, as where a nearly planar side is split at a shallow fold
// and a block rocks about the fold onto the other face, had no contact
// until that face was the entrance, and it entered within a step
// unopposed. Random hulls (27 in a box): at E = 1e11 Pa a
// corner 0.65 m from the entrance's contacts, over a face 2.4 degrees
// from the entrance face, 35 to 2.6 mm from it for 12 steps, found
// first 0.34 mm deep (3.3e4 J in one step); at 1e9 Pa a corner 0.46 mm
// deep after 4 such steps (690 J). Closed form:
// tests/cpp/contact/test_fold_corner.cpp.
// Energy: the rule only adds contacts, and closes, deepens or drops no
// other. One added open (most: a corner comes within d0 before it
// arrives) stores nothing, and open-close stops the corner at G; one
// added at a negative gap is no deeper than the pair's penetration, its
// first spring booked as a contact change, as any new contact's. A
// corner below f's plane deeper than the penetration, left out before,
// is kept against G only if G's gap is no deeper than that either.
// Measured (bench/energy.py --hulls 8,
// seeds 1-8, 1 s): the steps' gains 3.30e3 -> 2.29e3 J at 1e9 Pa and
// 3.32e5 -> 2.86e5 J at 1e11 Pa; largest single step 690.8 -> 17.9 J
// (1e9, seed 7) and 3.29e4 -> 1.48e3 J (1e11, seed 3); one seed's
// largest rose, 2.49e3 -> 4.68e3 J (1e11, seed 4: a kept contact's
// linearisation, on a changed trajectory; its net gains fell 0.70 ->
// 0.61 of the scale).
void faceEntranceContacts(const Prepared& owner, bool ownerIsA, int f, const Prepared& other, double depthBound,
                          double crossingBound, const DetectionSettings& settings, double sinTolerance, Scratch& s,
                          std::vector<SubContact>& out) {
	// Within d0, to the length tolerance: a face is planar only to within it, so
	// a corner touching a face may lie that far off the face's triangle plane.
	const double reach = settings.contactDistance + settings.lengthTolerance;
	const std::size_t start = out.size();

	// The other block's corners' distances from the face's plane, each
	// computed when first needed.
	std::vector<double>& distances = s.cornerDistances;
	std::vector<char>& ready = s.cornerDistanceReady;
	distances.resize(other.cornerCount());
	ready.assign(other.cornerCount(), 0);
	const double bound = planeRoundoffBound(owner, f, other.lower, other.upper);
	const auto distance = [&](int v) {
		if (!ready[v]) {
			distances[v] = planeDistanceInBox(owner, f, other.corner(v), bound);
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
	// A corner outside `owner` past f's edge is measured against its own
	// face (outsideBeyondFaceEdge), after the crossings below: an open
	// contact there must not stand for a crossing beside it.
	// So is a corner within d0 of f's plane that is not f's (the fold
	// rule in the comment above the function).
	std::vector<int>& used = s.used;
	std::vector<int>& outside = s.outsideCorners;
	used.clear();
	outside.clear();
	for (int v : other.vertexList) {
		if (distance(v) > reach) continue;
		if (distance(v) < lowest || !projectionNearFace(owner, f, other.corner(v), reach)) {
			// Not f's corner: against its own entrance face (below).
			outside.push_back(v);
			continue;
		}
		if (distance(v) < -settings.lengthTolerance &&
		    outsideBeyondFaceEdge(owner, f, other, v, settings.lengthTolerance, sinTolerance)) {
			outside.push_back(v);
			continue;
		}
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
		ownEntranceContact(owner, ownerIsA, q, other, reach, settings.lengthTolerance, lowest, out);
	}

	// Edges of the other block crossing the face's edges, no deeper than the
	// pair's penetration allows (the rule at the top of this file; for
	// crossings `crossingBound`, which near-parallel edge axes may raise).
	const double deepest = std::min(crossingBound, 0.0) - settings.lengthTolerance;
	std::vector<int>& faceEdges = s.faceEdges;
	edgesOfFace(owner, f, faceEdges);
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
	for (int v : outside) ownEntranceContact(other, !ownerIsA, v, owner, reach, settings.lengthTolerance, lowest, out);
	if (out.size() == start) return;
	// Corners of f's block beside f (ownerCornersBesideFace).
	double above = std::numeric_limits<double>::infinity();
	for (int v = 0; v < other.cornerCount(); ++v) above = std::min(above, distance(v));
	ownerCornersBesideFace(owner, ownerIsA, f, other, above, reach, settings.lengthTolerance, lowest, merge, out);
}

// faceEntranceContacts for entrance face `face` of A or of B, entered by the
// other block.
void entranceFaceContacts(const Prepared& a, const Prepared& b, const EntranceFeature& face, double depthBound,
                          double crossingBound, const DetectionSettings& settings, double sinTolerance, Scratch& s,
                          std::vector<SubContact>& out) {
	if (face.kind == EntranceFeature::FaceOfA)
		faceEntranceContacts(a, true, face.feature, b, depthBound, crossingBound, settings, sinTolerance, s, out);
	else
		faceEntranceContacts(b, false, face.feature, a, depthBound, crossingBound, settings, sinTolerance, s, out);
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
void otherFeaturesOfEdgeEntrance(const Prepared& a, const Prepared& b, const EntranceFeature& face, double depthBound,
                                 double crossingBound, const DetectionSettings& settings, double sinTolerance,
                                 Scratch& s, std::vector<SubContact>& out) {
	const SubContact crossing = out.front();
	const std::size_t first = out.size();
	entranceFaceContacts(a, b, face, depthBound, crossingBound, settings, sinTolerance, s, out);
	const double merge = std::max(settings.cornerMergeDistance, settings.lengthTolerance);
	const auto sameAsCrossing = [&](const SubContact& c) {
		if (c.kind == ContactKind::EdgeEdge) {
			const int edgeA = c.firstIsA ? c.feature1 : c.feature2, edgeB = c.firstIsA ? c.feature2 : c.feature1;
			if (edgeA == crossing.feature1 && edgeB == crossing.feature2) return true;
		}
		return atCrossing(c, crossing, merge);
	};
	out.erase(std::remove_if(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(), sameAsCrossing), out.end());
}

// Step 3 for an edge entrance whose edges cross (out[0] the crossing): where
// either entrance edge, past the crossing, runs on across a face at the other
// entrance edge, its crossing of that face's boundary further on. Two blocks
// meeting edge on edge touch at one point only while neither edge lies across
// the other's face; once edge b crosses edge a and continues over a face F at
// a, the pair touches along b over F (an edge-on-face contact), and F's
// boundary crosses b a second time. The best face's search finds that second
// crossing only when F is the best face, which an edge axis beat and which
// may lie elsewhere on the block: with the entrance crossing alone, b pivots
// about it and drives its other crossing into F's block within a step
// (random hulls at E = 1e11 Pa: a crossing found first at 0.88 mm deep, 4.0e5
// J in its spring; measured on random hulls, doc/benchmarks.md). Each such
// crossing is the edge-edge contact the face search would give were F the
// entrance (edge of the block crossing F as i, F's edge as j, normal within
// 60 degrees of F's, no deeper than the pair's penetration, not beside a
// vertex contact or the entrance crossing), found while it is within d0.
// Energy: a crossing added open stores nothing; one already compressed is no
// deeper than the pair's penetration (its spring is booked as a contact
// change); none is closed, deepened or dropped by the rule.
void crossingsAcrossEntranceFaces(const Prepared& a, const Prepared& b, int edgeA, int edgeB, double crossingBound,
                                  const DetectionSettings& settings, double sinTolerance, Scratch& s,
                                  std::vector<SubContact>& out) {
	const SubContact crossing = out.front();
	const double reach = settings.contactDistance + settings.lengthTolerance;
	const double merge = std::max(settings.cornerMergeDistance, settings.lengthTolerance);
	EdgeContactLimits limits;
	limits.highestGap = reach;
	limits.deepestGap = std::min(crossingBound, 0.0) - settings.lengthTolerance;
	limits.minCosine = kEdgeNormalMinCosine;
	const auto known = [&](const SubContact& c) {
		for (const SubContact& o : out)
			if (o.kind == ContactKind::EdgeEdge && o.stencil.kind == ContactKind::EdgeEdge &&
			    ((o.feature1 == c.feature1 && o.feature2 == c.feature2 && o.firstIsA == c.firstIsA) ||
			     (o.feature1 == c.feature2 && o.feature2 == c.feature1 && o.firstIsA != c.firstIsA)))
				return true;
		return atCrossing(c, crossing, merge) || besideVertexContact(c, out, merge);
	};
	for (int side = 0; side < 2; ++side) {
		// The faces of `owner` at its entrance edge, crossed by the other block's entrance edge.
		const Prepared& owner = side == 0 ? a : b;
		const Prepared& other = side == 0 ? b : a;
		const int ownEdge = side == 0 ? edgeA : edgeB, otherEdge = side == 0 ? edgeB : edgeA;
		for (int f : owner.shape->edgeFaces[ownEdge]) {
			if (f < 0 || owner.internal(f)) continue;
			ensurePlane(owner, f);
			limits.direction = &owner.faces[f].normal;
			edgesOfFace(owner, f, s.faceEdges);
			for (int g : s.faceEdges) {
				if (g == ownEdge) continue;
				++*owner.tests;
				const std::optional<SubContact> c =
				    edgeEdgeContact(side != 0, other, otherEdge, owner, g, settings, sinTolerance, limits);
				if (!c || planeDistance(owner, f, c->pointI) > reach || known(*c)) continue;
				out.push_back(*c);
			}
		}
	}
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
void cornersOfEdgeEntrance(const Prepared& a, int edgeA, const Prepared& b, int edgeB, double depthBound,
                           const DetectionSettings& settings, std::vector<SubContact>& out) {
	const double lowest = std::min(depthBound, 0.0) - settings.lengthTolerance;
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
			if (!known) ownEntranceContact(block, blockIsA, q, other, reach, settings.lengthTolerance, lowest, out);
		}
	}
}

// The pair's normal (from A towards B) when `face` is its entrance: the
// face's outward normal, negated for a face of B.
Vector3 faceEntranceNormal(const Prepared& a, const Prepared& b, const EntranceFeature& face) {
	return face.kind == EntranceFeature::FaceOfA ? a.faces[face.feature].normal : Vector3(-b.faces[face.feature].normal);
}

// A face entrance that found nothing, among faces tied with the best
// (within lengthTolerance): the next tied face that finds something is the
// entrance. Two halves of a nearly planar side tie, and the one of larger
// area may not be the one the other block's corners lie over: a pair 9.2
// mm apart and one overlapping by 0.38 mm had no sub-contact at all (2 of
// 2 million random near pairs of the oracle).
void tiedFaceContacts(const Prepared& a, const Prepared& b, const std::vector<FaceCandidate>& faces,
                      const AxisSearch& axes, double depthBound, double crossingBound,
                      const DetectionSettings& settings, double sinTolerance, Scratch& s, Entrance& entrance,
                      PairContacts& out) {
	for (const FaceCandidate& c : faces) {
		if (c.separation < axes.bestFace - settings.lengthTolerance || c.feature == entrance.feature) continue;
		entranceFaceContacts(a, b, c.feature, depthBound, crossingBound, settings, sinTolerance, s, out.contacts);
		if (out.contacts.empty()) continue;
		entrance = {c.feature, c.separation};
		out.normal = faceEntranceNormal(a, b, c.feature);
		break;
	}
}

// The point of edge e of `block` deepest inside `other`: x(t) = start + t
// (end - start), t in [0, 1], minimising h(t) = max over every face g of
// `other` of the distance of x(t) above g's plane (the point's signed
// distance from the convex block: minus its depth inside). Each distance is
// affine in t, so h is convex and piecewise affine and its minimum lies at
// t = 0, t = 1 or where two faces' distances are equal; every such t is
// tried (a block has few faces, and this runs only for the rare pairs
// nearParallelEdgeContact is for). Divisions only by a nonzero difference of
// slopes, and only a quotient within [0, 1] is used: no NaN.
struct DeepestEdgePoint {
	double t = 0;
	double distance = std::numeric_limits<double>::infinity();  // h(t) [m], < 0 inside
	int face = -1;  // the exposed face of `other` farthest above x(t), -1 when an internal face is
};
// With `at` in [0, 1], the point x(at) instead of the deepest.
DeepestEdgePoint deepestEdgePoint(const Prepared& block, int e, const Prepared& other, double tolerance,
                                  double at = -1) {
	const Vector3& p0 = block.edgeStart(e);
	const Vector3& p1 = block.edgeEnd(e);
	const int faces = other.faceCount();
	std::vector<double> at0(static_cast<std::size_t>(faces)), slope(static_cast<std::size_t>(faces));
	for (int g = 0; g < faces; ++g) {
		ensurePlane(other, g);
		++*block.tests;
		at0[g] = planeDistance(other, g, p0);
		slope[g] = planeDistance(other, g, p1) - at0[g];
	}
	const auto h = [&](double t) {
		double best = -std::numeric_limits<double>::infinity();
		for (int g = 0; g < faces; ++g) best = std::max(best, at0[g] + t * slope[g]);
		return best;
	};
	DeepestEdgePoint out;
	const auto tryAt = [&](double t) {
		const double value = h(t);
		if (value < out.distance) {
			out.distance = value;
			out.t = t;
		}
	};
	if (at >= 0 && at <= 1) {
		tryAt(at);
	} else {
		tryAt(0);
		tryAt(1);
		for (int g = 0; g < faces; ++g)
			for (int k = g + 1; k < faces; ++k) {
				const double denominator = slope[g] - slope[k];
				if (denominator == 0) continue;
				const double t = (at0[k] - at0[g]) / denominator;
				if (t > 0 && t < 1) tryAt(t);
			}
	}
	// Its own entrance face: the exposed face it lies farthest above, unless
	// an internal face lies above that by more than the tolerance (the point
	// is then across a flush joint, held through the neighbour's faces).
	double exposed = -std::numeric_limits<double>::infinity();
	for (int g = 0; g < faces; ++g) {
		if (other.internal(g)) continue;
		const double d = at0[g] + out.t * slope[g];
		if (d > exposed) {
			exposed = d;
			out.face = g;
		}
	}
	if (exposed < out.distance - tolerance) out.face = -1;
	return out;
}

// The contact of two edges parallel within the angle tolerance that overlap
// with no other contact to push them apart (findSubContacts): the point of
// one edge deepest inside the other block (of the two edges' points, the
// deeper; A's edge on a tie), a fixed point of its block for the step,
// against that block's face it lies farthest above (its own entrance face,
// as ownEntranceContact's corners). Keyed as the two edges' edge-edge
// contact (edge of block i, edge of block j), so that the crossing that
// takes over once the angle passes the tolerance inherits its history; its
// stencil is the vertex-face stencil of that point and the face's triangle.
// Nothing when no point of either edge lies inside the other block by more
// than the tolerance, when the point lies across an internal face, or when
// its gap is below `lowest` (minus the pair's penetration).
//
// Why: the contact of two near-parallel edges is the vertex contacts at
// their ends (no crossing: for an angle theta below the tolerance its point
// moves along the edges by their offset / theta, and its normal, the edges'
// cross product, turns by about omega / theta for a turn omega of a block
// in the step, which the tolerance allows up to theta). That fails when the
// edges cross at their small angle inside both segments with the ends of
// both outside the other block: the overlap lies in the middle of both
// edges, at no corner, and nothing pushed on it (the coverage oracle's
// convex pile, seed 6, E = 1e10 Pa: parts 18 and 19 overlapped by 1.4 to
// 8.9 mm over four steps with every sub-contact open, then a crossing 8.9 mm
// deep appeared new and stored 1.58e7 J in one step). A point of an edge
// against a face plane is well conditioned at any angle: its gap is the
// point's height above the plane and its normal the face's, neither
// depending on the angle between the edges, and for exactly parallel edges
// it is what their corner contacts measure (two ridges at 45 degrees
// overlapping by delta: delta / sqrt(2) against a face, the corners'
// gap of EdgeEdgeParallelGeneric). The point is a material point of its
// block (its displacement T(x - c) D, as a corner's), so the stencil
// linearises as any vertex-face contact.
// Depth: the gap is minus the depth of a point of one block inside the
// other, and a translation of the pair's penetration depth carries every
// point out, so it is no deeper than the penetration (no ghost; `lowest`
// holds it to the pair's separating-axis value).
// Energy: the contact is made only while the pair overlaps and none of its
// sub-contacts has a negative gap; it never deepens or closes another
// contact. At the step it first appears it adds one spring compressed by
// the point's depth, at most the penetration, which grew from zero within
// the steps since the blocks met (a new contact's spring is booked in
// contactChanges, as for a corner entering a face): without it the overlap
// grew unopposed and the crossing appeared later as deep as the overlap had
// become. Measured on the coverage oracle (8 seeds x 6 scenes; the 45
// scenes without such a pair unchanged): convex pile seed 6, E = 1e10 Pa,
// largest single-step gain of contactChanges 1.58e7 -> 2.26e5 J (steps'
// gains 1.61e7 -> 3.30e5 J); E = 1e8 Pa 4.22e4 -> 2.93e4 J (8.18e4 ->
// 5.14e4 J); seed 8, E = 1e8 Pa, 1.49e3 -> 5.83e3 J (5.59e3 -> 1.25e4 J:
// the spring of the contact's first step, an overlap of up to 2.8 mm that
// had no spring before). That first-step gain remains: the pair has no open
// contact within d0 before it overlaps, so the overlap's first step, up to
// the step's relative motion, is met compressed.
// Tried and not kept (the oracle's 48 scenes, 8 seeds:
// sum of the steps' gains 2.96e6 J, largest single step 2.26e5 J before):
// the same contact made while the pair is within d0, open at a positive gap.
// (1) At any point of the edge: the point of an edge nearest the other
// block is mostly its end, a corner with its own vertex-face contact, whose
// spring it doubled (~15,000 contact-steps per convex pile); seed 6 fell to
// 5.2e4 J, but 37 scenes changed, sum 2.90e6 J, one scene 3.7e4 -> 2.6e5 J.
// (2) Only at a point more than the corner merge distance inside the edge
// (it reproduces the 1.39e6 J an earlier attempt measured): the rule acts
// only while no sub-contact is negative, so a corner 0.5 m away closing at
// -51 um switched it off; in that step the crossing went unresisted and
// came back 2.64 mm deep as a new contact, 1.39e6 J (convex seed 1, E =
// 1e10 Pa, parts 22 and 23; sum 4.22e6 J). (3) As (2), a negative
// sub-contact farther than d0 from the point no longer switching it off:
// one point cannot hold two near-parallel edges, whose crossing moves
// along them by their offset / angle as the blocks turn; the deepest point
// moved 0.5 m in a step and was met 0.93 mm deep while the old point ended
// 5 um deep (convex seed 3, E = 1e10 Pa, parts 13 and 14: 1.74e5 J; 13
// scenes raised, sum 3.06e6 J). An open contact for such a pair would have
// to hold the line (its ends and the crossing), not a point.
std::optional<SubContact> nearParallelEdgeContact(const Prepared& a, int edgeA, const Prepared& b, int edgeB,
                                                  double depth, double tolerance, double lowest,
                                                  const KeptEdgePoint* kept) {
	const DeepestEdgePoint inB = deepestEdgePoint(a, edgeA, b, tolerance);
	const DeepestEdgePoint inA = deepestEdgePoint(b, edgeB, a, tolerance);
	bool useA = inA.distance < inB.distance;  // B's edge in A; ties: A's edge in B
	DeepestEdgePoint deepest = useA ? inA : inB;
	// The last step's point, a material point of its edge, while it lies at
	// least half as deep as the deepest point (keptEdgePoint; given only
	// for these two edges).
	if (kept) {
		const Prepared& owner = kept->onA ? a : b;
		const Vector3 start = owner.edgeStart(kept->edge), along = owner.edgeEnd(kept->edge) - start;
		const double length2 = along.squaredNorm();
		const double t = length2 > 0 ? along.dot(kept->point - start) / length2 : -1;
		if (t >= 0 && t <= 1) {
			const DeepestEdgePoint held = deepestEdgePoint(owner, kept->edge, kept->onA ? b : a, tolerance, t);
			if (held.face >= 0 && held.distance < 0 && held.distance <= 0.5 * deepest.distance) {
				deepest = held;
				useA = !kept->onA;
			}
		}
	}
	const Prepared& blockI = useA ? b : a;
	const Prepared& blockJ = useA ? a : b;
	const int edgeI = useA ? edgeB : edgeA, edgeJ = useA ? edgeA : edgeB;
	if (deepest.face < 0 || !(deepest.distance < -depth)) return std::nullopt;
	const Vector3 x = blockI.edgeStart(edgeI) + deepest.t * (blockI.edgeEnd(edgeI) - blockI.edgeStart(edgeI));
	const FacePlane& plane = blockJ.faces[deepest.face];
	SubContact c;
	c.kind = ContactKind::EdgeEdge;
	c.firstIsA = !useA;
	c.feature1 = edgeI;
	c.feature2 = edgeJ;
	c.stencil = vertexFaceStencil(x, blockJ.corner(plane.corners[0]), blockJ.corner(plane.corners[1]),
	                              blockJ.corner(plane.corners[2]));
	bool valid = false;
	c.gap = stencilGap(c.stencil, valid);
	if (!valid || !(c.gap < -depth) || c.gap < lowest) return std::nullopt;
	c.normal = plane.normal;
	c.pointI = x;
	c.pointJ = x - c.gap * plane.normal;
	return c;
}

}  // namespace

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
// sank 0.13 mm into the other, tests/py/system/test_hard_cases.py, when its
// corners were bound by it).
void findSubContacts(const Prepared& a, const Prepared& b, const std::vector<FaceCandidate>& faces,
                     const AxisSearch& axes, const EntranceFeature& previous, const DetectionSettings& settings,
                     double sinTolerance, Scratch& s, Entrance& entrance, PairContacts& out) {
	const double tol = settings.lengthTolerance;
	// The bound is the largest separation over every axis tested
	// (deepestBound: faces, internal ones too, and the edge pairs that are not
	// near-parallel), never the entrance's own when that lies deeper: a
	// previous entrance kept by hysteresis may lie up to `hysteresis` deeper
	// than the best axis, and bounding by it let corners that deep below its
	// plane count as contacts. In a pile of 200 cubes at E = 1e11 Pa a cube
	// landing on another was given a corner contact 0.43 mm deep while the
	// cubes overlapped by 1.8 um: 363 kJ in its penalty spring, 37 times the
	// cube's kinetic energy (core 90eae68, the account's contactChanges).
	const double depthBound = std::max(entrance.separation, axes.deepestBound);
	const double crossingBound = std::max(depthBound, axes.nearParallelBest);
	std::optional<std::array<int, 2>> fallbackEdges;  // the edge entrance's edges, when it falls back
	out.normal = Vector3::UnitZ();  // the default, kept when no entrance sets it
	out.contacts.clear();
	if (entrance.feature.kind == EntranceFeature::EdgePair) {
		EdgeContactLimits limits;  // the crossing, too, no deeper than the bound
		limits.deepestGap = std::min(crossingBound, 0.0) - tol;
		std::optional<SubContact> c = edgeEdgeContact(true, a, entrance.feature.feature, b, entrance.feature.other,
		                                              settings, sinTolerance, limits);
		if (c) {
			out.normal = (axes.previousEdge.valid && entrance.feature == previous) ? axes.previousEdge.normal
			                                                                        : axes.bestEdge.normal;
			out.contacts.push_back(*c);
			otherFeaturesOfEdgeEntrance(a, b, chooseFace(faces, a, b, tol, previous).feature, depthBound,
			                            crossingBound, settings, sinTolerance, s, out.contacts);
			crossingsAcrossEntranceFaces(a, b, entrance.feature.feature, entrance.feature.other, crossingBound, settings,
			                             sinTolerance, s, out.contacts);
		} else {
			// The edges do not cross strictly inside (a corner meets an edge),
			// or their crossing is deeper than the bound: the best face is the
			// entrance, its separation the pair's reported one, but the depth
			// bound stays the edge axis's.
			fallbackEdges = {entrance.feature.feature, entrance.feature.other};
			const FaceCandidate& f = chooseFace(faces, a, b, tol, previous);
			entrance = {f.feature, f.separation};
		}
	}
	if (entrance.feature.kind == EntranceFeature::FaceOfA || entrance.feature.kind == EntranceFeature::FaceOfB) {
		out.normal = faceEntranceNormal(a, b, entrance.feature);
		entranceFaceContacts(a, b, entrance.feature, depthBound, crossingBound, settings, sinTolerance, s,
		                     out.contacts);
	}
	if (fallbackEdges)
		cornersOfEdgeEntrance(a, (*fallbackEdges)[0], b, (*fallbackEdges)[1], depthBound, settings, out.contacts);
	if (out.contacts.empty() && entrance.feature.kind != EntranceFeature::EdgePair)
		tiedFaceContacts(a, b, faces, axes, depthBound, crossingBound, settings, sinTolerance, s, entrance, out);
	// Near-parallel edges that overlap, with no sub-contact pushing the pair
	// apart (nearParallelEdgeContact; the argument at the top of this file).
	// Made once the pair overlaps by more than lengthTolerance, the contact is
	// kept while it overlaps at all (keptEdgePoint).
	const double pairSeparation = std::max(depthBound, axes.nearParallelBest);
	const KeptEdgePoint& kept = settings.keptEdgePoint;
	const bool keep = kept.edge >= 0 && kept.edge == (kept.onA ? axes.nearParallelEdgeA : axes.nearParallelEdgeB) &&
	                  kept.otherEdge == (kept.onA ? axes.nearParallelEdgeB : axes.nearParallelEdgeA);
	const double depth = keep ? 0.0 : tol;
	if (axes.nearParallelEdgeA >= 0 && pairSeparation < -depth &&
	    std::none_of(out.contacts.begin(), out.contacts.end(), [](const SubContact& c) { return c.gap < 0; })) {
		const std::optional<SubContact> c = nearParallelEdgeContact(a, axes.nearParallelEdgeA, b, axes.nearParallelEdgeB,
		                                                            depth, tol, pairSeparation - tol, keep ? &kept : nullptr);
		if (c) out.contacts.push_back(*c);
	}
}

}  // namespace dda::narrow
