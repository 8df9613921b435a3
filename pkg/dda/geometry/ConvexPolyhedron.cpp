// Builds the face/edge topology of a convex DDA block from its corner points.
//
// Pipeline (one function per step):
//   1. validate the raw points (count, finiteness, distinctness, volume);
//   2. hull the points with CGAL (triangles, outward);
//   3. merge adjacent hull triangles that are exactly coplanar into facets;
//   4. check that every input point is a corner of the hull;
//   5. trace each facet's boundary as one counter-clockwise vertex cycle;
//   6. list the edges with the two faces that share each, and check Euler.
// Every side-of decision (collinear, coplanar, inside) uses CGAL's exact
// predicates, so the topology is a function of the input doubles alone.
#include "ConvexPolyhedron.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <utility>

namespace dda {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using HullMesh = CGAL::Surface_mesh<Point3>;

// The smallest point set with volume is a tetrahedron.
constexpr std::size_t kMinPointCount = 4;

// Two input points closer than this fraction of the bounding-box diagonal are
// treated as one (dimensionless; the absolute tolerance scales with the block).
// 1e-12 is about 4500 ulps of the diagonal: far above the round-off of any
// coordinate transformation a caller applies, far below any intended feature.
constexpr double kCoincidenceRelativeTolerance = 1e-12;

// Euler characteristic of a sphere-like closed surface: V - E + F.
constexpr int kEulerCharacteristic = 2;

// A vertex of a 3D convex polytope lies on at least this many facet planes; a
// point of the boundary on fewer is inside a facet (1) or inside an edge (2).
constexpr int kMinFacetsAtCorner = 3;

using Triangle = std::array<int, 3>;
using DirectedEdge = std::pair<int, int>;

// ---------------------------------------------------------------- messages

// Shortest text that reads back to the same double ("0.30000000000000004",
// "1", "nan", "-inf").
std::string formatNumber(double x) {
	char buffer[64];
	const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
	return std::string(buffer, result.ptr);
}

std::string formatPoint(const Vector3& p) {
	return "(" + formatNumber(p.x()) + ", " + formatNumber(p.y()) + ", " + formatNumber(p.z()) + ")";
}

[[noreturn]] void internalError(const std::string& what) {
	throw std::logic_error("buildConvexPolyhedron internal error: " + what);
}

Point3 toPoint3(const Vector3& p) { return Point3(p.x(), p.y(), p.z()); }

// ---------------------------------------------------------------- step 1

void requireEnoughPoints(const std::vector<Vector3>& points) {
	if (points.size() < kMinPointCount) {
		throw InputError("a block needs at least " + std::to_string(kMinPointCount) + " points, got " +
		                 std::to_string(points.size()));
	}
}

void requireFiniteCoordinates(const std::vector<Vector3>& points) {
	for (std::size_t i = 0; i < points.size(); ++i) {
		if (!points[i].allFinite()) {
			throw InputError("point " + std::to_string(i) + " has a non-finite coordinate: " + formatPoint(points[i]));
		}
	}
}

double boundingBoxDiagonal(const std::vector<Vector3>& points) {
	Vector3 lo = points.front();
	Vector3 hi = points.front();
	for (const Vector3& p : points) {
		lo = lo.cwiseMin(p);
		hi = hi.cwiseMax(p);
	}
	return (hi - lo).norm();
}

// Throws for the pair (i, j), i < j, that comes first in input order among all
// pairs closer than the coincidence tolerance. Sorting by x and sweeping keeps
// this near-linear for ordinary blocks.
void requireDistinctPoints(const std::vector<Vector3>& points) {
	const double tolerance = kCoincidenceRelativeTolerance * boundingBoxDiagonal(points);

	std::vector<int> byX(points.size());
	std::iota(byX.begin(), byX.end(), 0);
	std::sort(byX.begin(), byX.end(), [&](int a, int b) { return points[a].x() < points[b].x(); });

	std::pair<int, int> first{-1, -1};
	for (std::size_t s = 0; s < byX.size(); ++s) {
		for (std::size_t t = s + 1; t < byX.size(); ++t) {
			const Vector3& p = points[byX[s]];
			const Vector3& q = points[byX[t]];
			if (q.x() - p.x() > tolerance) break;
			const bool coincide = (p == q) || (p - q).norm() < tolerance;
			if (!coincide) continue;
			const std::pair<int, int> pair{std::min(byX[s], byX[t]), std::max(byX[s], byX[t])};
			if (first.first < 0 || pair < first) first = pair;
		}
	}
	if (first.first < 0) return;

	const Vector3& p = points[first.first];
	const Vector3& q = points[first.second];
	std::string message = "points " + std::to_string(first.first) + " and " + std::to_string(first.second) +
	                      " coincide at " + formatPoint(p);
	if (p != q) {
		message += " (" + formatPoint(q) + " is " + formatNumber((p - q).norm()) + " away, closer than " +
		           formatNumber(kCoincidenceRelativeTolerance) + " x the bounding-box diagonal)";
	}
	throw InputError(message);
}

// Exact: the points span 3D iff some four of them are not coplanar. Points
// are distinct here, so points 0 and 1 define a line.
void requireVolume(const std::vector<Vector3>& points) {
	const Point3 p0 = toPoint3(points[0]);
	const Point3 p1 = toPoint3(points[1]);
	std::size_t third = 2;
	while (third < points.size() && CGAL::collinear(p0, p1, toPoint3(points[third]))) ++third;
	if (third < points.size()) {
		const Point3 p2 = toPoint3(points[third]);
		for (std::size_t i = 2; i < points.size(); ++i) {
			if (!CGAL::coplanar(p0, p1, p2, toPoint3(points[i]))) return;
		}
	}
	throw InputError("all " + std::to_string(points.size()) + " points are coplanar: the block has no volume");
}

// ---------------------------------------------------------------- step 2

// Hull triangles as input-point indices, counter-clockwise seen from outside.
std::vector<Triangle> hullTriangles(const std::vector<Vector3>& points) {
	std::vector<Point3> cgalPoints;
	cgalPoints.reserve(points.size());
	std::map<std::array<double, 3>, int> indexOf;  // points are distinct here
	for (std::size_t i = 0; i < points.size(); ++i) {
		cgalPoints.push_back(toPoint3(points[i]));
		indexOf[{points[i].x(), points[i].y(), points[i].z()}] = static_cast<int>(i);
	}

	HullMesh mesh;
	CGAL::convex_hull_3(cgalPoints.begin(), cgalPoints.end(), mesh);

	std::vector<Triangle> triangles;
	triangles.reserve(mesh.number_of_faces());
	for (const auto face : mesh.faces()) {
		Triangle triangle{};
		int corner = 0;
		for (const auto vertex : CGAL::vertices_around_face(mesh.halfedge(face), mesh)) {
			if (corner == 3) internalError("hull face with more than 3 vertices");
			const Point3& p = mesh.point(vertex);
			const auto found = indexOf.find({p.x(), p.y(), p.z()});
			if (found == indexOf.end()) internalError("hull vertex that is not an input point");
			triangle[corner++] = found->second;
		}
		if (corner != 3) internalError("hull face with fewer than 3 vertices");
		triangles.push_back(triangle);
	}
	return triangles;
}

// ---------------------------------------------------------------- step 3

// Facets: groups of hull triangles in one plane, each with one triangle that
// spans that plane (hull triangles are never degenerate, checked below).
struct Facets {
	std::vector<int> facetOfTriangle;           // triangle index -> facet index
	std::vector<Triangle> planeOf;              // facet index -> triangle in its plane
	std::vector<std::vector<int>> trianglesOf;  // facet index -> its triangles
};

int findRoot(std::vector<int>& parent, int i) {
	while (parent[i] != i) {
		parent[i] = parent[parent[i]];
		i = parent[i];
	}
	return i;
}

Facets mergeCoplanarTriangles(const std::vector<Vector3>& points, const std::vector<Triangle>& triangles) {
	const auto at = [&](int i) { return toPoint3(points[i]); };

	std::map<DirectedEdge, int> triangleOfEdge;
	for (std::size_t t = 0; t < triangles.size(); ++t) {
		const Triangle& tri = triangles[t];
		if (CGAL::collinear(at(tri[0]), at(tri[1]), at(tri[2]))) internalError("degenerate hull triangle");
		for (int k = 0; k < 3; ++k) {
			if (!triangleOfEdge.emplace(DirectedEdge{tri[k], tri[(k + 1) % 3]}, static_cast<int>(t)).second) {
				internalError("hull edge used twice in one direction");
			}
		}
	}

	std::vector<int> parent(triangles.size());
	std::iota(parent.begin(), parent.end(), 0);
	for (std::size_t t = 0; t < triangles.size(); ++t) {
		const Triangle& tri = triangles[t];
		for (int k = 0; k < 3; ++k) {
			const auto across = triangleOfEdge.find({tri[(k + 1) % 3], tri[k]});
			if (across == triangleOfEdge.end()) internalError("hull is not closed");
			const Triangle& other = triangles[across->second];
			// The neighbour's vertex that is not on the shared edge.
			int apex = other[0];
			for (int v : other) {
				if (v != tri[k] && v != tri[(k + 1) % 3]) apex = v;
			}
			if (CGAL::coplanar(at(tri[0]), at(tri[1]), at(tri[2]), at(apex))) {
				parent[findRoot(parent, static_cast<int>(t))] = findRoot(parent, across->second);
			}
		}
	}

	Facets facets;
	facets.facetOfTriangle.assign(triangles.size(), -1);
	std::map<int, int> facetOfRoot;
	for (std::size_t t = 0; t < triangles.size(); ++t) {
		const int root = findRoot(parent, static_cast<int>(t));
		const auto inserted = facetOfRoot.emplace(root, static_cast<int>(facets.planeOf.size()));
		if (inserted.second) {
			facets.planeOf.push_back(triangles[t]);
			facets.trianglesOf.emplace_back();
		}
		facets.facetOfTriangle[t] = inserted.first->second;
		facets.trianglesOf[inserted.first->second].push_back(static_cast<int>(t));
	}
	return facets;
}

// ---------------------------------------------------------------- step 4

// Every input point must be a corner of the hull. Decided exactly by counting
// the facet planes through each point; reports the first offender in input
// order.
void requireAllCorners(const std::vector<Vector3>& points, const Facets& facets) {
	for (std::size_t i = 0; i < points.size(); ++i) {
		const Point3 p = toPoint3(points[i]);
		int planesThrough = 0;
		for (const Triangle& plane : facets.planeOf) {
			const auto side = CGAL::orientation(toPoint3(points[plane[0]]), toPoint3(points[plane[1]]),
			                                    toPoint3(points[plane[2]]), p);
			if (side == CGAL::POSITIVE) internalError("input point outside its own hull");
			if (side == CGAL::COPLANAR) ++planesThrough;
		}
		if (planesThrough >= kMinFacetsAtCorner) continue;

		const std::string prefix = "point " + std::to_string(i) + " " + formatPoint(points[i]);
		if (planesThrough == 0) {
			throw InputError(prefix + " lies strictly inside the hull of the others: the input is not convex");
		}
		const std::string where = planesThrough == 1 ? "inside a face" : "inside an edge";
		throw InputError(prefix + " lies on the hull surface but is not a corner (it is " + where + ")");
	}
}

// ---------------------------------------------------------------- step 5

// The facet's boundary: its triangles' directed edges whose reverse belongs to
// another facet, chained head to tail. Triangles are counter-clockwise from
// outside, so the chain is too.
std::vector<int> traceFacetBoundary(const std::vector<Triangle>& triangles, const Facets& facets, int facet) {
	std::set<DirectedEdge> inside;
	for (int t : facets.trianglesOf[facet]) {
		for (int k = 0; k < 3; ++k) inside.insert({triangles[t][k], triangles[t][(k + 1) % 3]});
	}
	std::map<int, int> nextOf;
	for (const DirectedEdge& e : inside) {
		if (inside.count({e.second, e.first})) continue;  // interior diagonal
		if (!nextOf.emplace(e.first, e.second).second) internalError("facet boundary is not a simple cycle");
	}
	if (nextOf.empty()) internalError("facet without boundary");

	std::vector<int> cycle;
	int v = nextOf.begin()->first;  // the smallest index: a canonical start
	do {
		cycle.push_back(v);
		const auto next = nextOf.find(v);
		if (next == nextOf.end() || cycle.size() > nextOf.size()) internalError("facet boundary is open");
		v = next->second;
	} while (v != cycle.front());
	if (cycle.size() != nextOf.size()) internalError("facet boundary has several cycles");
	return cycle;
}

std::vector<std::vector<int>> faceCycles(const std::vector<Triangle>& triangles, const Facets& facets) {
	std::vector<std::vector<int>> faces;
	faces.reserve(facets.planeOf.size());
	for (std::size_t f = 0; f < facets.planeOf.size(); ++f) {
		faces.push_back(traceFacetBoundary(triangles, facets, static_cast<int>(f)));
	}
	// Each cycle starts at its smallest index; sorting makes the face order
	// independent of the hull algorithm's internal order.
	std::sort(faces.begin(), faces.end());
	return faces;
}

// ---------------------------------------------------------------- step 6

void buildEdges(ConvexPolyhedron& poly) {
	// Undirected edge {lo, hi} -> {face traversing lo->hi, face traversing hi->lo}.
	std::map<std::array<int, 2>, std::array<int, 2>> facesOfEdge;
	for (std::size_t f = 0; f < poly.faces.size(); ++f) {
		const std::vector<int>& face = poly.faces[f];
		for (std::size_t k = 0; k < face.size(); ++k) {
			const int a = face[k];
			const int b = face[(k + 1) % face.size()];
			const bool forward = a < b;
			auto& slots = facesOfEdge.try_emplace({std::min(a, b), std::max(a, b)}, std::array<int, 2>{-1, -1})
			                  .first->second;
			int& slot = slots[forward ? 0 : 1];
			if (slot >= 0) internalError("directed edge in two faces");
			slot = static_cast<int>(f);
		}
	}
	for (const auto& [edge, faces] : facesOfEdge) {
		if (faces[0] < 0 || faces[1] < 0) internalError("edge with a single face");
		poly.edges.push_back(edge);
		poly.edgeFaces.push_back(faces);
	}
}

void checkEuler(const ConvexPolyhedron& poly) {
	const long v = static_cast<long>(poly.vertices.size());
	const long e = static_cast<long>(poly.edges.size());
	const long f = static_cast<long>(poly.faces.size());
	if (v - e + f != kEulerCharacteristic) {
		internalError("Euler's formula fails: V - E + F = " + std::to_string(v) + " - " + std::to_string(e) + " + " +
		              std::to_string(f) + " != " + std::to_string(kEulerCharacteristic));
	}
}

}  // namespace

ConvexPolyhedron buildConvexPolyhedron(const std::vector<Vector3>& points) {
	requireEnoughPoints(points);
	requireFiniteCoordinates(points);
	requireDistinctPoints(points);
	requireVolume(points);

	const std::vector<Triangle> triangles = hullTriangles(points);
	const Facets facets = mergeCoplanarTriangles(points, triangles);
	requireAllCorners(points, facets);

	ConvexPolyhedron poly;
	poly.vertices = points;
	poly.faces = faceCycles(triangles, facets);
	buildEdges(poly);
	checkEuler(poly);
	return poly;
}

}  // namespace dda
