#include "PairDetection.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace dda {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using ExactPoint = Kernel::Point_3;
using ExactVector = Kernel::Vector_3;

// A double distance from a plane (or between two lines) below this fraction of
// the lengths it is computed from is round-off (dimensionless): its sign is
// then decided exactly by CGAL. Rule: the distance carries an error of a few
// DBL_EPSILON x (lengths involved) x (conditioning of the face triangle, which
// chooseFaceCorners keeps near 1); 1e-12 is ~4500 DBL_EPSILON, far above that
// and far below kDefaultRelativeLengthTolerance (1e-8).
constexpr double kRoundoffRelative = 1e-12;

// Two face areas within this fraction of each other tie (dimensionless), so
// identical blocks are ordered by block and face index, not by round-off.
// Rule: above the round-off of an area (~1e-15), below any real difference.
constexpr double kAreaTieRelative = 1e-9;

// An edge-edge sub-contact of a face entrance may penetrate at most this many
// times the entrance's penetration, plus max(d0, lengthTolerance)
// (dimensionless). A crossing whose line distance is much deeper than the
// pair's penetration is an edge piercing the face steeply near its boundary:
// its normal lies in the face and would push the block sideways by that depth.
constexpr double kEdgePenetrationFactor = 2;

// An edge-edge sub-contact of a face entrance must push within 60 degrees of
// the face's normal: cosine of that angle (dimensionless). An edge crossing a
// face's edge steeply (along the face normal) has its line distance in the
// face's plane; that contact belongs to the neighbouring face, and the
// vertex-face contacts of its corners already hold the pair along the normal.
constexpr double kEdgeNormalMinCosine = 0.5;

ExactPoint exactPoint(const Vector3& p) { return ExactPoint(p.x(), p.y(), p.z()); }
ExactVector exactVector(const Vector3& v) { return ExactVector(v.x(), v.y(), v.z()); }

// A face's plane: the chooseFaceCorners triangle (counter-clockwise seen from
// outside), its unit normal, and the polygon's area.
struct FacePlane {
	std::array<int, 3> corners{};
	Vector3 normal = Vector3::UnitZ();
	double area = 0;  // [m^2]
};

// A block with the per-call data the narrow phase needs.
struct Prepared {
	const ConvexPolyhedron* shape = nullptr;
	const std::vector<Vector3>* vertices = nullptr;
	Vector3 centroid = Vector3::Zero();
	std::vector<FacePlane> faces;
	Vector3 lower = Vector3::Zero(), upper = Vector3::Zero();  // bounding box [m]

	const Vector3& corner(int v) const { return (*vertices)[v]; }
	int cornerCount() const { return static_cast<int>(vertices->size()); }
	int faceCount() const { return static_cast<int>(faces.size()); }
	int edgeCount() const { return static_cast<int>(shape->edges.size()); }
	const Vector3& edgeStart(int e) const { return corner(shape->edges[e][0]); }
	const Vector3& edgeEnd(int e) const { return corner(shape->edges[e][1]); }
	// Sum of the outward normals of the two faces sharing edge e: points out
	// of the block at the edge.
	Vector3 edgeOutward(int e) const {
		return faces[shape->edgeFaces[e][0]].normal + faces[shape->edgeFaces[e][1]].normal;
	}
};

Prepared prepare(const BlockGeometry& block) {
	Prepared p;
	p.shape = block.shape;
	p.vertices = block.vertices;
	p.centroid = block.centroid;
	const std::vector<Vector3>& v = *block.vertices;
	p.lower = p.upper = v.front();
	for (const Vector3& x : v) {
		p.lower = p.lower.cwiseMin(x);
		p.upper = p.upper.cwiseMax(x);
	}
	p.faces.reserve(block.shape->faces.size());
	for (const std::vector<int>& face : block.shape->faces) {
		FacePlane plane;
		plane.corners = chooseFaceCorners(v, face);
		const Vector3& f0 = v[plane.corners[0]];
		const Vector3 cross = (v[plane.corners[1]] - f0).cross(v[plane.corners[2]] - f0);
		plane.normal = cross.normalized();
		// Polygon area from the fan about its first corner.
		Vector3 vectorArea = Vector3::Zero();
		for (std::size_t k = 1; k + 1 < face.size(); ++k)
			vectorArea += (v[face[k]] - v[face[0]]).cross(v[face[k + 1]] - v[face[0]]);
		plane.area = 0.5 * vectorArea.norm();
		p.faces.push_back(plane);
	}
	return p;
}

