// An edge entrance (SubContactRules.hpp): with its two edges crossing (the
// crossing is out[0]), what the best face finds away from the crossing
// (otherFeaturesOfEdgeEntrance) and each entrance edge's second crossings with
// the faces at the other edge (crossingsAcrossEntranceFaces); with edges that
// do not cross strictly inside, after the fallback face's search, the two
// edges' ends against their own entrance faces (cornersOfEdgeEntrance).
// Invariant: nothing within the corner merge distance of the crossing or of a
// vertex contact is added again, and no crossing is deeper than
// min(crossingBound, 0) to the length tolerance; these rules only add
// contacts. Guarded by EdgeEntrance.AnEdgeAcrossAFaceAtTheOtherEdgeHasItsSecondCrossing
// (tests/cpp/contact/test_edge_entrance.cpp),
// ContactDetection.EdgeEntranceAlsoGivesTheFarCornersWithinContactDistance,
// EdgeEntranceOfCrossedLogsApartHasNoDeepSubContacts and
// GhostPairsOfTheDepositHaveNoNegativeGap (test_contact_detection.cpp),
// NarrowPhaseOracle.RandomNearPairsAgainstExactSeparationAndDistance (every
// near pair has a sub-contact), and the mutations corner-on-corner and
// edge-entrance-second-crossing (tests/mutations/). Units: m.
#include "SubContactRules.hpp"

#include <algorithm>
#include <cstddef>
#include <optional>
#include <vector>

namespace dda::narrow::rules {

namespace {

// Whether a point of sub-contact c lies within `merge` [m] of a point of the
// edge entrance's crossing: the crossing's own contact.
bool atCrossing(const SubContact& c, const SubContact& crossing, double merge) {
	for (const Vector3* p : {&c.pointI, &c.pointJ})
		if ((*p - crossing.pointI).norm() <= merge || (*p - crossing.pointJ).norm() <= merge) return true;
	return false;
}

}  // namespace

// A cube tilting onto another rocks on the crossing while its far corner
// comes down within d0: the best face axis finds it. What the face finds at
// the crossing itself (the same edge pair, or a point within the corner merge
// distance of it) is the crossing's contact and is left out. `depthBound` is
// the edge axis's separation (the pair's), `crossingBound` as for
// faceEntranceContacts.
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

// Once edge b crosses edge a and runs on over a face F at a, the pair touches
// along b over F, and F's boundary crosses b a second time; the best face
// finds that crossing only when it is F. Each such crossing is the edge-edge
// contact F's search would give (edge crossing F as i, F's edge as j, normal
// within 60 degrees of F's, not beside a vertex contact or the entrance
// crossing), found while within d0.
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

// The edge axis is the pair's best, so the blocks' closest features are a
// corner at an end of one edge and the other edge (or its end); the best
// face may lie far from them (crossed slender blocks: a block's width deep)
// and find nothing. An end that already has a vertex-face contact, or lies
// within the corner merge distance of a contact point found, is that contact.
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

}  // namespace dda::narrow::rules
