// Tests of the block geometry: hull topology (buildConvexPolyhedron) and
// volume integrals (computeMassProperties).
//
// Reference values never reuse the library's formulas: mass properties are
// checked against closed forms for boxes and tetrahedra, and against an
// independent decomposition that uses a different tetrahedron formula (second
// moment about the tetrahedron's own centroid, combined with the parallel-axis
// theorem) on CGAL's own hull triangles.
#include "dda/geometry/ConvexPolyhedron.hpp"
#include "dda/geometry/MassProperties.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <initializer_list>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

using dda::ConvexPolyhedron;
using dda::MassProperties;
using dda::Vector3;
using Matrix3 = Eigen::Matrix3d;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;

// Relative accuracy demanded of every mass property (dimensionless): errors
// are measured against the size of the quantity (|V|, ||J||, or the block's
// bounding-box diagonal for positions).
constexpr double kRelTol = 1e-12;

const double kPi = std::acos(-1.0);

// ---------------------------------------------------------------- shapes

// The 8 corners of an axis-aligned box, x varying fastest.
std::vector<Vector3> boxCorners(const Vector3& lo, const Vector3& size) {
	std::vector<Vector3> corners;
	for (int k = 0; k < 2; ++k)
		for (int j = 0; j < 2; ++j)
			for (int i = 0; i < 2; ++i) corners.push_back(lo + Vector3(i * size.x(), j * size.y(), k * size.z()));
	return corners;
}

std::vector<Vector3> unitCube() { return boxCorners(Vector3::Zero(), Vector3::Ones()); }

