// Near-parallel edges that overlap (SubContactRules.hpp): two edges parallel
// within the angle tolerance have no crossing, and their contact is the
// vertex contacts at their ends; when they cross inside both segments with
// every end outside the other block, the overlap lies at no corner. Then the
// point of either edge deepest inside the other block (or the last step's
// point while at least half as deep) gets a vertex-face stencil against its
// own entrance face, keyed as the two edges' edge-edge contact.
// Invariant: made only while the pair overlaps and none of its sub-contacts
// has a negative gap; its gap is minus a point's depth inside the other block,
// no deeper than the pair's penetration (`lowest`). Guarded by
// ContactDetection.NearParallelEdgesCrossingInsideHaveAContactAsDeepAsTheirOverlap
// and NearParallelEdgeContactKeepsItsPointWhileHalfAsDeep
// (tests/cpp/contact/test_contact_detection.cpp), ContactCoverage
// (test_contact_coverage.cpp) and the mutation kept-edge-point
// (tests/mutations/). Why a point and not the crossing, and what was tried:
// doc/DESIGN.md, Contacts, item 2. Units: m.
#include "SubContactRules.hpp"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

namespace dda::narrow::rules {

namespace {

// The point of edge e of `block` deepest inside `other`: x(t) = start + t
// (end - start), t in [0, 1], minimising h(t) = max over every face g of
// `other` of the distance of x(t) above g's plane (minus its depth inside).
// h is convex and piecewise affine, so its minimum lies at t = 0, t = 1 or
// where two faces' distances are equal; every such t is tried. Divisions only
// by a nonzero difference of slopes, a quotient used only within [0, 1]: no NaN.
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

}  // namespace

// Of the two edges' deepest points the deeper (A's edge on a tie), a fixed
// point of its block for the step, against that block's face it lies
// farthest above; keyed as the edge-edge contact (edge of block i, edge of
// block j), so that the crossing that takes over past the angle tolerance
// inherits its history. Nothing when no point lies inside the other block by
// more than `depth`, when the point lies across an internal face, or when its
// gap is below `lowest`.
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

}  // namespace dda::narrow::rules
