// Step 3 of the narrow phase (SubContacts.hpp): the dispatch of
// findSubContacts over the rule families of SubContactRules.hpp (one file
// each), the depth bound they share, the tied faces of a face entrance that
// finds nothing, and the near-parallel edge contact's trigger. Invariant: no
// sub-contact is deeper than the pair's penetration: a gap is at least
// min(depthBound, 0) - lengthTolerance (min(crossingBound, 0) for edge
// crossings), depthBound the largest separation over the axes tested; a
// translation of the penetration depth separates convex blocks and moves any
// gap by at most that much, so a deeper gap is a ghost (doc/DESIGN.md,
// Contacts, item 2). Guarded by
// NarrowPhaseOracle.RandomNearPairsAgainstExactSeparationAndDistance
// (tests/cpp/contact/test_narrow_phase_oracle.cpp: sub-contact gaps against a
// long-double separation and distance of random near pairs, and no pair
// within d0 without one), ContactDetection.GhostPairsOfTheDepositHaveNoNegativeGap
// (test_contact_detection.cpp), and the mutations corner-on-corner,
// entrance-depth-bound, edge-entrance-second-crossing and kept-edge-point
// (tests/mutations/). Units: m.
#include "SubContactRules.hpp"

#include <algorithm>
#include <array>
#include <optional>

namespace dda::narrow {

void rules::entranceFaceContacts(const Prepared& a, const Prepared& b, const EntranceFeature& face, double depthBound,
                                 double crossingBound, const DetectionSettings& settings, double sinTolerance,
                                 Scratch& s, std::vector<SubContact>& out) {
	if (face.kind == EntranceFeature::FaceOfA)
		faceEntranceContacts(a, true, face.feature, b, depthBound, crossingBound, settings, sinTolerance, s, out);
	else
		faceEntranceContacts(b, false, face.feature, a, depthBound, crossingBound, settings, sinTolerance, s, out);
}

namespace {

using rules::cornersOfEdgeEntrance;
using rules::crossingsAcrossEntranceFaces;
using rules::EdgeContactLimits;
using rules::edgeEdgeContact;
using rules::entranceFaceContacts;
using rules::nearParallelEdgeContact;
using rules::otherFeaturesOfEdgeEntrance;

// The pair's normal (from A towards B) when `face` is its entrance: the
// face's outward normal, negated for a face of B.
Vector3 faceEntranceNormal(const Prepared& a, const Prepared& b, const EntranceFeature& face) {
	return face.kind == EntranceFeature::FaceOfA ? a.faces[face.feature].normal : Vector3(-b.faces[face.feature].normal);
}

// A face entrance that found nothing, among faces tied with the best
// (within lengthTolerance): the next tied face that finds something is the
// entrance. Two halves of a nearly planar side tie, and the other block's
// corners may lie over the one of smaller area.
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

}  // namespace

// `depthBound` is the largest separation over every axis tested
// (deepestBound: faces, internal ones too, and the edge pairs that are not
// near-parallel), never a kept entrance's own when that lies deeper, and it
// stays the edge axis's when an edge entrance falls back to the best face
// (that face's own separation can lie a slender block's width deep). Edge
// pairs parallel within the angle tolerance bound the edge crossings
// (`crossingBound`), not the corners, which stand for such a contact along
// the entrance face.
void findSubContacts(const Prepared& a, const Prepared& b, const std::vector<FaceCandidate>& faces,
                     const AxisSearch& axes, const EntranceFeature& previous, const DetectionSettings& settings,
                     double sinTolerance, Scratch& s, Entrance& entrance, PairContacts& out) {
	const double tol = settings.lengthTolerance;
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
	// apart (nearParallelEdgeContact, ParallelEdges.cpp). Made once the pair
	// overlaps by more than lengthTolerance, the contact is kept while it
	// overlaps at all (keptEdgePoint).
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