std::vector<Vector3> regularOctahedron() {
	return {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
}

std::vector<Vector3> hexagonalPrism(double radius, double height) {
	std::vector<Vector3> points;
	for (double z : {0.0, height}) {
		for (int k = 0; k < 6; ++k) {
			const double angle = k * kPi / 3;
			points.emplace_back(radius * std::cos(angle), radius * std::sin(angle), z);
		}
	}
	return points;
}

// `count` points on the surface of an ellipsoid centred at `center`: a strictly
// convex surface, so every point is a hull vertex. Directions come from the raw
// mt19937 stream (portable across standard libraries, unlike distributions).
std::vector<Vector3> ellipsoidPoints(int count, const Vector3& semiAxes, const Vector3& center) {
	std::mt19937 engine(20240611u);
	const auto unit = [&engine] { return engine() / 4294967296.0; };  // [0, 1)
	std::vector<Vector3> points;
	for (int i = 0; i < count; ++i) {
		const double z = 2 * unit() - 1;
		const double phi = 2 * kPi * unit();
		const double r = std::sqrt(1 - z * z);
		points.push_back(center + semiAxes.cwiseProduct(Vector3(r * std::cos(phi), r * std::sin(phi), z)));
	}
	return points;
}

Matrix3 rotation(double angle, const Vector3& axis) {
	return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// Uniform numbers in [0, 1) from the raw mt19937 stream (portable across
// standard libraries, unlike std::uniform_real_distribution).
class Uniform {
public:
	explicit Uniform(unsigned seed) : engine_(seed) {}
	double operator()() { return engine_() / 4294967296.0; }
	double in(double lo, double hi) { return lo + (hi - lo) * (*this)(); }
	Vector3 in(const Vector3& lo, const Vector3& hi) {
		const double x = in(lo.x(), hi.x()), y = in(lo.y(), hi.y()), z = in(lo.z(), hi.z());
		return {x, y, z};
	}

private:
	std::mt19937 engine_;
};

// A rotation uniformly distributed over SO(3) (Shoemake's unit quaternion).
Matrix3 randomRotation(Uniform& uniform) {
	const double u1 = uniform(), a = 2 * kPi * uniform(), b = 2 * kPi * uniform();
	const Eigen::Quaterniond q(std::sqrt(1 - u1) * std::sin(a), std::sqrt(1 - u1) * std::cos(a),
	                           std::sqrt(u1) * std::sin(b), std::sqrt(u1) * std::cos(b));
	return q.normalized().toRotationMatrix();
}

// `count` points spread evenly over a sphere (Fibonacci lattice): a strictly
// convex surface, finely but irregularly tessellated by its hull.
std::vector<Vector3> fibonacciSphere(int count, double radius, const Vector3& center) {
	const double goldenAngle = kPi * (3 - std::sqrt(5.0));
	std::vector<Vector3> points;
	for (int i = 0; i < count; ++i) {
		const double z = 1 - (2 * i + 1.0) / count;
		const double r = std::sqrt(1 - z * z);
		points.push_back(center + radius * Vector3(r * std::cos(goldenAngle * i), r * std::sin(goldenAngle * i), z));
	}
	return points;
}

std::vector<Vector3> moved(const std::vector<Vector3>& points, const Matrix3& R, const Vector3& t) {
	std::vector<Vector3> result;
	for (const Vector3& p : points) result.push_back(R * p + t);
	return result;
}

// A box of the given size centred at `center`, rotated by R about its centre;
// the corners are rounded to double, so its sides are generally not exactly
// planar any more.
std::vector<Vector3> rotatedBox(const Vector3& size, const Matrix3& R, const Vector3& center) {
	return moved(boxCorners(-size / 2, size), R, center);
}

double boundingDiagonal(const std::vector<Vector3>& points) {
	Vector3 lo = points[0], hi = points[0];
	for (const Vector3& p : points) {
		lo = lo.cwiseMin(p);
		hi = hi.cwiseMax(p);
	}
	return (hi - lo).norm();
}

double relativeError(const Matrix3& actual, const Matrix3& expected) {
	return (actual - expected).norm() / expected.norm();
}

double relativeError(double actual, double expected) { return std::abs(actual - expected) / std::abs(expected); }

// ---------------------------------------------------------------- independent moments

struct Moments {
	double volume = 0;
	Vector3 centroid = Vector3::Zero();
	Matrix3 J = Matrix3::Zero();  // about `centroid`
};

// A tetrahedron's moments in the centroid-relative form: with d_k = p_k - c
// (so Σ d_k = 0), x - c = Σ λ_k d_k for barycentric weights λ uniform on the
// simplex, E[λ_k λ_l] = (1 + δ_kl)/20, hence J = V/20 Σ_k d_k d_k^T.
// Volume is signed: positive when (p1-p0, p2-p0, p3-p0) is right-handed.
Moments tetrahedronMoments(const Vector3& p0, const Vector3& p1, const Vector3& p2, const Vector3& p3) {
	Moments m;
	Matrix3 edges;
	edges << p1 - p0, p2 - p0, p3 - p0;
	m.volume = edges.determinant() / 6;
	m.centroid = (p0 + p1 + p2 + p3) / 4;
	for (const Vector3* p : {&p0, &p1, &p2, &p3}) {
		const Vector3 d = *p - m.centroid;
		m.J += m.volume / 20 * d * d.transpose();
	}
	return m;
}

// Parallel-axis theorem: J_total = Σ (J_i + V_i (c_i - c)(c_i - c)^T).
Moments combine(const std::vector<Moments>& parts) {
	Moments total;
	for (const Moments& m : parts) {
		total.volume += m.volume;
		total.centroid += m.volume * m.centroid;
	}
	total.centroid /= total.volume;
	for (const Moments& m : parts) {
		const Vector3 shift = m.centroid - total.centroid;
		total.J += m.J + m.volume * shift * shift.transpose();
	}
	return total;
}

CGAL::Surface_mesh<Point3> cgalHull(const std::vector<Vector3>& points) {
	std::vector<Point3> cgalPoints;
	for (const Vector3& p : points) cgalPoints.emplace_back(p.x(), p.y(), p.z());
	CGAL::Surface_mesh<Point3> mesh;
	CGAL::convex_hull_3(cgalPoints.begin(), cgalPoints.end(), mesh);
	return mesh;
}

// Moments of the convex hull of `points` from CGAL's own (triangulated) hull,
// coned from the vertex mean: no code shared with the library.
Moments referenceHullMoments(const std::vector<Vector3>& points) {
	const auto mesh = cgalHull(points);
	Vector3 apex = Vector3::Zero();
	for (const Vector3& p : points) apex += p;
	apex /= static_cast<double>(points.size());

	std::vector<Moments> parts;
	for (const auto face : mesh.faces()) {
		std::vector<Vector3> corner;
		for (const auto v : CGAL::vertices_around_face(mesh.halfedge(face), mesh)) {
			const Point3& p = mesh.point(v);
			corner.emplace_back(p.x(), p.y(), p.z());
		}
		parts.push_back(tetrahedronMoments(apex, corner[0], corner[1], corner[2]));
	}
	return combine(parts);
}

Matrix3 boxSecondMoment(const Vector3& size) {
	const double volume = size.prod();
	return (volume / 12 * size.cwiseProduct(size)).asDiagonal();
}

// ---------------------------------------------------------------- topology checks

Point3 toPoint3(const Vector3& p) { return Point3(p.x(), p.y(), p.z()); }

// Newell's method: twice the vector area of the polygon, taken about the mean
// of its corners (round-off stays relative to the block, not to the distance
// from the origin).
Vector3 newellNormal(const ConvexPolyhedron& poly, const std::vector<int>& face) {
	Vector3 mean = Vector3::Zero();
	for (int v : face) mean += poly.vertices[v];
	mean /= static_cast<double>(face.size());
	Vector3 n = Vector3::Zero();
	for (std::size_t k = 0; k < face.size(); ++k) {
		const Vector3 p = poly.vertices[face[k]] - mean;
		const Vector3 q = poly.vertices[face[(k + 1) % face.size()]] - mean;
		n += p.cross(q);
	}
	return n;
}

// The distance within which the library treats points as on one face plane.
double coplanarTolerance(const std::vector<Vector3>& points) {
	return dda::kCoplanarRelativeTolerance * boundingDiagonal(points);
}

// Everything the header promises about a polyhedron built from `points`.
// Faces are checked as the header tells consumers to read them: the plane
// through the mean of the corners with the Newell normal. A face's corners
// must lie within the coplanar tolerance of it, every other vertex strictly
// behind it by more than that.
void expectValidPolyhedron(const ConvexPolyhedron& poly, const std::vector<Vector3>& points) {
	ASSERT_EQ(poly.vertices, points) << "vertices must be the input points, in input order";
	const int vertexCount = static_cast<int>(points.size());
	const double tolerance = coplanarTolerance(points);

	Vector3 inner = Vector3::Zero();  // vertex mean: inside a convex body
	for (const Vector3& p : points) inner += p;
	inner /= vertexCount;

	std::map<std::pair<int, int>, int> faceOfDirectedEdge;
	std::vector<int> facesAtVertex(vertexCount, 0);
	for (std::size_t f = 0; f < poly.faces.size(); ++f) {
		const std::vector<int>& face = poly.faces[f];
		ASSERT_GE(face.size(), 3u) << "face " << f;
		ASSERT_EQ(std::set<int>(face.begin(), face.end()).size(), face.size()) << "repeated vertex in face " << f;
		for (int v : face) {
			ASSERT_TRUE(v >= 0 && v < vertexCount) << "face " << f;
			++facesAtVertex[v];
		}

		const Vector3 normal = newellNormal(poly, face);
		const Vector3 unitNormal = normal.normalized();
		Vector3 mean = Vector3::Zero();
		for (int v : face) mean += points[v];
		mean /= static_cast<double>(face.size());
		for (int v = 0; v < vertexCount; ++v) {
			const bool onFace = std::find(face.begin(), face.end(), v) != face.end();
			const double distance = unitNormal.dot(points[v] - mean);
			// Planar face, and the whole body behind it (outward orientation).
			if (onFace) {
				EXPECT_LE(std::abs(distance), tolerance) << "face " << f << " is not planar at vertex " << v;
			} else {
				EXPECT_LT(distance, -tolerance) << "face " << f << ", vertex " << v << " is not behind it";
			}
		}
	Vector3 faceCenter = Vector3::Zero();
		for (int v : face) faceCenter += points[v];
		faceCenter /= static_cast<double>(face.size());
		EXPECT_GT(normal.dot(faceCenter - inner), 0) << "face " << f << " normal points inward";

		for (std::size_t k = 0; k < face.size(); ++k) {
			const int from = face[k];
			const int to = face[(k + 1) % face.size()];
			const Vector3& p = points[from];
			const Vector3& q = points[to];
			const Vector3& r = points[face[(k + 2) % face.size()]];
			EXPECT_GT((q - p).cross(r - q).dot(normal), 0) << "face " << f << " is not strictly convex at " << to;
			const bool fresh = faceOfDirectedEdge.emplace(std::make_pair(from, to), static_cast<int>(f)).second;
			EXPECT_TRUE(fresh) << "directed edge " << from << "->" << to << " in two faces";
		}
	}
	for (int v = 0; v < vertexCount; ++v) EXPECT_GE(facesAtVertex[v], 3) << "vertex " << v;

	// Every face edge is matched by its reverse in another face ...
	for (const auto& [edge, face] : faceOfDirectedEdge) {
		const auto reverse = faceOfDirectedEdge.find({edge.second, edge.first});
		ASSERT_NE(reverse, faceOfDirectedEdge.end()) << "edge " << edge.first << "-" << edge.second << " has one face";
		EXPECT_NE(reverse->second, face);
	}
	// ... and the edge list holds each undirected edge once, with those faces.
	ASSERT_EQ(poly.edges.size(), faceOfDirectedEdge.size() / 2);
	ASSERT_EQ(poly.edgeFaces.size(), poly.edges.size());
	std::set<std::pair<int, int>> seen;
	for (std::size_t e = 0; e < poly.edges.size(); ++e) {
		const int a = poly.edges[e][0], b = poly.edges[e][1];
		EXPECT_TRUE(seen.insert({std::min(a, b), std::max(a, b)}).second) << "edge " << e << " listed twice";
		const auto forward = faceOfDirectedEdge.find({a, b});
		const auto backward = faceOfDirectedEdge.find({b, a});
		ASSERT_NE(forward, faceOfDirectedEdge.end()) << "edge " << e;
		ASSERT_NE(backward, faceOfDirectedEdge.end()) << "edge " << e;
		EXPECT_EQ(poly.edgeFaces[e][0], forward->second) << "edge " << e;
		EXPECT_EQ(poly.edgeFaces[e][1], backward->second) << "edge " << e;
	}
	EXPECT_EQ(vertexCount - static_cast<int>(poly.edges.size()) + static_cast<int>(poly.faces.size()), 2) << "Euler";
}

// For input whose faces are exactly planar (axis-aligned, exactly permuted or
// simplicial): each face is exactly coplanar and the body strictly behind it.
void expectExactlyPlanarFaces(const ConvexPolyhedron& poly) {
	for (std::size_t f = 0; f < poly.faces.size(); ++f) {
		const std::vector<int>& face = poly.faces[f];
		const Point3 a = toPoint3(poly.vertices[face[0]]), b = toPoint3(poly.vertices[face[1]]),
		             c = toPoint3(poly.vertices[face[2]]);
		for (int v = 0; v < static_cast<int>(poly.vertices.size()); ++v) {
			const bool onFace = std::find(face.begin(), face.end(), v) != face.end();
			const auto side = CGAL::orientation(a, b, c, toPoint3(poly.vertices[v]));
			EXPECT_EQ(side, onFace ? CGAL::COPLANAR : CGAL::NEGATIVE) << "face " << f << ", vertex " << v;
		}
	}
}

// Faces whose corners are not exactly coplanar: merged within the tolerance.
int inexactFaceCount(const ConvexPolyhedron& poly) {
	int count = 0;
	for (const auto& face : poly.faces) {
		const Point3 a = toPoint3(poly.vertices[face[0]]), b = toPoint3(poly.vertices[face[1]]),
		             c = toPoint3(poly.vertices[face[2]]);
		bool exact = true;
		for (std::size_t k = 3; k < face.size(); ++k) exact = exact && CGAL::coplanar(a, b, c, toPoint3(poly.vertices[face[k]]));
		count += !exact;
	}
	return count;
}

std::multiset<std::size_t> faceSizes(const ConvexPolyhedron& poly) {
	std::multiset<std::size_t> sizes;
	for (const auto& face : poly.faces) sizes.insert(face.size());
	return sizes;
}

// `count` faces of `size` vertices each.
std::multiset<std::size_t> repeatedSize(std::size_t count, std::size_t size) {
	std::multiset<std::size_t> sizes;
	for (std::size_t i = 0; i < count; ++i) sizes.insert(size);
	return sizes;
}

// ---------------------------------------------------------------- input errors

// Expects buildConvexPolyhedron to throw dda::InputError whose message holds
// every fragment. Any other exception escapes and fails the test.
void expectInputError(const std::vector<Vector3>& points, std::initializer_list<std::string> fragments) {
	try {
		dda::buildConvexPolyhedron(points);
		ADD_FAILURE() << "no InputError thrown";
	} catch (const dda::InputError& error) {
		const std::string message = error.what();
		for (const std::string& fragment : fragments) {
			EXPECT_NE(message.find(fragment), std::string::npos) << "\"" << fragment << "\" missing from: " << message;
		}
	}
}

}  // namespace

// ================================================================ topology

TEST(GeometryTopology, CubeHasSixQuadFacesAndTwelveEdges) {
	const auto points = unitCube();
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	expectExactlyPlanarFaces(poly);
	EXPECT_EQ(poly.faces.size(), 6u);
	EXPECT_EQ(faceSizes(poly), repeatedSize(6, 4));
	EXPECT_EQ(poly.edges.size(), 12u);
	// Each face of a unit cube lies in a plane x, y or z = 0 or 1.
	for (const auto& face : poly.faces) {
		int sharedAxes = 0;
		for (int axis = 0; axis < 3; ++axis) {
			bool shared = true;
			for (int v : face) shared = shared && points[v][axis] == points[face[0]][axis];
			sharedAxes += shared;
		}
		EXPECT_EQ(sharedAxes, 1);
	}
}

TEST(GeometryTopology, OctahedronHasEightTrianglesAndTwelveEdges) {
	const auto points = regularOctahedron();
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	expectExactlyPlanarFaces(poly);
	EXPECT_EQ(faceSizes(poly), repeatedSize(8, 3));
	EXPECT_EQ(poly.edges.size(), 12u);
}

TEST(GeometryTopology, HexagonalPrismHasTwoHexagonsAndSixQuads) {
	const auto points = hexagonalPrism(0.7, 2.5);
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	expectExactlyPlanarFaces(poly);
	EXPECT_EQ(faceSizes(poly), (std::multiset<std::size_t>{4, 4, 4, 4, 4, 4, 6, 6}));
	EXPECT_EQ(poly.edges.size(), 18u);
}

TEST(GeometryTopology, AxisAlignedBoxesOfAnyShapeAndScaleHaveSixQuads) {
	struct Case {
		const char* name;
		Vector3 lo, size;
	};
	const Case cases[] = {
	    {"slender 60:1", {-3, 0.5, 2}, {60, 1, 1}},
	    {"tiny 1e-3 m", {0.1, 0.2, 0.3}, {1e-3, 2e-3, 1.5e-3}},
	    {"huge 1e4 m", {-5e3, 1e4, 0}, {1e4, 2e4, 1.5e4}},
	    {"inexact decimals", {0.1 + 0.2, 0.7, 1.1}, {0.1 + 0.2, 0.3 + 0.6, 0.7 - 0.4}},
	};
	for (const Case& c : cases) {
		SCOPED_TRACE(c.name);
		const auto points = boxCorners(c.lo, c.size);
		const auto poly = dda::buildConvexPolyhedron(points);
		expectValidPolyhedron(poly, points);
		expectExactlyPlanarFaces(poly);
		EXPECT_EQ(faceSizes(poly), repeatedSize(6, 4));
		EXPECT_EQ(poly.edges.size(), 12u);
	}
}

TEST(GeometryTopology, QuarterTurnRotatedBoxStillHasSixQuads) {
	// A quarter turn about z permutes coordinates exactly, so faces stay
	// exactly planar even with inexact decimal coordinates.
	const Matrix3 quarterTurn = (Matrix3() << 0, -1, 0, 1, 0, 0, 0, 0, 1).finished();
	const auto points = moved(boxCorners({0.1, 0.2, 0.3}, {0.1 + 0.2, 0.7, 1.3}), quarterTurn, {0.1 + 0.2, -0.7, 5});
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	expectExactlyPlanarFaces(poly);
	EXPECT_EQ(faceSizes(poly), repeatedSize(6, 4));
}

TEST(GeometryTopology, GenericallyRotatedBoxHasSixQuads) {
	// After a generic rotation the 4 rounded corners of a side are usually not
	// exactly coplanar any more; they are within round-off, so still one face.
	const Vector3 size(1, 2, 3);
	const Matrix3 R = rotation(0.3, {1, 0.1 + 0.2, 0.7});
	const auto points = rotatedBox(size, R, {0.1, 0.2, 0.3});
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	EXPECT_EQ(faceSizes(poly), repeatedSize(6, 4));
	EXPECT_EQ(poly.edges.size(), 12u);
	EXPECT_GT(inexactFaceCount(poly), 0) << "the rotation no longer exercises the tolerance";
	const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);
	EXPECT_LE(relativeError(mass.volume, size.prod()), kRelTol);
	EXPECT_LE(relativeError(mass.secondMoment, R * boxSecondMoment(size) * R.transpose()), kRelTol);
}

