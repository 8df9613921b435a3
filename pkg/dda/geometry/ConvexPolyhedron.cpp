// Builds the face/edge topology of a convex DDA block from its corner points.
//
// Pipeline (one function per step):
//   1. validate the raw points (count, finiteness, distinctness, volume);
//   2. hull the points with CGAL (triangles, outward);
//   3. grow facets: from the largest unassigned hull triangle, whose plane
//      becomes the facet's plane, add neighbouring triangles whose corners lie
//      on that plane (exactly coplanar, or within the scaled tolerance);
//   4. trace each facet's boundary as one counter-clockwise vertex cycle;
//   5. check that every input point is a corner of the merged faces, and that
//      every face is a strictly convex polygon;
//   6. list the edges with the two faces that share each, and check Euler.
// Collinear, coplanar and inside decisions on the raw points use CGAL's exact
// predicates; only the face merge adds a tolerance (kCoplanarRelativeTolerance,
// see the header), so the topology of a rotated box is that of a box.
#include "ConvexPolyhedron.hpp"
#include "PointChecks.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <utility>

namespace dda {
namespace {

using namespace hull;

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using HullMesh = CGAL::Surface_mesh<Point3>;

// Euler characteristic of a sphere-like closed surface: V - E + F.
constexpr int kEulerCharacteristic = 2;

// A vertex of a 3D convex polytope lies on at least this many facet planes; a
// point of the boundary on fewer is inside a facet (1) or inside an edge (2).
constexpr int kMinFacetsAtCorner = 3;

using Triangle = std::array<int, 3>;
using DirectedEdge = std::pair<int, int>;

[[noreturn]] void internalError(const std::string& what) {
	throw std::logic_error("buildConvexPolyhedron internal error: " + what);
}

Point3 toPoint3(const Vector3& p) { return Point3(p.x(), p.y(), p.z()); }

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

// A facet's plane: unit outward normal through a point of the plane.
struct Plane {
	Vector3 normal;
	Vector3 point;
	double signedDistance(const Vector3& p) const { return normal.dot(p - point); }
};

// The plane of a hull triangle and twice its area. The cross product is taken
// at the corner opposite the longest edge (the two shortest edges), which
// keeps its round-off smallest; a cyclic shift keeps the orientation.
struct TrianglePlane {
	Plane plane;
	double doubleArea;
};

TrianglePlane trianglePlane(const std::vector<Vector3>& points, const Triangle& tri) {
	int corner = 0;
	double longest = -1;
	for (int k = 0; k < 3; ++k) {
		const double opposite = (points[tri[(k + 1) % 3]] - points[tri[(k + 2) % 3]]).squaredNorm();
		if (opposite > longest) {
			longest = opposite;
			corner = k;
		}
	}
	const Vector3& o = points[tri[corner]];
	const Vector3 n = (points[tri[(corner + 1) % 3]] - o).cross(points[tri[(corner + 2) % 3]] - o);
	const double doubleArea = n.norm();
	// Not collinear (CGAL decided exactly), yet the double cross product is
	// zero: a sliver of nearly collinear points (found by the fuzzer).
	if (!(doubleArea > 0)) {
		throw InputError("points " + std::to_string(tri[0]) + ", " + std::to_string(tri[1]) + " and " +
		                 std::to_string(tri[2]) + " form a hull triangle so thin that its normal is lost to round-off "
		                 "(they are collinear to double precision): the block is degenerate there");
	}
	return {{n / doubleArea, (points[tri[0]] + points[tri[1]] + points[tri[2]]) / 3.0}, doubleArea};
}

// Facets: groups of hull triangles in one face plane. Each facet's plane is
// that of its seed, the largest of its triangles, fixed before the facet grows.
struct Facets {
	std::vector<int> facetOfTriangle;           // triangle index -> facet index
	std::vector<Triangle> seedOf;               // facet index -> its largest triangle
	std::vector<Plane> planeOf;                 // facet index -> plane of the seed
	std::vector<bool> exactOf;                  // facet index -> all triangles exactly coplanar
	std::vector<std::vector<int>> trianglesOf;  // facet index -> its triangles
};

enum class OnPlane { no, exactly, withinTolerance };

// Whether point p lies on the plane of facet f: exactly coplanar with its seed
// (decided exactly, so exact input never depends on the tolerance), or within
// `tolerance` of the seed's plane.
OnPlane onFacetPlane(const std::vector<Vector3>& points, const Facets& facets, int f, const Vector3& p,
                     double tolerance) {
	const Triangle& seed = facets.seedOf[f];
	if (CGAL::coplanar(toPoint3(points[seed[0]]), toPoint3(points[seed[1]]), toPoint3(points[seed[2]]), toPoint3(p))) {
		return OnPlane::exactly;
	}
	return std::abs(facets.planeOf[f].signedDistance(p)) <= tolerance ? OnPlane::withinTolerance : OnPlane::no;
}

// Region growing. Seeds are taken largest first (the best-conditioned plane);
// a neighbour across the facet's boundary joins when its corner off the shared
// edge lies on the seed's plane. Its other two corners are corners of the
// facet already, so every corner of every triangle of a facet lies on the
// facet's plane: the test is against one fixed plane, never against the last
// triangle added, so slightly tilted triangles cannot chain into a curved face.
Facets growFacets(const std::vector<Vector3>& points, const std::vector<Triangle>& triangles, double tolerance) {
	const auto at = [&](int i) { return toPoint3(points[i]); };
	const int triangleCount = static_cast<int>(triangles.size());

	std::map<DirectedEdge, int> triangleOfEdge;
	for (int t = 0; t < triangleCount; ++t) {
		const Triangle& tri = triangles[t];
		if (CGAL::collinear(at(tri[0]), at(tri[1]), at(tri[2]))) internalError("degenerate hull triangle");
		for (int k = 0; k < 3; ++k) {
			if (!triangleOfEdge.emplace(DirectedEdge{tri[k], tri[(k + 1) % 3]}, t).second) {
				internalError("hull edge used twice in one direction");
			}
		}
	}
	// across[t][k]: the triangle on the other side of edge tri[k] -> tri[k+1].
	std::vector<std::array<int, 3>> across(triangles.size());
	for (int t = 0; t < triangleCount; ++t) {
		for (int k = 0; k < 3; ++k) {
			const auto found = triangleOfEdge.find({triangles[t][(k + 1) % 3], triangles[t][k]});
			if (found == triangleOfEdge.end()) internalError("hull is not closed");
			across[t][k] = found->second;
		}
	}

	// Largest first; ties by sorted corner indices, so the result does not
	// depend on the order in which the hull algorithm lists its triangles.
	std::vector<double> doubleArea(triangles.size());
	std::vector<Triangle> sortedCorners(triangles);
	for (int t = 0; t < triangleCount; ++t) {
		doubleArea[t] = trianglePlane(points, triangles[t]).doubleArea;
		std::sort(sortedCorners[t].begin(), sortedCorners[t].end());
	}
	std::vector<int> seedOrder(triangles.size());
	std::iota(seedOrder.begin(), seedOrder.end(), 0);
	std::sort(seedOrder.begin(), seedOrder.end(), [&](int a, int b) {
		if (doubleArea[a] != doubleArea[b]) return doubleArea[a] > doubleArea[b];
		return sortedCorners[a] < sortedCorners[b];
	});

	Facets facets;
	facets.facetOfTriangle.assign(triangles.size(), -1);
	for (int seed : seedOrder) {
		if (facets.facetOfTriangle[seed] >= 0) continue;
		const int f = static_cast<int>(facets.seedOf.size());
		facets.seedOf.push_back(triangles[seed]);
		facets.planeOf.push_back(trianglePlane(points, triangles[seed]).plane);
		facets.exactOf.push_back(true);
		facets.trianglesOf.push_back({seed});
		facets.facetOfTriangle[seed] = f;

		for (std::size_t next = 0; next < facets.trianglesOf[f].size(); ++next) {
			const int t = facets.trianglesOf[f][next];
			for (int k = 0; k < 3; ++k) {
				const int u = across[t][k];
				if (facets.facetOfTriangle[u] >= 0) continue;
				// The neighbour's corner that is not on the shared edge.
				int apex = -1;
				for (int v : triangles[u]) {
					if (v != triangles[t][k] && v != triangles[t][(k + 1) % 3]) apex = v;
				}
				const OnPlane on = onFacetPlane(points, facets, f, points[apex], tolerance);
				if (on == OnPlane::no) continue;
				if (on == OnPlane::withinTolerance) facets.exactOf[f] = false;
				facets.facetOfTriangle[u] = f;
				facets.trianglesOf[f].push_back(u);
			}
		}
	}
	return facets;
}

// ---------------------------------------------------------------- step 4

std::string formatIndexList(const std::vector<int>& indices) {
	std::string text;
	for (std::size_t k = 0; k < indices.size(); ++k) text += (k ? ", " : "") + std::to_string(indices[k]);
	return text;
}

std::string toleranceText() {
	return formatNumber(kCoplanarRelativeTolerance) + " x the bounding-box diagonal";
}

// The facet's boundary: its triangles' directed edges whose reverse belongs to
// another facet, chained head to tail. Triangles are counter-clockwise from
// outside, so the chain is too. Starts at the smallest index (canonical).
// A boundary that is not one simple cycle can only come from a tolerance
// merge of a nearly flat block; an exactly planar facet always has one.
std::vector<int> traceFacetBoundary(const std::vector<Triangle>& triangles, const Facets& facets, int facet) {
	const Triangle& seed = facets.seedOf[facet];
	const auto fail = [&](const std::string& what) {
		if (facets.exactOf[facet]) internalError("facet boundary " + what);
		if (facets.trianglesOf[facet].size() == triangles.size()) {
			throw InputError("all points lie within " + toleranceText() + " of one plane: the block is too flat");
		}
		throw InputError("the hull triangles within " + toleranceText() + " of the plane through points " +
		                 formatIndexList({seed[0], seed[1], seed[2]}) +
		                 " do not form one simple polygon (" + what + "): the block is too flat there");
	};

	std::set<DirectedEdge> inside;
	for (int t : facets.trianglesOf[facet]) {
		for (int k = 0; k < 3; ++k) inside.insert({triangles[t][k], triangles[t][(k + 1) % 3]});
	}
	std::map<int, int> nextOf;
	std::set<int> heads;
	for (const DirectedEdge& e : inside) {
		if (inside.count({e.second, e.first})) continue;  // interior diagonal
		if (!nextOf.emplace(e.first, e.second).second || !heads.insert(e.second).second) {
			fail("is not a simple cycle");
		}
	}
	if (nextOf.empty()) fail("is empty");

	std::vector<int> cycle;
	int v = nextOf.begin()->first;
	do {
		cycle.push_back(v);
		const auto next = nextOf.find(v);
		if (next == nextOf.end() || cycle.size() > nextOf.size()) fail("is open");
		v = next->second;
	} while (v != cycle.front());
	if (cycle.size() != nextOf.size()) fail("has several cycles");
	return cycle;
}

std::vector<std::vector<int>> facetBoundaries(const std::vector<Triangle>& triangles, const Facets& facets) {
	std::vector<std::vector<int>> cycles;
	cycles.reserve(facets.seedOf.size());
	for (std::size_t f = 0; f < facets.seedOf.size(); ++f) {
		cycles.push_back(traceFacetBoundary(triangles, facets, static_cast<int>(f)));
	}
	return cycles;
}

// ---------------------------------------------------------------- step 5

// The block is too small for its distance from the origin: the round-off of
// its coordinates (an ulp of the largest, relative to the block's size)
// exceeds the face tolerance, so its faces cannot be resolved.
InputError roundoffError(const std::vector<Vector3>& points, std::size_t i) {
	double largest = 0;
	for (const Vector3& p : points) largest = std::max(largest, p.cwiseAbs().maxCoeff());
	const double diagonal = boundingBoxDiagonal(points);
	return InputError("point " + std::to_string(i) + " " + formatPoint(points[i]) +
	                  " lies outside the hull of the block's own faces by more than " + toleranceText() +
	                  ": the block (bounding-box diagonal " + formatNumber(diagonal) + ") is too small for its distance " +
	                  "from the origin (coordinates up to " + formatNumber(largest) + ", " +
	                  formatNumber(largest / diagonal) + " block sizes), where double precision cannot resolve its "
	                  "faces; move the origin of the coordinates closer to the block");
}

// Every input point must be a corner of the merged faces: on the boundary of at
// least 3 of them. Otherwise the faces whose plane it lies on (exactly or
// within the tolerance, the same test as the merge) tell where it is: none,
// strictly inside; one, inside a face; two, inside an edge. A real corner
// within the tolerance of a face plane is indistinguishable from round-off and
// is rejected the same way; the message says so. Reports the first offender
// in input order.
void requireAllCorners(const std::vector<Vector3>& points, const Facets& facets,
                       const std::vector<std::vector<int>>& cycles, double tolerance) {
	std::vector<std::set<int>> cyclesAt(points.size());
	for (std::size_t f = 0; f < cycles.size(); ++f) {
		for (int v : cycles[f]) cyclesAt[v].insert(static_cast<int>(f));
	}
	const int facetCount = static_cast<int>(facets.seedOf.size());

	for (std::size_t i = 0; i < points.size(); ++i) {
		for (int f = 0; f < facetCount; ++f) {
			// A hull point outside a hull facet's plane: only round-off of the
			// plane (a tiny block far from the origin, where the coordinates'
			// ulps exceed the tolerance) puts it there. Found by the fuzzer.
			if (facets.planeOf[f].signedDistance(points[i]) > tolerance) throw roundoffError(points, i);
		}
		if (cyclesAt[i].size() >= static_cast<std::size_t>(kMinFacetsAtCorner)) continue;

		std::vector<int> near;
		for (int f = 0; f < facetCount; ++f) {
			if (cyclesAt[i].count(f) || onFacetPlane(points, facets, f, points[i], tolerance) != OnPlane::no) {
				near.push_back(f);
			}
		}

		const std::string prefix = "point " + std::to_string(i) + " " + formatPoint(points[i]);
		if (near.empty()) {
			throw InputError(prefix + " lies strictly inside the hull of the others: the input is not convex");
		}
		std::string faces;
		for (std::size_t k = 0; k < near.size(); ++k) {
			if (k > 0) faces += k + 1 == near.size() ? " and " : "; ";
			faces += formatIndexList(cycles[near[k]]);
		}
		std::string where;
		if (near.size() == 1) {
			where = "it is inside a face, within " + toleranceText() + " of the plane of the face with corners " + faces;
		} else if (near.size() == 2) {
			where = "it is inside an edge, within " + toleranceText() + " of the planes of the faces with corners " +
			        faces;
		} else {
			// Within the tolerance of 3 or more planes: next to the corner they
			// share, if there is one.
			std::set<int> shared(cycles[near[0]].begin(), cycles[near[0]].end());
			for (int f : near) {
				std::set<int> kept;
				for (int v : cycles[f]) {
					if (shared.count(v)) kept.insert(v);
				}
				shared = kept;
			}
			where = "it is within " + toleranceText() + " of the planes of the faces with corners " + faces;
			if (shared.size() == 1) where += ", next to their common corner " + std::to_string(*shared.begin());
		}
		throw InputError(prefix + " lies on the hull surface but is not a corner: " + where +
		                 " (if it is meant as a corner, the block is too flat there)");
	}
}

// Each face, seen from outside by its Newell normal, must turn left at every
// corner. Exactly planar faces of a convex hull always do; a tolerance merge
// of a nearly flat block may not.
void requireConvexFaces(const std::vector<Vector3>& points, const Facets& facets,
                        const std::vector<std::vector<int>>& cycles) {
	for (std::size_t f = 0; f < cycles.size(); ++f) {
		const std::vector<int>& cycle = cycles[f];
		const std::string face = "the face with corners " + formatIndexList(cycle);
		const Vector3 normal = faceNormal(points, cycle);
		if (!(normal.dot(facets.planeOf[f].normal) > 0)) {
			throw InputError(face + " faces inward after merging within " + toleranceText() +
			                 ": the block is too flat there");
		}
		for (std::size_t k = 0; k < cycle.size(); ++k) {
			const Vector3& p = points[cycle[k]];
			const Vector3& q = points[cycle[(k + 1) % cycle.size()]];
			const Vector3& r = points[cycle[(k + 2) % cycle.size()]];
			if (!((q - p).cross(r - q).dot(normal) > 0)) {
				throw InputError(face + " (merged within " + toleranceText() + ") is not convex at point " +
				                 std::to_string(cycle[(k + 1) % cycle.size()]) + ": the block is too flat there");
			}
		}
	}
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

Vector3 faceNormal(const std::vector<Vector3>& vertices, const std::vector<int>& face) {
	if (face.size() < 3) {
		throw InputError("a face needs at least 3 corners, got " + std::to_string(face.size()));
	}
	Vector3 mean = Vector3::Zero();
	for (int v : face) {
		if (v < 0 || static_cast<std::size_t>(v) >= vertices.size()) {
			throw InputError("face refers to vertex " + std::to_string(v) + " but there are " +
			                 std::to_string(vertices.size()) + " vertices");
		}
		mean += vertices[v];
	}
	mean /= static_cast<double>(face.size());
	Vector3 areaVector = Vector3::Zero();  // twice the vector area
	for (std::size_t k = 0; k < face.size(); ++k) {
		areaVector += (vertices[face[k]] - mean).cross(vertices[face[(k + 1) % face.size()]] - mean);
	}
	const double norm = areaVector.norm();
	if (!(norm > 0) || !std::isfinite(norm)) {
		throw InputError("the face with corners " + formatIndexList(face) + " has no well-defined normal (area " +
		                 formatNumber(norm / 2) + ")");
	}
	return areaVector / norm;
}

ConvexPolyhedron buildConvexPolyhedron(const std::vector<Vector3>& points) {
	requireEnoughPoints(points);
	requireFiniteCoordinates(points);
	requireDistinctPoints(points);
	requireVolume(points);
	const double tolerance = kCoplanarRelativeTolerance * boundingBoxDiagonal(points);

	const std::vector<Triangle> triangles = hullTriangles(points);
	const Facets facets = growFacets(points, triangles, tolerance);
	std::vector<std::vector<int>> cycles = facetBoundaries(triangles, facets);
	requireAllCorners(points, facets, cycles, tolerance);
	requireConvexFaces(points, facets, cycles);

	ConvexPolyhedron poly;
	poly.vertices = points;
	// Each cycle starts at its smallest index; sorting makes the face order
	// independent of the hull algorithm's internal order.
	std::sort(cycles.begin(), cycles.end());
	poly.faces = std::move(cycles);
	buildEdges(poly);
	checkEuler(poly);
	return poly;
}

std::vector<int> hullCorners(const std::vector<Vector3>& points) {
	requireEnoughPoints(points);
	requireFiniteCoordinates(points);
	// Points closer than the coincidence tolerance are one: the first of them stays.
	const double coincidence = kCoincidenceRelativeTolerance * boundingBoxDiagonal(points);
	std::vector<int> kept;
	for (int i = 0; i < static_cast<int>(points.size()); ++i) {
		const bool repeated = std::any_of(kept.begin(), kept.end(), [&](int k) {
			return points[k] == points[i] || (points[k] - points[i]).norm() < coincidence;
		});
		if (!repeated) kept.push_back(i);
	}
	const auto pick = [&points](const std::vector<int>& indices) {
		std::vector<Vector3> picked;
		picked.reserve(indices.size());
		for (int i : indices) picked.push_back(points[i]);
		return picked;
	};
	if (kept.size() < 4) requireEnoughPoints(pick(kept));
	requireVolume(pick(kept));
	// Each round drops what the exact hull leaves inside, then what lies on a
	// merged face without being a corner of it (on the boundary of fewer than
	// kMinFacetsAtCorner merged faces: inside a face or an edge within the
	// coplanar tolerance). Dropping a point can merge faces anew (and the
	// tolerance follows the shrinking bounding box), so rounds repeat until
	// none drops a point; each drops at least one, so there are fewer rounds
	// than points.
	for (;;) {
		const std::vector<Vector3> candidates = pick(kept);
		const std::vector<Triangle> triangles = hullTriangles(candidates);
		std::vector<int> facetCount(candidates.size(), 0);
		std::vector<bool> onHull(candidates.size(), false);
		for (const Triangle& t : triangles)
			for (int v : t) onHull[v] = true;
		const double tolerance = kCoplanarRelativeTolerance * boundingBoxDiagonal(candidates);
		const Facets facets = growFacets(candidates, triangles, tolerance);
		for (const std::vector<int>& cycle : facetBoundaries(triangles, facets))
			for (int v : cycle) ++facetCount[v];
		std::vector<int> corners;
		for (std::size_t i = 0; i < candidates.size(); ++i)
			if (onHull[i] && facetCount[i] >= kMinFacetsAtCorner) corners.push_back(kept[i]);
		if (corners.size() == kept.size()) return kept;
		if (corners.size() < 4) requireEnoughPoints(pick(corners));
		kept = std::move(corners);
	}
}

std::shared_ptr<const PolyhedronTopology> TopologyPool::intern(std::shared_ptr<const PolyhedronTopology> topology) {
	std::size_t hash = topology->faces.size();
	const auto mix = [&hash](int x) { hash = hash * 1000003u ^ static_cast<std::size_t>(x); };
	for (const auto& face : topology->faces) {
		mix(static_cast<int>(face.size()));
		for (int v : face) mix(v);
	}
	for (const auto& edge : topology->edges) mix(edge[0]), mix(edge[1]);
	for (const auto& faces : topology->edgeFaces) mix(faces[0]), mix(faces[1]);
	const auto [first, last] = byHash_.equal_range(hash);
	for (auto it = first; it != last; ++it)
		if (*it->second == *topology) return it->second;
	byHash_.emplace(hash, topology);
	return topology;
}

}  // namespace dda
