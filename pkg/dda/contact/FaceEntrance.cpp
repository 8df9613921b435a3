// A face entrance's search (SubContactRules.hpp): for entrance face f of one
// block entered by the other, the vertex-face contacts of the other block's
// corners on f, f's own corners against their own entrance face, the
// edge-edge contacts of edges crossing f's edges, and the corners measured
// elsewhere: past f's edge outside f's block (outsideBeyondFaceEdge), not
// f's (the fold rule), and f's block's corners beside f
// (ownerCornersBesideFace). Invariant: no corner deeper than min(depthBound,
// 0), no crossing deeper than min(crossingBound, 0), to the length
// tolerance; a crossing beside a vertex contact pushing the same way is that
// contact. Guarded by NarrowPhaseOracle.RandomNearPairsAgainstExactSeparationAndDistance
// (tests/cpp/contact/test_narrow_phase_oracle.cpp), FoldCorner and
// FoldCornerOwner (test_fold_corner*.cpp),
// ContactDetection.CornerPastAFaceEdgeOutsideTheBlockHasNoNegativeGap and
// OverlapOfTurnedLogsIsRepresentedByASubContact, ContactCoverage
// (test_contact_coverage.cpp), and the mutations vertex-across-face-boundary,
// fold-corner and fold-corner-owner (tests/mutations/). Units: m.
#include "SubContactRules.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace dda::narrow::rules {

namespace {

// A crossing beside a vertex contact is that contact only if their normals
// are within about 25 degrees (dimensionless cosine).
constexpr double kSameNormalCosine = 0.9;

// Whether corner v of `block`, below the plane of face f of `owner`, lies
// outside `owner` beyond the boundary of f: above the plane of an exposed
// face of `owner` by more than `tolerance` [m], its projection beyond an edge
// of f by more than `tolerance`, and no edge of `block` at v parallel (sine
// `sinTolerance`) to an edge of f it lies beyond. Such a corner is in no part
// of `owner`, so its distance below f's plane is no overlap: it is measured
// against its own entrance face (ownEntranceContact), at a positive gap. A
// corner with an edge along f's edge stays on f (it stands for the vertex of
// the overlap where the near-parallel edges meet), as does one past no edge
// of f (doc/DESIGN.md, Contacts, item 2, and "Energy of the sub-contact rules").
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

// The fold rule's symmetric case: each corner q of `owner` not on f, within
// d0 of `other` along f's normal (`other` lies at least `above` [m] over f's
// plane), against its own entrance face of `other` (ownEntranceContact),
// appended to `out`; a corner within `merge` [m] of a contact point found is
// that contact's. A slab resting on f near one end and reaching over a
// shallow fold has the far corners beside f within d0 of it.
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

// Corners of face f near the other block, against their own entrance face;
// a corner within `merge` [m] of a corner in `used` (a vertex-face contact
// on f) is that contact.
void faceCornersAgainstOwnEntrance(const Prepared& owner, bool ownerIsA, int f, const Prepared& other,
                                   const std::vector<int>& used, double merge, double reach, double tolerance,
                                   double lowest, std::vector<SubContact>& out) {
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
		ownEntranceContact(owner, ownerIsA, q, other, reach, tolerance, lowest, out);
	}
}

}  // namespace

// Only a vertex-face contact whose normal is within acos(kSameNormalCosine)
// counts: a crossing pushing another way is a different contact, even beside
// a corner (two turned logs side by side).
bool besideVertexContact(const SubContact& crossing, const std::vector<SubContact>& found, double merge) {
	for (const SubContact& other : found) {
		if (other.kind != ContactKind::VertexFace) continue;
		if (std::abs(other.normal.dot(crossing.normal)) < kSameNormalCosine) continue;
		if ((other.pointI - crossing.pointI).norm() <= merge || (other.pointI - crossing.pointJ).norm() <= merge)
			return true;
	}
	return false;
}

void edgesOfFace(const Prepared& owner, int f, std::vector<int>& out) {
	out.clear();
	for (int e : owner.edgeList) {
		const auto& ef = owner.shape->edgeFaces[e];
		if (ef[0] == f || ef[1] == f) out.push_back(e);
	}
}

// `owner` is block j of every vertex-face contact of the other block's
// corners. `depthBound` is the pair's separation as findSubContacts takes it;
// it is f's own only when f bounds the penetration: for an edge entrance's
// face search or fallback, f's plane may lie a block's width inside the
// other block. The fold rule: a corner within d0 of f's plane that is not
// f's (its projection more than d0 from f, or deeper below the plane than the
// penetration) is measured against its own entrance face G; every corner
// within d0 of `owner` over a face beside f is in this band, since f is
// exposed (doc/DESIGN.md, Contacts, item 2).
void faceEntranceContacts(const Prepared& owner, bool ownerIsA, int f, const Prepared& other, double depthBound,
                          double crossingBound, const DetectionSettings& settings, double sinTolerance, Scratch& s,
                          std::vector<SubContact>& out) {
	// Within d0, to the length tolerance: a face is planar only to within it, so
	// a corner touching a face may lie that far off the face's triangle plane.
	const double reach = settings.contactDistance + settings.lengthTolerance;
	const std::size_t start = out.size();
	// The other block's corners' distances from f's plane, each computed when first needed.
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
	// Corners of the other block on f, none deeper than the pair's penetration.
	// One not f's (the fold rule) or outside `owner` past f's edge is measured on
	// its own face after the crossings, so that it stands for no crossing.
	const double lowest = std::min(depthBound, 0.0) - settings.lengthTolerance;
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
	const double merge = std::max(settings.cornerMergeDistance, settings.lengthTolerance);
	faceCornersAgainstOwnEntrance(owner, ownerIsA, f, other, used, merge, reach, settings.lengthTolerance, lowest, out);
	// Edges of the other block crossing the face's edges, no deeper than
	// `crossingBound` allows, not beside a vertex contact found above.
	const double deepest = std::min(crossingBound, 0.0) - settings.lengthTolerance;
	std::vector<int>& faceEdges = s.faceEdges;
	edgesOfFace(owner, f, faceEdges);
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

}  // namespace dda::narrow::rules