TEST(GeometryTopology, RandomlyPlacedBoxesOfAllScalesHaveSixQuads) {
	// 200 boxes: uniformly random rotations, sides from 1e-3 m to 1e3 m (log
	// uniform, aspect up to 3:1), centres anywhere within 1e3 m of the origin.
	int inexactFaces = 0;
	for (unsigned seed = 0; seed < 200; ++seed) {
		Uniform uniform(seed);
		const Matrix3 R = randomRotation(uniform);
		const double scale = std::pow(10.0, uniform.in(-3, 3));
		const Vector3 size = scale * uniform.in(Vector3::Constant(0.5), Vector3::Constant(1.5));
		const Vector3 center = uniform.in(Vector3::Constant(-1e3), Vector3::Constant(1e3));
		SCOPED_TRACE(testing::Message() << "seed " << seed << ", size " << size.transpose() << ", centre "
		                                << center.transpose());
		const auto points = rotatedBox(size, R, center);
		const auto poly = dda::buildConvexPolyhedron(points);
		expectValidPolyhedron(poly, points);
		EXPECT_EQ(faceSizes(poly), repeatedSize(6, 4));
		EXPECT_EQ(poly.edges.size(), 12u);
		inexactFaces += inexactFaceCount(poly);
	}
	// Most sides are merged by the tolerance, not by exact coplanarity.
	EXPECT_GT(inexactFaces, 600) << inexactFaces << " of 1200 sides were not exactly planar";
}