// Signed distance [m] of x from the plane of face f of `block`, > 0 outside.
// Below round-off the sign is decided exactly: a point exactly on the
// triangle's plane gets exactly 0, a point whose double distance has the
// wrong sign gets 0.
double planeDistance(const Prepared& block, int f, const Vector3& x) {
	const FacePlane& plane = block.faces[f];
	const Vector3& f0 = block.corner(plane.corners[0]);
	const Vector3& f1 = block.corner(plane.corners[1]);
	const Vector3& f2 = block.corner(plane.corners[2]);
	const double d = plane.normal.dot(x - f0);
	const double scale = (x - f0).norm() + (f1 - f0).norm() + (f2 - f0).norm();
	if (std::abs(d) > kRoundoffRelative * scale) return d;
	const CGAL::Orientation side = CGAL::orientation(exactPoint(f0), exactPoint(f1), exactPoint(f2), exactPoint(x));
	if (side == CGAL::COPLANAR) return 0;
	const bool outside = side == CGAL::POSITIVE;
	return (outside == (d > 0)) ? d : 0;
}

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

// Two edge directions are parallel: exactly (cross product of the double
// vectors zero, decided by CGAL) or within the angle tolerance.
bool parallelDirections(const Vector3& da, const Vector3& db, double angleTolerance) {
	if (CGAL::collinear(ExactPoint(0, 0, 0), exactPoint(da), exactPoint(db))) return true;
	return da.cross(db).norm() <= std::sin(angleTolerance) * da.norm() * db.norm();
}

// Do the Gauss-map arcs (a1, a2) and (c, d) cross (strictly)? Signs of triple
// products decided exactly (Gregorius, "The separating axis test between
// convex polyhedra", GDC 2013).
bool arcsCross(const Vector3& a1, const Vector3& a2, const Vector3& c, const Vector3& d) {
	const ExactVector A = exactVector(a1), B = exactVector(a2), C = exactVector(c), D = exactVector(d);
	const int cba = static_cast<int>(CGAL::orientation(C, B, A));  // C . (B x A)
	const int dba = static_cast<int>(CGAL::orientation(D, B, A));
	const int adc = static_cast<int>(CGAL::orientation(A, D, C));  // A . (D x C)
	const int bdc = static_cast<int>(CGAL::orientation(B, D, C));
	return cba * dba < 0 && adc * bdc < 0 && cba * bdc > 0;
}

// Separation [m] along the outward normal of face f of `owner`: the smallest
// signed distance of `other`'s corners from the face's plane.
double faceSeparation(const Prepared& owner, int f, const Prepared& other) {
	double separation = std::numeric_limits<double>::infinity();
	for (int v = 0; v < other.cornerCount(); ++v)
		separation = std::min(separation, planeDistance(owner, f, other.corner(v)));
	return separation;
}

struct EdgeAxis {
	bool valid = false;
	double separation = 0;              // [m]
	Vector3 normal = Vector3::UnitZ();  // unit, from A towards B
};

