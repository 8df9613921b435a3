// A corner against its own entrance face (SubContactRules.hpp): the
// vertex-face sub-contact of a corner of one block on the exposed face of the
// other it lies farthest above, used for corners no entrance face measures
// (a face's own corners, fold corners, corners past a face's edge, an edge
// entrance's ends). Internal (flush-covered) faces of fixed blocks are no
// entrance but count in how far the corner lies outside. Invariant: the gap
// is within `reach` and no deeper than the pair's penetration (`lowest`),
// except for a corner inside the fixed mass at a covered seam, which keeps
// its gap (the seam rule); the rules only leave contacts out or keep one, so
// they create no energy (doc/DESIGN.md, Contacts: the covered-face rules and
// "Energy of the sub-contact rules"). Guarded by
// tests/cpp/contact/test_internal_face_rules.cpp, test_covered_seam.cpp and the
// mutations internal-face-own-entrance, own-entrance-ridge, covered-seam,
// covered-seam-depth and covered-seam-cover-planes (tests/mutations/).
// Units: m.
#include "SubContactRules.hpp"

#include <algorithm>
#include <limits>
#include <vector>

namespace dda::narrow::rules {

namespace {

// Whether x lies in the fixed mass at a seam of `other`: past at most one
// internal face g of `other` (the one x is farthest past), no farther past
// g's plane than g's flush neighbour surely reaches (coverDepth, less
// `tolerance`), projecting into g (to `tolerance`), and at least `below`
// inside the neighbour from its faces but the covering one (depthInCover),
// so that a ball of radius `below` about x stays in the fixed mass. Then a
// gap of -below against an exposed face is no deeper than x's true
// penetration of the fixed mass (doc/DESIGN.md, Contacts: the seam rule).
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

}  // namespace

// G, the entrance-eligible face q lies farthest above, when that distance is
// within `reach` and q's projection within `reach` of G. Outside `other` the
// gap is positive (a plane separates a point from a convex block); inside,
// minus q's distance to the boundary, which the penetration depth bounds.
// `farthest` counts internal faces too: a corner more than `reach` across an
// internal face, on the flush neighbour's side, is that pair's contact.
// Below `lowest` (minus the pair's penetration) q keeps its contact only
// inside the fixed mass at a covered seam (insideCoveredSeam).
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
	// The ridge rule: q beyond two or more internal faces of `other` (each
	// farther above than q lies above G), below G's plane and beyond G's
	// boundary sits at a covered ridge or corner of `other`, held by its
	// neighbours; the gap against G's plane measures no overlap. Beyond one
	// internal face only (a flush floor's seam) both blocks hold q.
	if (bestDistance < -tolerance && bestDistance < farthest - tolerance &&
	    insideMargin(other, bestFace, x) < -tolerance) {
		int beyond = 0;
		for (int g = 0; g < other.faceCount(); ++g)
			if (other.internal(g) && planeDistance(other, g, x) > bestDistance + tolerance) ++beyond;
		if (beyond >= 2) return;
	}
	out.push_back(vertexFaceContact(blockIsA, block, q, other, bestFace));
}

}  // namespace dda::narrow::rules