TEST(GeometryTopology, RandomlyPlacedSlenderBoxesHaveSixQuads) {
	// A 60:1 column: long thin faces, the worst conditioned planes of a box.
	for (unsigned seed = 0; seed < 100; ++seed) {
		Uniform uniform(1000 + seed);
		const Matrix3 R = randomRotation(uniform);
		const Vector3 size = std::pow(10.0, uniform.in(-2, 1)) * Vector3(60, 1, 1);
		const Vector3 center = uniform.in(Vector3::Constant(-1e3), Vector3::Constant(1e3));
		SCOPED_TRACE(testing::Message() << "seed " << seed << ", size " << size.transpose());
		const auto points = rotatedBox(size, R, center);
		const auto poly = dda::buildConvexPolyhedron(points);
		expectValidPolyhedron(poly, points);
		EXPECT_EQ(faceSizes(poly), repeatedSize(6, 4));
		EXPECT_EQ(poly.edges.size(), 12u);
	}
}

TEST(GeometryTopology, RandomlyPlacedHexagonalPrismsHaveEightFaces) {
	for (unsigned seed = 0; seed < 100; ++seed) {
		Uniform uniform(2000 + seed);
		const Matrix3 R = randomRotation(uniform);
		const double scale = std::pow(10.0, uniform.in(-2, 2));
		const Vector3 center = uniform.in(Vector3::Constant(-1e3), Vector3::Constant(1e3));
		SCOPED_TRACE(testing::Message() << "seed " << seed);
		const auto points = moved(hexagonalPrism(0.7 * scale, 2.5 * scale), R, center);
		const auto poly = dda::buildConvexPolyhedron(points);
		expectValidPolyhedron(poly, points);
		EXPECT_EQ(faceSizes(poly), (std::multiset<std::size_t>{4, 4, 4, 4, 4, 4, 6, 6}));
		EXPECT_EQ(poly.edges.size(), 18u);
	}
}