// Edge axis of edge ea of A and eb of B when the two edges form a face of the
// Minkowski difference and are not parallel.
EdgeAxis edgeAxis(const Prepared& a, int ea, const Prepared& b, int eb, double angleTolerance) {
	EdgeAxis axis;
	const Vector3& a0 = a.edgeStart(ea);
	const Vector3& a1 = a.edgeEnd(ea);
	const Vector3& b0 = b.edgeStart(eb);
	const Vector3& b1 = b.edgeEnd(eb);
	const Vector3 da = a1 - a0, db = b1 - b0;
	if (parallelDirections(da, db, angleTolerance)) return axis;
	const auto& fa = a.shape->edgeFaces[ea];
	const auto& fb = b.shape->edgeFaces[eb];
	if (!arcsCross(a.faces[fa[0]].normal, a.faces[fa[1]].normal, -b.faces[fb[0]].normal,
	               -b.faces[fb[1]].normal))
		return axis;
	Vector3 n = da.cross(db).normalized();
	if (n.dot(a0 - a.centroid) < 0) n = -n;
	double separation = n.dot(b0 - a0);
	const double scale = (b0 - a0).norm() + da.norm() + db.norm();
	if (std::abs(separation) <= kRoundoffRelative * scale &&
	    CGAL::orientation(exactPoint(a0), exactPoint(a1), exactPoint(b0), exactPoint(b1)) == CGAL::COPLANAR)
		separation = 0;
	axis.valid = true;
	axis.separation = separation;
	axis.normal = n;
	return axis;
}

struct FaceCandidate {
	EntranceFeature feature;
	double separation = 0;
	double area = 0;
};

// The entrance face among the face axes: largest separation; within
// lengthTolerance of it, the previous entrance face if it is one of them, else
// the larger area, then A before B, then the lower face index (the order of
// `faces`).
const FaceCandidate& chooseFace(const std::vector<FaceCandidate>& faces, double lengthTolerance,
                                const EntranceFeature& previous) {
	double best = -std::numeric_limits<double>::infinity();
	for (const FaceCandidate& c : faces) best = std::max(best, c.separation);
	const FaceCandidate* chosen = nullptr;
	for (const FaceCandidate& c : faces) {
		if (c.separation < best - lengthTolerance) continue;
		if (c.feature == previous) return c;
		if (!chosen || c.area > chosen->area * (1 + kAreaTieRelative)) chosen = &c;
	}
	return *chosen;
}

// ------------------------------------------------------------ sub-contacts

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
	c.gap = linearizeNormalDistance(c.stencil, blockI.centroid, blockJ.centroid).d0;
	c.normal = plane.normal;
	c.pointI = p;
	c.pointJ = p - c.gap * plane.normal;
	return c;
}

// Edge-edge sub-contact of edge e1 of block i and e2 of block j, or nothing
// when the edges are parallel or their closest points are not strictly inside
// both segments (more than lengthTolerance from every endpoint).
std::optional<SubContact> edgeEdgeContact(bool firstIsA, const Prepared& blockI, int e1, const Prepared& blockJ,
                                          int e2, const DetectionSettings& settings) {
	const Vector3& p1 = blockI.edgeStart(e1);
	const Vector3& p2 = blockI.edgeEnd(e1);
	const Vector3& p3 = blockJ.edgeStart(e2);
	const Vector3& p4 = blockJ.edgeEnd(e2);
	const Vector3 da = p2 - p1, db = p4 - p3;
	if (parallelDirections(da, db, settings.angleTolerance)) return std::nullopt;
	// From block i towards block j: out of i at its edge, into j at its edge.
	const Vector3 reference = blockI.edgeOutward(e1) - blockJ.edgeOutward(e2);
	const EdgeEdgeResult r =
	    edgeEdgeDistance(p1, p2, p3, p4, reference, settings.lengthTolerance, settings.angleTolerance);
	if (r.parallel || !r.interior) return std::nullopt;
	const double tol = settings.lengthTolerance;
	const double la = da.norm(), lb = db.norm();
	if (r.s * la <= tol || (1 - r.s) * la <= tol || r.t * lb <= tol || (1 - r.t) * lb <= tol) return std::nullopt;
	SubContact c;
	c.kind = ContactKind::EdgeEdge;
	c.firstIsA = firstIsA;
	c.feature1 = e1;
	c.feature2 = e2;
	c.stencil = edgeEdgeStencil(p1, p2, p3, p4, reference);
	const LinearizedDistance lin = linearizeNormalDistance(c.stencil, blockI.centroid, blockJ.centroid);
	if (!lin.valid) return std::nullopt;
	c.gap = lin.d0;
	// The stencil's n = -sigma (a x b)/|a x b| points from i to j.
	c.normal = c.stencil.sigma * da.cross(db).normalized();
	c.pointI = r.closestI;
	c.pointJ = r.closestJ;
	return c;
}

