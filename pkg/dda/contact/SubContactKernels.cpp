// Sub-contact kernels of step 3 (SubContactRules.hpp): one vertex-face or
// edge-edge sub-contact (stencil, gap, normal, contact points) and whether a
// point projects into or near a face. The other rule families decide which
// features to pair; these give the gap every family bounds by the pair's
// penetration. Invariant: the early rejections of edgeEdgeContact (signs of
// numerators, the lines' distance against the limits) only reject what the
// full computation rejects, so the contacts are the same with or without
// them, bit for bit. Guarded by NarrowPhaseOracle.RandomNearPairsAgainstExactSeparationAndDistance
// (tests/cpp/contact/test_narrow_phase_oracle.cpp: gaps against a long-double
// separation) and the closed forms of tests/cpp/contact/test_contact_detection.cpp.
// Units: m.
#include "SubContactRules.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace dda::narrow::rules {

namespace {

// Whether insideMargin(block, f, x) >= 0, told from signs alone where they
// suffice (true: it is; false: not known). For an edge with length > 0,
// fl(dot / length) has the sign of dot (an underflow gives a zero of that
// sign, and -0 >= 0), so the margin is >= 0 when every such edge has dot >= 0
// (a NaN dot fails here, as insideMargin's std::min passes it over); length >
// 0 exactly when the squared norm is. Any other case takes the full margin.
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

}  // namespace

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

// A corner just past a face's edge or corner makes a contact with it;
// measured as a distance so that near an acute corner of the face, too, the
// corner is within sqrt(2) reach of the face.
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

// The tests before the stencil only reject, so their order changes no result.
std::optional<SubContact> edgeEdgeContact(bool firstIsA, const Prepared& blockI, int e1, const Prepared& blockJ,
                                          int e2, const DetectionSettings& settings, double sinTolerance,
                                          const EdgeContactLimits& limits) {
	const Vector3& p1 = blockI.edgeStart(e1);
	const Vector3& p2 = blockI.edgeEnd(e1);
	const Vector3& p3 = blockJ.edgeStart(e2);
	const Vector3& p4 = blockJ.edgeEnd(e2);
	const Vector3 da = p2 - p1, db = p4 - p3;
	const Vector3 cross = da.cross(db);
	// Most edge pairs have their lines' closest points outside a segment:
	// rejected first, on the line parameters edgeEdgeDistance computes by
	// these same expressions (a clamped value fails the endpoint test too).
	const Vector3 w = p3 - p1;
	const double sNumerator = w.cross(db).dot(cross);
	double tNumerator;
	{
		// Without a square root: sLine = sNumerator / nn, nn > 0, so a negative
		// numerator gives sLine < 0 (or -0), and nn is cross.squaredNorm() to a
		// few DBL_EPSILON, so a numerator above (1 + 1e-12) squaredNorm gives
		// sLine > 1. s's test before t's numerator is computed.
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
		// The gap limits on the lines' distance, before the stencil: its |gap|
		// is |Delta| / crossNorm, Delta exactly -w . cross; `margin` bounds the
		// round-off of both triple products (10 DBL_EPSILON times their factors'
		// 1-norms, taken as 1e-12), so a distance beyond a limit by more than it
		// means a gap outside that limit.
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
	// The closest points edgeEdgeDistance(p1, p2, p3, p4, reference, tol,
	// angleTolerance) gives, without calling it: for edges it finds not
	// parallel (sinTolerance is its sine) and interior (tol >= 0) its s, t are
	// sLine, tLine. Otherwise (never for valid settings and corners) it is called.
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

}  // namespace dda::narrow::rules