TEST(GeometryTopology, RandomlyPlacedOctahedraHaveEightTriangles) {
	for (unsigned seed = 0; seed < 100; ++seed) {
		Uniform uniform(3000 + seed);
		const Matrix3 R = randomRotation(uniform);
		const double scale = std::pow(10.0, uniform.in(-2, 2));
		const Vector3 center = uniform.in(Vector3::Constant(-1e3), Vector3::Constant(1e3));
		SCOPED_TRACE(testing::Message() << "seed " << seed);
		std::vector<Vector3> octahedron = regularOctahedron();
		for (Vector3& p : octahedron) p *= scale;
		const auto points = moved(octahedron, R, center);
		const auto poly = dda::buildConvexPolyhedron(points);
		expectValidPolyhedron(poly, points);
		EXPECT_EQ(faceSizes(poly), repeatedSize(8, 3));
		EXPECT_EQ(poly.edges.size(), 12u);
	}
}

TEST(GeometryTopology, FinelyTessellatedSphereDoesNotMergeIntoCurvedFaces) {
	// Neighbouring hull triangles of a 200-point sphere are tilted against each
	// other: a merge that compared each triangle with the last one added (and
	// not with one fixed plane) could chain them into one curved "face".
	for (const Vector3& center : {Vector3(0, 0, 0), Vector3(3, -2, 1), Vector3(-700, 400, 900)}) {
		SCOPED_TRACE(testing::Message() << "centre " << center.transpose());
		const auto points = fibonacciSphere(200, 2.0, center);
		const auto poly = dda::buildConvexPolyhedron(points);
		expectValidPolyhedron(poly, points);  // includes: every face planar within the tolerance
		std::size_t largest = 0;
		for (const auto& face : poly.faces) largest = std::max(largest, face.size());
		EXPECT_LE(largest, 6u);
		EXPECT_GE(poly.faces.size(), 2 * points.size() - 4 - 20);  // nearly simplicial
	}
}

TEST(GeometryTopology, FaceNormalIsTheUnitOutwardNewellNormal) {
	const auto cube = dda::buildConvexPolyhedron(unitCube());
	for (const auto& face : cube.faces) {
		const Vector3 n = dda::faceNormal(cube.vertices, face);
		// Axis-aligned, pointing away from the cube's centre.
		Vector3 mean = Vector3::Zero();
		for (int v : face) mean += cube.vertices[v];
		mean /= static_cast<double>(face.size());
		const Vector3 expected = (2 * mean - Vector3::Ones());
		EXPECT_LE((n - expected).norm(), 1e-15) << n.transpose();
	}

	// A rotated box far from the origin: the normals are the rotated axes.
	Uniform uniform(7);
	const Matrix3 R = randomRotation(uniform);
	const Vector3 center(1e3, -1e3, 500);
	const auto points = rotatedBox({1e-2, 2e-2, 3e-2}, R, center);
	const auto poly = dda::buildConvexPolyhedron(points);
	ASSERT_EQ(poly.faces.size(), 6u);
	for (const auto& face : poly.faces) {
		const Vector3 n = dda::faceNormal(poly.vertices, face);
		EXPECT_NEAR(n.norm(), 1, 1e-15);
		const Vector3 local = R.transpose() * n;  // one of +-e_x, +-e_y, +-e_z
		Eigen::Index axis;
		local.cwiseAbs().maxCoeff(&axis);
		EXPECT_LE((local - Vector3::Unit(axis) * (local[axis] > 0 ? 1 : -1)).norm(), 1e-9) << local.transpose();
		Vector3 mean = Vector3::Zero();
		for (int v : face) mean += poly.vertices[v];
		EXPECT_GT(n.dot(mean / 4 - center), 0) << "normal points inward";
	}

	EXPECT_THROW(dda::faceNormal(cube.vertices, {0, 1}), dda::InputError);
	EXPECT_THROW(dda::faceNormal(cube.vertices, {0, 1, 8}), dda::InputError);
	EXPECT_THROW(dda::faceNormal(cube.vertices, {0, 1, -1}), dda::InputError);
	const std::vector<Vector3> collinear{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
	EXPECT_THROW(dda::faceNormal(collinear, {0, 1, 2}), dda::InputError);
}

TEST(GeometryTopology, CornerJustAboveTheToleranceIsAFaceOfItsOwn) {
	// A cube with a pyramid of height 1e-6 on top: a real (if low) apex, far
	// above 1e-9 x size, so the top is 4 triangles.
	auto points = unitCube();
	points.emplace_back(0.5, 0.5, 1 + 1e-6);
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	EXPECT_EQ(faceSizes(poly), (std::multiset<std::size_t>{3, 3, 3, 3, 4, 4, 4, 4, 4}));
	EXPECT_EQ(poly.edges.size(), 16u);
}

TEST(GeometryTopology, InputOrderIsPreserved) {
	// A shuffled cube: faces must refer to the caller's indices.
	std::vector<Vector3> points = unitCube();
	std::swap(points[0], points[7]);
	std::swap(points[2], points[5]);
	std::rotate(points.begin(), points.begin() + 3, points.end());
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	expectExactlyPlanarFaces(poly);
	EXPECT_EQ(faceSizes(poly), repeatedSize(6, 4));
}

TEST(GeometryTopology, PointsOnAnEllipsoidGiveASimplicialPolyhedron) {
	// Points in general position: every face is a triangle, so E = 3V - 6 and
	// F = 2V - 4.
	const auto points = ellipsoidPoints(16, {1.5, 1.0, 0.7}, {2, -1, 0.5});
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	expectExactlyPlanarFaces(poly);
	const std::size_t v = points.size();
	EXPECT_EQ(poly.faces.size(), 2 * v - 4);
	EXPECT_EQ(poly.edges.size(), 3 * v - 6);
	EXPECT_EQ(faceSizes(poly), repeatedSize(2 * v - 4, 3));
}

// ================================================================ mass properties

TEST(GeometryMass, UnitTetrahedronMatchesHandIntegration) {
	// By hand for 0 <= x, y, z, x + y + z <= 1: V = 1/6, centroid 1/4,
	// ∫x² = 1/60, ∫xy = 1/120, so J_xx = 1/60 - V/16 = 1/160 and
	// J_xy = 1/120 - V/16 = -1/480.
	const std::vector<Vector3> points{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	expectExactlyPlanarFaces(poly);
	EXPECT_EQ(poly.faces.size(), 4u);
	EXPECT_EQ(poly.edges.size(), 6u);

	const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);
	EXPECT_LE(relativeError(mass.volume, 1.0 / 6), kRelTol);
	EXPECT_LE((mass.centroid - Vector3::Constant(0.25)).norm(), kRelTol);
	Matrix3 expected = Matrix3::Constant(-1.0 / 480);
	expected.diagonal().setConstant(1.0 / 160);
	EXPECT_LE(relativeError(mass.secondMoment, expected), kRelTol);
}

TEST(GeometryMass, GeneralTetrahedronMatchesClosedForm) {
	const std::vector<Vector3> points{{0.3, -1.2, 2.0}, {2.1, 0.4, 1.7}, {-0.5, 1.9, 2.6}, {0.8, 0.2, 4.4}};
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	expectExactlyPlanarFaces(poly);
	const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);

	const Moments expected = tetrahedronMoments(points[0], points[1], points[2], points[3]);
	EXPECT_LE(relativeError(mass.volume, std::abs(expected.volume)), kRelTol);
	EXPECT_LE((mass.centroid - expected.centroid).norm(), kRelTol * boundingDiagonal(points));
	const Matrix3 expectedJ = expected.volume > 0 ? expected.J : Matrix3(-expected.J);
	EXPECT_LE(relativeError(mass.secondMoment, expectedJ), kRelTol);
}