// Step 3 for a face entrance: face f of block `owner` (block j of every
// vertex-face contact of the other block's corners) entered by block `other`.
void faceEntranceContacts(const Prepared& owner, bool ownerIsA, int f, const Prepared& other, double separation,
                          const DetectionSettings& settings, std::vector<SubContact>& out) {
	// Within d0, to the length tolerance: a face is planar only to within it, so
	// a corner touching a face may lie that far off the face's triangle plane.
	const double reach = settings.contactDistance + settings.lengthTolerance;

	// Corners of the other block on the face.
	std::vector<int> used;
	for (int v = 0; v < other.cornerCount(); ++v) {
		const Vector3& p = other.corner(v);
		if (planeDistance(owner, f, p) > reach) continue;
		if (insideMargin(owner, f, p) < -reach) continue;
		out.push_back(vertexFaceContact(!ownerIsA, other, v, owner, f));
		used.push_back(v);
	}

	// Corners of the face near the other block, against their own entrance face.
	for (int q : owner.shape->faces[f]) {
		const Vector3& x = owner.corner(q);
		bool coincident = false;  // with a corner used above
		const double merge = std::max(settings.cornerMergeDistance, settings.lengthTolerance);
		for (int v : used) coincident = coincident || (other.corner(v) - x).norm() <= merge;
		if (coincident) continue;
		int bestFace = -1;
		double bestDistance = -std::numeric_limits<double>::infinity();
		for (int g = 0; g < other.faceCount(); ++g) {
			const double d = planeDistance(other, g, x);
			if (d > bestDistance) {
				bestDistance = d;
				bestFace = g;
			}
		}
		if (bestDistance > reach) continue;
		if (insideMargin(other, bestFace, x) < -reach) continue;
		out.push_back(vertexFaceContact(ownerIsA, owner, q, other, bestFace));
	}

	// Edges of the other block crossing the face's edges.
	const double deepest = kEdgePenetrationFactor * std::min(separation, 0.0) - reach;
	std::vector<int> faceEdges;
	for (int e = 0; e < owner.edgeCount(); ++e) {
		const auto& ef = owner.shape->edgeFaces[e];
		if (ef[0] == f || ef[1] == f) faceEdges.push_back(e);
	}
	for (int e = 0; e < other.edgeCount(); ++e) {
		const double low = std::min(planeDistance(owner, f, other.edgeStart(e)),
		                            planeDistance(owner, f, other.edgeEnd(e)));
		if (low > reach) continue;
		for (int g : faceEdges) {
			std::optional<SubContact> c = edgeEdgeContact(!ownerIsA, other, e, owner, g, settings);
			if (!c || c->gap > reach || c->gap < deepest) continue;
			if (c->normal.dot(owner.faces[f].normal) < kEdgeNormalMinCosine) continue;
			if (planeDistance(owner, f, c->pointI) > reach) continue;  // crosses far from the face
			out.push_back(*c);
		}
	}
}

// ------------------------------------------------------------ structural type

enum class FeatureKind { Vertex, Edge, Face };
struct Feature {
	FeatureKind kind = FeatureKind::Face;
	int index = -1;  // corner (Vertex) or edge (Edge)
};

double segmentDistance(const Vector3& x, const Vector3& p, const Vector3& q) {
	const Vector3 d = q - p;
	const double dd = d.squaredNorm();
	const double s = dd > 0 ? std::clamp(d.dot(x - p) / dd, 0.0, 1.0) : 0.0;
	return (x - (p + s * d)).norm();
}

