#include "StructuralType.hpp"

#include <algorithm>
#include <limits>

namespace dda::narrow {

namespace {

enum class FeatureKind { Vertex, Edge, Face };
struct Feature {
	FeatureKind kind = FeatureKind::Face;
	int index = -1;  // corner (Vertex) or edge (Edge)
};

// Which edges of `block` have a point outside their bounding box widened by
// `margin` [m] in some coordinate (s.farEdges[e] = 1): featureOf's edge test,
// from the corners' sides. Rounding is monotone, so fl(max(p, q) + margin) =
// max(fl(p + margin), fl(q + margin)) and fl(min(p, q) - margin) = min(fl(p -
// margin), fl(q - margin)): x is above edge pq's widened box in coordinate k
// exactly when above both corners' widened coordinates, and below exactly when
// below both (a NaN compares false either way). So an edge's sides are the AND
// of its corners' (bit k: above in coordinate k, bit 3 + k: below), computed
// once per corner and point instead of per edge and point: the same
// comparisons of the same doubles as the box test of each edge.
void markFarEdges(const Prepared& block, const std::vector<Vector3>& points, double margin, Scratch& s) {
	std::vector<unsigned char>& sides = s.cornerSides;
	std::vector<char>& far = s.farEdges;
	sides.resize(block.cornerCount());
	far.assign(block.edgeCount(), 0);
	const auto& edges = block.shape->edges;
	for (const Vector3& x : points) {
		for (int v = 0; v < block.cornerCount(); ++v) {
			const Vector3& c = block.corner(v);
			unsigned bits = 0;
			for (int k = 0; k < 3; ++k) {
				bits |= static_cast<unsigned>(x(k) > c(k) + margin) << k;
				bits |= static_cast<unsigned>(x(k) < c(k) - margin) << (3 + k);
			}
			sides[v] = static_cast<unsigned char>(bits);
		}
		for (int e = 0; e < block.edgeCount(); ++e) far[e] |= (sides[edges[e][0]] & sides[edges[e][1]]) != 0;
	}
}

// The smallest feature of `block` within `tolerance` [m] of all the points: one
// corner, else one edge, else a face.
//
// Most corners and edges are far from the points; a coordinate difference
// rejects them without a square root. The rejections are those of the
// distances themselves: a computed norm is at least any |component| of its
// vector to within 2 DBL_EPSILON relative, and a computed segment distance is
// at least x's distance from the segment's bounding box along an axis, to
// within a few DBL_EPSILON of the coordinates (the closest point is rounded);
// the margins 1e-12 cover both. The edges' box tests are markFarEdges'.
Feature featureOf(const Prepared& block, const std::vector<Vector3>& points, double tolerance, Scratch& s) {
	Feature out;
	if (points.empty()) return out;
	const double reach = tolerance * (1 + 1e-12);
	double bestCorner = std::numeric_limits<double>::infinity();
	for (int v = 0; v < block.cornerCount(); ++v) {
		const Vector3& c = block.corner(v);
		bool far = false;
		for (const Vector3& x : points) {
			if ((x - c).cwiseAbs().maxCoeff() > reach) {
				far = true;
				break;
			}
		}
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
	markFarEdges(block, points, margin, s);
	for (int e = 0; e < block.edgeCount(); ++e) {
		if (s.farEdges[e]) continue;
		const Vector3& p = block.edgeStart(e);
		const Vector3& q = block.edgeEnd(e);
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

}  // namespace

ContactType classifyPair(const Prepared& a, const Prepared& b, const PairContacts& pair, double featureTolerance,
                         double sinTolerance, Scratch& s) {
	std::vector<Vector3>& pointsA = s.pointsA;
	std::vector<Vector3>& pointsB = s.pointsB;
	pointsA.clear();
	pointsB.clear();
	for (const SubContact& c : pair.contacts) {
		pointsA.push_back(c.firstIsA ? c.pointI : c.pointJ);
		pointsB.push_back(c.firstIsA ? c.pointJ : c.pointI);
	}
	if (pair.contacts.empty()) {
		supportCorners(a, pair.normal, featureTolerance, pointsA);
		supportCorners(b, -pair.normal, featureTolerance, pointsB);
	}
	return structuralType(a, featureOf(a, pointsA, featureTolerance, s), b, featureOf(b, pointsB, featureTolerance, s),
	                      sinTolerance);
}

}  // namespace dda::narrow

namespace dda {

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

}  // namespace dda