TEST(GeometryMass, TetrahedronReferenceFormulaReproducesTheBox) {
	// Checks the tests' own tetrahedron formula: the six Kuhn tetrahedra
	// (0, e_i, e_i + e_j, 1) for the permutations (i, j, k) tile the box.
	const Vector3 size(1.3, 0.6, 2.2);
	const Vector3 lo(-0.4, 3.0, 1.0);
	std::vector<Moments> parts;
	std::array<int, 3> axes{0, 1, 2};
	do {
		Vector3 step[3];
		for (int k = 0; k < 3; ++k) step[k] = size[axes[k]] * Vector3::Unit(axes[k]);
		Moments m = tetrahedronMoments(lo, lo + step[0], lo + step[0] + step[1], lo + size);
		if (m.volume < 0) {  // odd permutation: left-handed
			m.volume = -m.volume;
			m.J = -m.J;
		}
		parts.push_back(m);
	} while (std::next_permutation(axes.begin(), axes.end()));

	const Moments box = combine(parts);
	EXPECT_LE(relativeError(box.volume, size.prod()), kRelTol);
	EXPECT_LE((box.centroid - (lo + size / 2)).norm(), kRelTol * size.norm());
	EXPECT_LE(relativeError(box.J, boxSecondMoment(size)), kRelTol);
}

TEST(GeometryMass, OffsetBoxMatchesClosedForm) {
	const Vector3 size(1, 2, 3);
	const Vector3 lo(10, -20, 30);
	const auto points = boxCorners(lo, size);
	const auto poly = dda::buildConvexPolyhedron(points);
	const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);
	EXPECT_LE(relativeError(mass.volume, 6.0), kRelTol);
	EXPECT_LE((mass.centroid - Vector3(10.5, -19, 31.5)).norm(), kRelTol * size.norm());
	EXPECT_LE(relativeError(mass.secondMoment, Matrix3(Vector3(0.5, 2, 4.5).asDiagonal())), kRelTol);
}

TEST(GeometryMass, BoxesOfAllScalesMatchClosedForm) {
	// J scales as L^5: from 1e-15 m^5 to 1e20 m^5, all at the same relative accuracy.
	const std::pair<Vector3, Vector3> cases[] = {
	    {{-3, 0.5, 2}, {60, 1, 1}},
	    {{0.1, 0.2, 0.3}, {1e-3, 2e-3, 1.5e-3}},
	    {{-5e3, 1e4, 0}, {1e4, 2e4, 1.5e4}},
	    {{0.1 + 0.2, 0.7, 1.1}, {0.1 + 0.2, 0.3 + 0.6, 0.7 - 0.4}},
	};
	for (const auto& [lo, size] : cases) {
		SCOPED_TRACE(testing::Message() << "size " << size.transpose());
		const auto poly = dda::buildConvexPolyhedron(boxCorners(lo, size));
		const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);
		EXPECT_LE(relativeError(mass.volume, size.prod()), kRelTol);
		EXPECT_LE((mass.centroid - (lo + size / 2)).norm(), kRelTol * size.norm());
		EXPECT_LE(relativeError(mass.secondMoment, boxSecondMoment(size)), kRelTol);
	}
}

TEST(GeometryMass, OctahedronMatchesClosedForm) {
	// |x| + |y| + |z| <= 1: V = 4/3, and by symmetry J = (∫x²) I with
	// ∫x² = 8 ∫ over the unit simplex = 8/60.
	const auto poly = dda::buildConvexPolyhedron(regularOctahedron());
	const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);
	EXPECT_LE(relativeError(mass.volume, 4.0 / 3), kRelTol);
	EXPECT_LE(mass.centroid.norm(), kRelTol);
	EXPECT_LE(relativeError(mass.secondMoment, Matrix3(8.0 / 60 * Matrix3::Identity())), kRelTol);
}