// The smallest feature of `block` within `tolerance` [m] of all the points: one
// corner, else one edge, else a face.
Feature featureOf(const Prepared& block, const std::vector<Vector3>& points, double tolerance) {
	Feature out;
	if (points.empty()) return out;
	double bestCorner = std::numeric_limits<double>::infinity();
	for (int v = 0; v < block.cornerCount(); ++v) {
		double worst = 0;
		for (const Vector3& x : points) worst = std::max(worst, (x - block.corner(v)).norm());
		if (worst <= tolerance && worst < bestCorner) {
			bestCorner = worst;
			out = {FeatureKind::Vertex, v};
		}
	}
	if (out.kind == FeatureKind::Vertex) return out;
	double bestEdge = std::numeric_limits<double>::infinity();
	for (int e = 0; e < block.edgeCount(); ++e) {
		double worst = 0;
		for (const Vector3& x : points) worst = std::max(worst, segmentDistance(x, block.edgeStart(e), block.edgeEnd(e)));
		if (worst <= tolerance && worst < bestEdge) {
			bestEdge = worst;
			out = {FeatureKind::Edge, e};
		}
	}
	return out;
}

ContactType structuralType(const Prepared& a, const Feature& fa, const Prepared& b, const Feature& fb,
                           double angleTolerance) {
	const FeatureKind ka = fa.kind, kb = fb.kind;
	auto either = [&](FeatureKind x, FeatureKind y) { return (ka == x && kb == y) || (ka == y && kb == x); };
	if (either(FeatureKind::Vertex, FeatureKind::Vertex)) return ContactType::VertexVertex;
	if (either(FeatureKind::Vertex, FeatureKind::Edge)) return ContactType::VertexEdge;
	if (either(FeatureKind::Vertex, FeatureKind::Face)) return ContactType::VertexFace;
	if (either(FeatureKind::Edge, FeatureKind::Face)) return ContactType::EdgeFace;
	if (either(FeatureKind::Face, FeatureKind::Face)) return ContactType::FaceFace;
	const Vector3 da = a.edgeEnd(fa.index) - a.edgeStart(fa.index);
	const Vector3 db = b.edgeEnd(fb.index) - b.edgeStart(fb.index);
	return parallelDirections(da, db, angleTolerance) ? ContactType::EdgeEdgeParallel
	                                                  : ContactType::EdgeEdgeCrossing;
}

// Corners of `block` within `tolerance` of its extreme along `direction`.
std::vector<Vector3> supportCorners(const Prepared& block, const Vector3& direction, double tolerance) {
	double extreme = -std::numeric_limits<double>::infinity();
	for (int v = 0; v < block.cornerCount(); ++v) extreme = std::max(extreme, direction.dot(block.corner(v)));
	std::vector<Vector3> out;
	for (int v = 0; v < block.cornerCount(); ++v)
		if (direction.dot(block.corner(v)) >= extreme - tolerance) out.push_back(block.corner(v));
	return out;
}

}  // namespace

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