TEST(GeometryMass, IrregularPolyhedronMatchesIndependentDecomposition) {
	const auto points = ellipsoidPoints(16, {1.5, 1.0, 0.7}, {2, -1, 0.5});
	const auto poly = dda::buildConvexPolyhedron(points);
	const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);

	const double cgalVolume = CGAL::to_double(CGAL::Polygon_mesh_processing::volume(cgalHull(points)));
	EXPECT_LE(relativeError(mass.volume, cgalVolume), kRelTol);

	const Moments expected = referenceHullMoments(points);
	EXPECT_LE(relativeError(mass.volume, expected.volume), kRelTol);
	EXPECT_LE((mass.centroid - expected.centroid).norm(), kRelTol * boundingDiagonal(points));
	EXPECT_LE(relativeError(mass.secondMoment, expected.J), kRelTol);
	// A sanity bound that a wrong formula can fail: J is positive definite.
	EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix3>(mass.secondMoment).eigenvalues().minCoeff(), 0);
}

TEST(GeometryMass, RigidMotionMovesCentroidAndRotatesSecondMoment) {
	const auto points = ellipsoidPoints(16, {1.5, 1.0, 0.7}, {2, -1, 0.5});
	const Matrix3 R = rotation(0.7, {1, 2, 3});
	const Vector3 t(12.5, -3.25, 7);
	const auto movedPoints = moved(points, R, t);

	const auto before = dda::buildConvexPolyhedron(points);
	const auto after = dda::buildConvexPolyhedron(movedPoints);
	expectValidPolyhedron(after, movedPoints);
	const MassProperties m0 = dda::computeMassProperties(before.vertices, before.faces);
	const MassProperties m1 = dda::computeMassProperties(after.vertices, after.faces);

	EXPECT_LE(relativeError(m1.volume, m0.volume), kRelTol);
	EXPECT_LE((m1.centroid - (R * m0.centroid + t)).norm(), kRelTol * boundingDiagonal(points));
	EXPECT_LE(relativeError(m1.secondMoment, R * m0.secondMoment * R.transpose()), kRelTol);
	EXPECT_LE(relativeError(m1.secondMoment.trace(), m0.secondMoment.trace()), kRelTol);
	const Vector3 eig0 = Eigen::SelfAdjointEigenSolver<Matrix3>(m0.secondMoment).eigenvalues();
	const Vector3 eig1 = Eigen::SelfAdjointEigenSolver<Matrix3>(m1.secondMoment).eigenvalues();
	EXPECT_LE((eig1 - eig0).norm() / eig0.norm(), kRelTol);
}

TEST(GeometryMass, BoxFarFromOriginKeepsItsMoments) {
	// A 1 x 2 x 3 box rotated about its centre and carried 1 km away: the
	// integrals must not lose digits to the large coordinates.
	const Vector3 size(1, 2, 3);
	const Matrix3 R = rotation(1.1, {-0.3, 0.8, 0.5});
	const Vector3 center(1e3, -1e3, 1e3);
	const auto points = moved(boxCorners(-size / 2, size), R, center);
	const auto poly = dda::buildConvexPolyhedron(points);
	expectValidPolyhedron(poly, points);
	const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);

	const Matrix3 expectedJ = R * boxSecondMoment(size) * R.transpose();
	EXPECT_LE(relativeError(mass.volume, size.prod()), kRelTol);
	EXPECT_LE((mass.centroid - center).norm(), kRelTol * center.norm());
	EXPECT_LE(relativeError(mass.secondMoment, expectedJ), kRelTol);
	EXPECT_LE(relativeError(mass.secondMoment.trace(), expectedJ.trace()), kRelTol);
}

TEST(GeometryMass, RandomlyPlacedBoxesMatchClosedForm) {
	// The boxes of RandomlyPlacedBoxesOfAllScalesHaveSixQuads, now merged into
	// nearly planar quads: the fan triangles still close the surface, so V, c
	// and J are exact up to round-off. Rounding the corners themselves changes
	// the box by ~1e-16 x (distance from origin / size) relative, so centres
	// stay within 1e3 x size of the origin (and within 1e3 m) to leave 1e-12
	// meaningful.
	for (unsigned seed = 0; seed < 200; ++seed) {
		Uniform uniform(seed);
		const Matrix3 R = randomRotation(uniform);
		const double scale = std::pow(10.0, uniform.in(-3, 3));
		const Vector3 size = scale * uniform.in(Vector3::Constant(0.5), Vector3::Constant(1.5));
		const double reach = std::min(1e3, 1e3 * scale);
		const Vector3 center = uniform.in(Vector3::Constant(-reach), Vector3::Constant(reach));
		SCOPED_TRACE(testing::Message() << "seed " << seed << ", size " << size.transpose() << ", centre "
		                                << center.transpose());
		const auto poly = dda::buildConvexPolyhedron(rotatedBox(size, R, center));
		ASSERT_EQ(faceSizes(poly), repeatedSize(6, 4));
		const MassProperties mass = dda::computeMassProperties(poly.vertices, poly.faces);
		EXPECT_LE(relativeError(mass.volume, size.prod()), kRelTol);
		EXPECT_LE((mass.centroid - center).norm(), kRelTol * size.norm());
		EXPECT_LE(relativeError(mass.secondMoment, R * boxSecondMoment(size) * R.transpose()), kRelTol);
	}
}

TEST(GeometryMass, RejectsFacesThatDoNotEncloseVolume) {
	const auto poly = dda::buildConvexPolyhedron(unitCube());
	std::vector<std::vector<int>> inward = poly.faces;
	for (auto& face : inward) std::reverse(face.begin(), face.end());
	EXPECT_THROW(dda::computeMassProperties(poly.vertices, inward), dda::InputError);
	EXPECT_THROW(dda::computeMassProperties(poly.vertices, {}), dda::InputError);

	std::vector<std::vector<int>> outOfRange = poly.faces;
	outOfRange[2][1] = 8;
	EXPECT_THROW(dda::computeMassProperties(poly.vertices, outOfRange), dda::InputError);
	std::vector<std::vector<int>> degenerate = poly.faces;
	degenerate[0].resize(2);
	EXPECT_THROW(dda::computeMassProperties(poly.vertices, degenerate), dda::InputError);
}

// ================================================================ input errors

TEST(GeometryInput, RejectsFewerThanFourPoints) {
	expectInputError({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {"at least 4", "got 3"});
	expectInputError({}, {"at least 4", "got 0"});
}

TEST(GeometryInput, RejectsNonFiniteCoordinates) {
	auto points = unitCube();
	points[2] = Vector3(std::nan(""), 0, 1);
	expectInputError(points, {"point 2 ", "non-finite", "(nan, 0, 1)"});
	points = unitCube();
	points[5].y() = -std::numeric_limits<double>::infinity();
	expectInputError(points, {"point 5 ", "non-finite", "-inf"});
}

TEST(GeometryInput, RejectsCoincidentPoints) {
	auto points = unitCube();
	points[4] = points[1];
	expectInputError(points, {"points 1 and 4", "coincide at (1, 0, 0)"});
}

TEST(GeometryInput, RejectsPointsCloserThanTheScaledTolerance) {
	// 1e-15 apart in a block of diagonal ~1.7: far below 1e-12 x diagonal.
	auto points = unitCube();
	points[6] = points[3] + Vector3(1e-15, 0, -1e-15);
	expectInputError(points, {"points 3 and 6", "coincide"});
	// The same relative gap in a tiny block.
	points = boxCorners({0.1, 0.2, 0.3}, Vector3::Constant(1e-3));
	points[6] = points[3] + Vector3(1e-18, 0, 0);
	expectInputError(points, {"points 3 and 6", "coincide"});
}

TEST(GeometryInput, RejectsCoplanarPoints) {
	// A convex pentagon in z = 0, and exactly coplanar points on x + y + z = 1.
	expectInputError({{0, 0, 0}, {2, 0, 0}, {3, 1, 0}, {1, 3, 0}, {-1, 1, 0}}, {"all 5 points are coplanar"});
	expectInputError({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, -1, 0}, {0, 2, -1}}, {"all 5 points are coplanar"});
	// Collinear points are coplanar too.
	expectInputError({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}, {"all 4 points are coplanar"});
}

TEST(GeometryInput, RejectsInteriorPoints) {
	auto points = unitCube();
	points.emplace_back(0.5, 0.5, 0.5);
	expectInputError(points, {"point 8 (0.5, 0.5, 0.5)", "strictly inside"});

	points = unitCube();
	points.insert(points.begin(), Vector3(0.25, 0.5, 0.75));
	expectInputError(points, {"point 0 ", "strictly inside"});

	// A point just inside a curved hull: 1e-6 relative below the surface.
	points = ellipsoidPoints(16, {1.5, 1.0, 0.7}, Vector3::Zero());
	points.insert(points.begin() + 5, (1 - 1e-6) * points[9]);
	expectInputError(points, {"point 5 ", "strictly inside"});
}

TEST(GeometryInput, RejectsPointsOnTheSurfaceThatAreNotCorners) {
	auto points = unitCube();
	points.emplace_back(0.5, 0.5, 0);  // centre of the bottom face
	expectInputError(points, {"point 8 (0.5, 0.5, 0)", "on the hull surface but is not a corner"});

	points = unitCube();
	points.insert(points.begin() + 3, Vector3(0.5, 0, 1));  // middle of a top edge
	expectInputError(points, {"point 3 ", "not a corner"});

	// Middle of an octahedron edge, listed first.
	points = regularOctahedron();
	points.insert(points.begin(), Vector3(0.5, 0.5, 0));
	expectInputError(points, {"point 0 ", "not a corner"});
}

TEST(GeometryInput, RejectsNonCornersOfRotatedBoxes) {
	// A face centre, an edge midpoint and an inner point of a randomly placed
	// box, after rounding: slightly off the (nearly planar) faces either way.
	for (unsigned seed = 0; seed < 50; ++seed) {
		Uniform uniform(4000 + seed);
		const Matrix3 R = randomRotation(uniform);
		const Vector3 size = std::pow(10.0, uniform.in(-2, 2)) * uniform.in(Vector3::Constant(0.5), Vector3::Constant(1.5));
		const Vector3 center = uniform.in(Vector3::Constant(-1e3), Vector3::Constant(1e3));
		SCOPED_TRACE(testing::Message() << "seed " << seed);
		const auto box = rotatedBox(size, R, center);
		const auto at = [&](const Vector3& local) { return Vector3(R * local.cwiseProduct(size) + center); };

		auto points = box;
		points.push_back(at({0.5, 0, 0}));  // centre of the +x face
		expectInputError(points, {"point 8 ", "on the hull surface but is not a corner", "inside a face"});

		points = box;
		points.insert(points.begin() + 2, at({0.5, 0.5, 0}));  // midpoint of an edge
		expectInputError(points, {"point 2 ", "on the hull surface but is not a corner", "inside an edge"});

		points = box;
		points.push_back(at({0.1, -0.2, 0.3}));
		expectInputError(points, {"point 8 ", "strictly inside"});
	}
}

TEST(GeometryInput, RejectsACornerWithinTheToleranceOfAFacePlane) {
	// A pyramid of height 1e-12 on a unit cube: a true corner, but as close to
	// the top plane as round-off could put a point of that face. Rejected,
	// never silently dropped.
	auto points = unitCube();
	points.emplace_back(0.5, 0.5, 1 + 1e-12);
	expectInputError(points, {"point 8 ", "within 1e-09 x the bounding-box diagonal of the plane of the face with corners",
	                          "the block is too flat there"});

	// The same, rotated and moved: still rejected.
	Uniform uniform(5);
	const Matrix3 R = randomRotation(uniform);
	expectInputError(moved(points, R, {10, 20, -30}), {"point 8 ", "too flat there"});
}

TEST(GeometryInput, RejectsBlocksThinnerThanTheTolerance) {
	// Not coplanar (exactly), but flatter than 1e-9 x size everywhere.
	expectInputError(boxCorners({0, 0, 0}, {1, 1, 1e-10}), {"within 1e-09 x", "too flat"});
	expectInputError({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, 1e-11}}, {"within 1e-09 x", "too flat"});
}