std::optional<PairContacts> detectPairContacts(const BlockGeometry& blockA, const BlockGeometry& blockB,
                                               const DetectionSettings& settings, const EntranceFeature& previous) {
	const double d0 = settings.contactDistance, tol = settings.lengthTolerance;

	// Bounding boxes widened by d0.
	const Prepared a = prepare(blockA);
	const Prepared b = prepare(blockB);
	for (int k = 0; k < 3; ++k) {
		if (b.lower(k) > a.upper(k) + d0 || a.lower(k) > b.upper(k) + d0) return std::nullopt;
	}

	// 1. Face axes, stopping at the first one farther than d0.
	std::vector<FaceCandidate> faces;
	faces.reserve(a.faces.size() + b.faces.size());
	for (int f = 0; f < a.faceCount(); ++f) {
		const double s = faceSeparation(a, f, b);
		if (s > d0) return std::nullopt;
		faces.push_back({{EntranceFeature::FaceOfA, f, -1}, s, a.faces[f].area});
	}
	for (int f = 0; f < b.faceCount(); ++f) {
		const double s = faceSeparation(b, f, a);
		if (s > d0) return std::nullopt;
		faces.push_back({{EntranceFeature::FaceOfB, f, -1}, s, b.faces[f].area});
	}
	double bestFace = -std::numeric_limits<double>::infinity();
	for (const FaceCandidate& c : faces) bestFace = std::max(bestFace, c.separation);

	// Edge axes of the Minkowski difference's faces.
	EdgeAxis bestEdge, previousEdge;
	int bestEdgeA = -1, bestEdgeB = -1;
	for (int ea = 0; ea < a.edgeCount(); ++ea) {
		for (int eb = 0; eb < b.edgeCount(); ++eb) {
			const EdgeAxis axis = edgeAxis(a, ea, b, eb, settings.angleTolerance);
			if (!axis.valid) continue;
			if (axis.separation > d0) return std::nullopt;
			if (previous.kind == EntranceFeature::EdgePair && previous.feature == ea && previous.other == eb)
				previousEdge = axis;
			if (!bestEdge.valid || axis.separation > bestEdge.separation) {
				bestEdge = axis;
				bestEdgeA = ea;
				bestEdgeB = eb;
			}
		}
	}
	const double best = bestEdge.valid ? std::max(bestFace, bestEdge.separation) : bestFace;

	// 2. The entrance feature.
	const double hysteresis = std::max(settings.hysteresis, tol);
	EntranceFeature entrance;
	double separation = 0;
	if (previous.kind == EntranceFeature::EdgePair && previousEdge.valid &&
	    previousEdge.separation >= best - hysteresis) {
		entrance = previous;
		separation = previousEdge.separation;
	} else {
		const FaceCandidate* previousFace = nullptr;
		for (const FaceCandidate& c : faces)
			if (c.feature == previous) previousFace = &c;
		if (previousFace && previousFace->separation >= best - hysteresis) {
			entrance = previousFace->feature;
			separation = previousFace->separation;
		} else if (bestEdge.valid && bestEdge.separation > bestFace + tol) {
			entrance = {EntranceFeature::EdgePair, bestEdgeA, bestEdgeB};
			separation = bestEdge.separation;
		} else {
			const FaceCandidate& c = chooseFace(faces, tol, previous);
			entrance = c.feature;
			separation = c.separation;
		}
	}

	// 3. Sub-contacts.
	PairContacts out;
	if (entrance.kind == EntranceFeature::EdgePair) {
		std::optional<SubContact> c = edgeEdgeContact(true, a, entrance.feature, b, entrance.other, settings);
		if (c) {
			out.normal = (previousEdge.valid && entrance == previous) ? previousEdge.normal : bestEdge.normal;
			out.contacts.push_back(*c);
		} else {
			const FaceCandidate& f = chooseFace(faces, tol, previous);
			entrance = f.feature;
			separation = f.separation;
		}
	}
	if (entrance.kind == EntranceFeature::FaceOfA) {
		out.normal = a.faces[entrance.feature].normal;
		faceEntranceContacts(a, true, entrance.feature, b, separation, settings, out.contacts);
	} else if (entrance.kind == EntranceFeature::FaceOfB) {
		out.normal = -b.faces[entrance.feature].normal;
		faceEntranceContacts(b, false, entrance.feature, a, separation, settings, out.contacts);
	}
	out.entrance = entrance;
	out.separation = separation;

	// 4. Structural type from the contact points of the sub-contacts.
	const double featureTolerance = d0 + tol;
	std::vector<Vector3> pointsA, pointsB;
	for (const SubContact& c : out.contacts) {
		pointsA.push_back(c.firstIsA ? c.pointI : c.pointJ);
		pointsB.push_back(c.firstIsA ? c.pointJ : c.pointI);
	}
	if (out.contacts.empty()) {
		pointsA = supportCorners(a, out.normal, featureTolerance);
		pointsB = supportCorners(b, -out.normal, featureTolerance);
	}
	out.type = structuralType(a, featureOf(a, pointsA, featureTolerance), b, featureOf(b, pointsB, featureTolerance),
	                          settings.angleTolerance);
	return out;
}

}  // namespace dda
