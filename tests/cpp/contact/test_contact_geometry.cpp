// Tests of the contact geometry kernels (pkg/dda/contact): vertex-face and
// edge-edge distances, and the linearised normal distance.
//
// Reference values are closed forms of simple configurations (a point above a
// square or triangular face, two crossing edges in parallel planes), brute
// force (segment distances on a grid), and central finite differences of the
// exact, nonlinear normal distance. Each configuration is also turned by
// random rotations and moved ~1 km from the origin to check invariance.
#include "dda/contact/Distance.hpp"
#include "dda/contact/Linearization.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace {

using dda::Vector12;
using dda::Vector3;
using dda::Matrix3;

constexpr double kPi = 3.14159265358979323846;

Matrix3 randomRotation(std::mt19937& rng) {
	std::normal_distribution<double> normal(0.0, 1.0);
	Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
	q.normalize();
	return q.toRotationMatrix();
}

Vector3 randomVector(std::mt19937& rng, double scale) {
	std::uniform_real_distribution<double> u(-scale, scale);
	return Vector3(u(rng), u(rng), u(rng));
}

bool finite(const Vector3& v) { return v.allFinite(); }

// A rigid placement x -> R x + o.
struct Placement {
	Matrix3 R = Matrix3::Identity();
	Vector3 o = Vector3::Zero();
	Vector3 operator()(const Vector3& x) const { return R * x + o; }
};

std::vector<Placement> placements(unsigned seed, int count, double offset) {
	std::mt19937 rng(seed);
	std::vector<Placement> out{Placement{}};
	for (int k = 0; k < count; ++k) out.push_back({randomRotation(rng), randomVector(rng, offset)});
	return out;
}

// Index of the face whose outward normal is closest to `direction`.
int faceAlong(const dda::ConvexPolyhedron& poly, const Vector3& direction) {
	int best = -1;
	double bestDot = -2;
	for (std::size_t f = 0; f < poly.faces.size(); ++f) {
		const double d = dda::faceNormal(poly.vertices, poly.faces[f]).dot(direction);
		if (d > bestDot) {
			bestDot = d;
			best = static_cast<int>(f);
		}
	}
	return best;
}

// ------------------------------------------------------------------ vertex-face

// Sample positions along a sweep parameter, with the exact boundary values
// 0 and `end`, points 1e-12 either side (inside within the tolerance) and
// 1e-6 either side (decided by geometry).
std::vector<double> sweepParameters(double end) {
	std::vector<double> s{-0.5, -1e-6, -1e-12, 0, 1e-12, 1e-6};
	for (int k = 1; k < 8; ++k) s.push_back(end * k / 8.0);
	for (double x : {end - 1e-6, end - 1e-12, end, end + 1e-12, end + 1e-6, end + 0.5}) s.push_back(x);
	return s;
}

struct SweepCase {
	Vector3 point;          // in the unrotated frame
	double distance;        // closed-form signed height above the face plane
	double margin;          // closed-form in-plane margin (> 0 inside)
};

// A vertex swept across the top face z = 0 of the unit box [0,1]^2 x [-1,0]:
// along the midline y = 0.5 (crossing two edges), along the diagonal y = x
// (crossing two corners) and on a slanted line crossing the plane.
std::vector<SweepCase> squareSweep() {
	std::vector<SweepCase> cases;
	for (double h : {0.25, 0.0, -0.1}) {
		for (double s : sweepParameters(1.0)) {
			cases.push_back({Vector3(s, 0.5, h), h, std::min({s, 1 - s, 0.5})});
			cases.push_back({Vector3(s, s, h), h, std::min(s, 1 - s)});
		}
	}
	for (double s : sweepParameters(1.0)) cases.push_back({Vector3(s, 0.3, 0.5 - s), 0.5 - s, std::min({s, 1 - s, 0.3})});
	return cases;
}

void checkSweep(const std::vector<Vector3>& corners, const Vector3& faceDirection, const std::vector<SweepCase>& cases,
                unsigned seed) {
	for (const Placement& place : placements(seed, 12, 1e3)) {
		std::vector<Vector3> moved;
		for (const Vector3& c : corners) moved.push_back(place(c));
		const dda::ConvexPolyhedron poly = dda::buildConvexPolyhedron(moved);
		const int f = faceAlong(poly, place.R * faceDirection);
		const double tolerance = 1e-9;  // [m]; round-off here is ~1e-13 m
		const double roundOff = place.o.norm() > 0 ? 1e-11 : 1e-15;
		for (const SweepCase& c : cases) {
			const Vector3 p = place(c.point);
			const dda::VertexFaceResult r = dda::vertexFaceDistance(p, poly.vertices, poly.faces[f], tolerance);
			SCOPED_TRACE("point " + std::to_string(c.point.x()) + " " + std::to_string(c.point.y()) + " " +
			             std::to_string(c.point.z()));
			EXPECT_NEAR((r.normal - place.R * faceDirection).norm(), 0, 1e-12);
			EXPECT_NEAR(r.distance, c.distance, roundOff);
			EXPECT_NEAR(r.insideMargin, c.margin, roundOff);
			EXPECT_EQ(r.inside, c.margin >= -tolerance);
			const Vector3 expectedProjection = place(c.point - c.distance * faceDirection);
			EXPECT_NEAR((r.projection - expectedProjection).norm(), 0, roundOff);
		}
	}
}

TEST(ContactVertexFace, SweepAcrossSquareFaceEdgesAndCorners) {
	std::vector<Vector3> box;
	for (int k = 0; k < 8; ++k) box.emplace_back(k & 1, (k >> 1) & 1, -double((k >> 2) & 1));
	checkSweep(box, Vector3::UnitZ(), squareSweep(), 11);
}

TEST(ContactVertexFace, SweepAcrossTriangleHypotenuse) {
	// Face z = 0 of the tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,-1): the
	// triangle x, y >= 0, x + y <= 1. The line y = 0.25 leaves it at x = 0.75
	// across the slanted edge, whose in-plane distance is (1 - x - y)/sqrt(2).
	const std::vector<Vector3> tetra{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}};
	std::vector<SweepCase> cases;
	for (double h : {0.5, 0.0, -0.2}) {
		for (double s : sweepParameters(0.75)) {
			cases.push_back({Vector3(s, 0.25, h), h, std::min({s, 0.25, (0.75 - s) / std::sqrt(2.0)})});
		}
	}
	// Through the corner (1, 0): along y = 0 from x = 0.5 to 1.5.
	for (double s : {0.5, 1 - 1e-6, 1.0, 1 + 1e-12, 1 + 1e-6, 1.5}) {
		// On the edge y = 0 (margin 0) up to the corner, then outside the hypotenuse.
		cases.push_back({Vector3(s, 0, 0.1), 0.1, std::min(0.0, (1 - s) / std::sqrt(2.0))});
	}
	checkSweep(tetra, Vector3::UnitZ(), cases, 12);
}

TEST(ContactVertexFace, VertexExactlyOnFaceCornerAndEdge) {
	std::vector<Vector3> box;
	for (int k = 0; k < 8; ++k) box.emplace_back(k & 1, (k >> 1) & 1, -double((k >> 2) & 1));
	const dda::ConvexPolyhedron poly = dda::buildConvexPolyhedron(box);
	const int f = faceAlong(poly, Vector3::UnitZ());
	for (int v : poly.faces[f]) {
		const dda::VertexFaceResult r = dda::vertexFaceDistance(poly.vertices[v], poly.vertices, poly.faces[f], 0.0);
		EXPECT_EQ(r.distance, 0);
		EXPECT_EQ(r.insideMargin, 0);
		EXPECT_TRUE(r.inside);  // zero tolerance: exactly on the corner is inside
	}
	const dda::VertexFaceResult edge = dda::vertexFaceDistance(Vector3(0.5, 1, 0), poly.vertices, poly.faces[f], 0.0);
	EXPECT_TRUE(edge.inside);
	EXPECT_EQ(edge.insideMargin, 0);
	const dda::VertexFaceResult out =
	    dda::vertexFaceDistance(Vector3(0.5, 1 + 1e-15, 0), poly.vertices, poly.faces[f], 0.0);
	EXPECT_FALSE(out.inside);
	EXPECT_TRUE(dda::vertexFaceDistance(Vector3(0.5, 1 + 1e-15, 0), poly.vertices, poly.faces[f], 1e-12).inside);
}

TEST(ContactVertexFace, DegenerateFaceThrowsInsteadOfNaN) {
	const std::vector<Vector3> v{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
	EXPECT_THROW(dda::vertexFaceDistance(Vector3(0, 1, 0), v, {0, 1, 2}, 0.0), dda::InputError);
	EXPECT_THROW(dda::vertexFaceDistance(Vector3(0, 1, 0), v, {0, 1}, 0.0), dda::InputError);
}

// ------------------------------------------------------------------ edge-edge

// Edge i from (-1,0,0) to (1,0,0). Edge j of half-length 1, direction
// (cos(theta), sin(theta), 0), centre (0.1, -0.4 sin(theta), h): its point at
// line parameter tau = 0.4 from the centre, (0.1 + 0.4 cos(theta), 0, h), lies
// straight above edge i. Closed form: distance h along +z,
// s = (1.1 + 0.4 cos(theta))/2, t = (tau + 1)/2 = 0.7.
struct CrossingCase {
	Vector3 p1, p2, p3, p4;
	double s, t;
};

CrossingCase crossing(double theta, double h) {
	const Vector3 dir(std::cos(theta), std::sin(theta), 0);
	const Vector3 centre(0.1, -0.4 * std::sin(theta), h);
	return {Vector3(-1, 0, 0), Vector3(1, 0, 0), centre - dir, centre + dir, (0.1 + 0.4 * std::cos(theta) + 1) / 2,
	        0.7};
}

TEST(ContactEdgeEdge, CrossingEdgesAtManyAnglesMatchClosedForm) {
	for (double theta : {kPi / 2, kPi / 3, 1e-3, 1e-8}) {
		for (double h : {0.2, 0.0, -0.05}) {
			const CrossingCase c = crossing(theta, h);
			const bool tiny = theta < 1e-6;
			// Offsets 1 km from the origin cost ~1e-13 m of direction accuracy;
			// at 1e-8 rad that is 1e-5 in s, t: the tiny angle runs unmoved.
			for (const Placement& place : placements(21, tiny ? 0 : 12, 1e3)) {
				SCOPED_TRACE("theta " + std::to_string(theta) + " h " + std::to_string(h));
				const double angleTolerance = tiny ? 1e-10 : dda::kDefaultParallelAngleTolerance;
				for (double side : {1.0, -1.0}) {
					const dda::EdgeEdgeResult r = dda::edgeEdgeDistance(
					    place(c.p1), place(c.p2), place(c.p3), place(c.p4), side * (place.R * Vector3::UnitZ()), 1e-9,
					    angleTolerance);
					// Conditioning: a point error delta in the plane of the edges moves the
					// closest points by ~delta/sin(theta); a tilt alpha of an edge out of
					// that plane turns n by ~alpha/sin(theta), which moves them by
					// ~h alpha/sin(theta)^2. Unmoved, the edges are exactly parallel to
					// z = 0 (no tilt) and delta ~1e-16; placed 1 km away, delta and
					// alpha are ~1e-13 (m, rad).
					const double sine = std::sin(theta);
					const double base = place.o.norm() > 0 ? 1e-12 : 1e-15;
					const double tilt = place.o.norm() > 0 ? std::abs(h) / (sine * sine) : 0.0;
					const double positionTolerance = base * (1 / sine + tilt + 1);
					EXPECT_FALSE(r.parallel);
					EXPECT_FALSE(r.degenerate);
					EXPECT_TRUE(r.interior);
					EXPECT_NEAR((r.normal - side * (place.R * Vector3::UnitZ())).norm(), 0, positionTolerance);
					EXPECT_NEAR(r.distance, side * h, 10 * positionTolerance);
					EXPECT_NEAR(r.s, c.s, positionTolerance);
					EXPECT_NEAR(r.t, c.t, positionTolerance);
					EXPECT_NEAR((r.closestJ - r.closestI).norm(), std::abs(h), 10 * positionTolerance);
				}
			}
			// With the default tolerance, 1e-8 rad counts as parallel.
			if (tiny) {
				const dda::EdgeEdgeResult r = dda::edgeEdgeDistance(c.p1, c.p2, c.p3, c.p4, Vector3::UnitZ(), 1e-9);
				EXPECT_TRUE(r.parallel);
				EXPECT_FALSE(r.interior);
				EXPECT_TRUE(std::isfinite(r.distance) && finite(r.normal));
				EXPECT_NEAR(r.distance, h, 1e-7);  // the lines' distance
			}
		}
	}
}

TEST(ContactEdgeEdge, OnSegmentConditionAtEndpoints) {
	// Edge j crosses above edge i's endpoint P2 = (1,0,0) exactly, then beyond.
	for (double x : {1.0, 1.0 + 1e-12, 1.0 + 1e-6}) {
		const dda::EdgeEdgeResult r = dda::edgeEdgeDistance(Vector3(-1, 0, 0), Vector3(1, 0, 0), Vector3(x, -1, 0.3),
		                                                    Vector3(x, 1, 0.3), Vector3::UnitZ(), 1e-9);
		EXPECT_EQ(r.interior, x - 1 <= 1e-9) << x;
		EXPECT_EQ(r.s, 1.0);
		EXPECT_NEAR(r.t, 0.5, 1e-15);
		EXPECT_NEAR(r.distance, 0.3, 1e-15);
	}
}

TEST(ContactEdgeEdge, ClosestPointsOfSegmentsMatchBruteForce) {
	std::mt19937 rng(31);
	constexpr int kGrid = 400;
	for (int trial = 0; trial < 60; ++trial) {
		const Vector3 p1 = randomVector(rng, 1), p2 = randomVector(rng, 1);
		const Vector3 p3 = randomVector(rng, 1), p4 = randomVector(rng, 1);
		const dda::EdgeEdgeResult r = dda::edgeEdgeDistance(p1, p2, p3, p4, Vector3::UnitZ(), 0.0);
		ASSERT_FALSE(r.parallel);
		EXPECT_GE(r.s, 0);
		EXPECT_LE(r.s, 1);
		EXPECT_GE(r.t, 0);
		EXPECT_LE(r.t, 1);
		const double found = (r.closestJ - r.closestI).norm();
		double brute = 1e300;
		for (int a = 0; a <= kGrid; ++a) {
			const Vector3 x = p1 + (p2 - p1) * (double(a) / kGrid);
			for (int b = 0; b <= kGrid; ++b) brute = std::min(brute, (p3 + (p4 - p3) * (double(b) / kGrid) - x).norm());
		}
		EXPECT_LE(found, brute + 1e-14);              // never worse than any sample
		EXPECT_GE(found, brute - 4.0 / kGrid);        // and samples are close to it
		// The signed distance is the projection of any connecting vector on n.
		EXPECT_NEAR(r.distance, r.normal.dot(r.closestJ - r.closestI), 1e-14);
		if (r.interior) EXPECT_NEAR(found, std::abs(r.distance), 1e-14);
	}
}

TEST(ContactEdgeEdge, ExactlyParallelEdgesSetFlagsWithoutNaN) {
	const Vector3 p1(-1, 0, 0), p2(1, 0, 0);
	for (double direction : {1.0, -1.0}) {  // parallel and antiparallel
		const Vector3 p3(-0.5 * direction, 0.3, 0.2), p4(0.7 * direction, 0.3, 0.2);
		for (double side : {1.0, -1.0}) {
			const dda::EdgeEdgeResult r = dda::edgeEdgeDistance(p1, p2, p3, p4, side * Vector3::UnitZ(), 1e-9);
			EXPECT_TRUE(r.parallel);
			EXPECT_FALSE(r.degenerate);
			EXPECT_FALSE(r.interior);
			ASSERT_TRUE(std::isfinite(r.distance) && finite(r.normal) && finite(r.closestI) && finite(r.closestJ));
			EXPECT_NEAR(r.distance, side * std::hypot(0.3, 0.2), 1e-15);
			EXPECT_NEAR((r.normal - side * Vector3(0, 0.3, 0.2) / std::hypot(0.3, 0.2)).norm(), 0, 1e-15);
			EXPECT_NEAR((r.closestJ - r.closestI).norm(), std::hypot(0.3, 0.2), 1e-15);
		}
	}
}

TEST(ContactEdgeEdge, CollinearAndZeroLengthEdgesGiveFlagsNotNaN) {
	const Vector3 p1(-1, 0, 0), p2(1, 0, 0);
	auto check = [](const dda::EdgeEdgeResult& r) {
		EXPECT_TRUE(r.parallel);
		EXPECT_FALSE(r.interior);
		EXPECT_TRUE(std::isfinite(r.distance) && std::isfinite(r.s) && std::isfinite(r.t));
		EXPECT_TRUE(finite(r.normal) && finite(r.closestI) && finite(r.closestJ));
		EXPECT_NEAR(r.normal.norm(), 1, 1e-15);
	};
	{  // collinear, overlapping: distance 0, normal from the reference
		const dda::EdgeEdgeResult r =
		    dda::edgeEdgeDistance(p1, p2, Vector3(0.5, 0, 0), Vector3(2, 0, 0), Vector3(1, 1, 0), 1e-9);
		check(r);
		EXPECT_FALSE(r.degenerate);
		EXPECT_EQ(r.distance, 0);
		EXPECT_NEAR((r.normal - Vector3::UnitY()).norm(), 0, 1e-15);
		EXPECT_EQ((r.closestJ - r.closestI).norm(), 0);
	}
	{  // collinear, disjoint; reference along the edges: any perpendicular normal
		const dda::EdgeEdgeResult r =
		    dda::edgeEdgeDistance(p1, p2, Vector3(3, 0, 0), Vector3(2, 0, 0), Vector3::UnitX(), 1e-9);
		check(r);
		EXPECT_EQ(r.distance, 0);
		EXPECT_NEAR(r.normal.x(), 0, 1e-15);
		EXPECT_NEAR((r.closestJ - r.closestI).norm(), 1, 1e-15);
	}
	{  // edge j is a point
		const Vector3 q(0.2, 0.5, 0.3);
		const dda::EdgeEdgeResult r = dda::edgeEdgeDistance(p1, p2, q, q, Vector3::UnitZ(), 1e-9);
		check(r);
		EXPECT_TRUE(r.degenerate);
		EXPECT_NEAR(r.distance, std::hypot(0.5, 0.3), 1e-15);
		EXPECT_NEAR(r.s, 0.6, 1e-15);
		EXPECT_NEAR((r.closestI - Vector3(0.2, 0, 0)).norm(), 0, 1e-15);
	}
	{  // edge i is a point
		const Vector3 q(0.2, 0.5, 0.3);
		const dda::EdgeEdgeResult r = dda::edgeEdgeDistance(q, q, p1, p2, -Vector3::UnitZ(), 1e-9);
		check(r);
		EXPECT_TRUE(r.degenerate);
		EXPECT_NEAR(r.distance, std::hypot(0.5, 0.3), 1e-15);
		EXPECT_NEAR(r.t, 0.6, 1e-15);
	}
	{  // both points; then all four coincide; then with a zero reference
		const dda::EdgeEdgeResult a = dda::edgeEdgeDistance(p1, p1, p2, p2, Vector3::UnitX(), 1e-9);
		check(a);
		EXPECT_NEAR(a.distance, 2, 1e-15);
		const dda::EdgeEdgeResult b = dda::edgeEdgeDistance(p1, p1, p1, p1, Vector3::UnitY(), 1e-9);
		check(b);
		EXPECT_EQ(b.distance, 0);
		const dda::EdgeEdgeResult c = dda::edgeEdgeDistance(p1, p1, p1, p1, Vector3::Zero(), 1e-9);
		check(c);
		const dda::EdgeEdgeResult d = dda::edgeEdgeDistance(p1, p2, p1, p2, Vector3::Zero(), 1e-9);
		check(d);
		EXPECT_EQ(d.distance, 0);
	}
}

// ------------------------------------------------------------------ linearisation

// Central finite differences of the exact d_n with respect to the 24 unknowns
// (D_i then D_j). Steps: 1e-5 m for translations, 1e-5 for rotations and
// strains (stencils are ~1 m across, so points move ~1e-5 m): truncation
// ~1e-10 relative (d_n is a ratio of polynomials of degree 3 and 2 in D),
// round-off ~1e-16 x 1e3 m / 1e-5 = 1e-8 absolute at 1 km from the origin.
Eigen::Matrix<double, 24, 1> finiteDifferences(const std::function<double(const Vector12&, const Vector12&)>& f) {
	constexpr double h = 1e-5;
	Eigen::Matrix<double, 24, 1> g;
	for (int k = 0; k < 24; ++k) {
		Vector12 Di = Vector12::Zero(), Dj = Vector12::Zero();
		(k < 12 ? Di(k) : Dj(k - 12)) = h;
		const double plus = f(Di, Dj);
		const double minus = f(-Di, -Dj);
		g(k) = (plus - minus) / (2 * h);
	}
	return g;
}

Eigen::Matrix<double, 24, 1> stacked(const dda::LinearizedDistance& lin) {
	Eigen::Matrix<double, 24, 1> e;
	e << lin.ei, lin.ej;
	return e;
}

double exactOrNaN(const dda::ContactStencil& s, const Vector3& ci, const Vector3& cj, const Vector12& Di,
                  const Vector12& Dj) {
	const auto d = dda::exactNormalDistance(s, ci, cj, Di, Dj);
	return d ? *d : std::nan("");
}

struct Configuration {
	dda::ContactStencil stencil;
	Vector3 ci, cj;
};

// A random vertex-face or edge-edge configuration, ~1 m across, placed by a
// random rigid motion up to `offset` from the origin; `gap` [m] is the normal
// distance (0: vertex on the plane, edges meeting).
Configuration randomConfiguration(std::mt19937& rng, dda::ContactKind kind, double gap, double offset) {
	const Placement place{randomRotation(rng), randomVector(rng, offset)};
	std::uniform_real_distribution<double> u(0.2, 1.0);
	Configuration c;
	if (kind == dda::ContactKind::VertexFace) {
		// Face triangle in z = 0, counter-clockwise seen from +z (outside of
		// block j, whose centroid lies below); vertex at height gap.
		const double below = u(rng);
		const Vector3 f0(-u(rng), -below, 0), f1(u(rng), -below, 0), f2(0.3 * u(rng), u(rng), 0);
		const Vector3 q(0.2 * u(rng), 0.1 * u(rng), gap);
		c.stencil = dda::vertexFaceStencil(place(q), place(f0), place(f1), place(f2));
		c.ci = place(q + Vector3(0.1 * u(rng), -0.2 * u(rng), 0.5 + u(rng)));
		c.cj = place(Vector3(0.1 * u(rng), 0.2 * u(rng), -0.5 - u(rng)));
	} else {
		// Edge i along x in z = 0, edge j at a random angle at height gap.
		const double theta = 0.3 + 2.5 * (u(rng) - 0.2) / 0.8;
		const Vector3 dir(std::cos(theta), std::sin(theta), 0);
		const Vector3 p1(-u(rng), 0, 0), p2(u(rng), 0, 0);
		const Vector3 centre(0.1 * u(rng), 0.1 * u(rng), gap);
		c.stencil = dda::edgeEdgeStencil(place(p1), place(p2), place(centre - u(rng) * dir), place(centre + u(rng) * dir),
		                                 place.R * Vector3::UnitZ());
		c.ci = place(Vector3(0.1 * u(rng), -0.5 - u(rng), -0.5 - u(rng)));
		c.cj = place(Vector3(0.1 * u(rng), 0.5 + u(rng), 0.5 + u(rng) + gap));
	}
	return c;
}

TEST(ContactLinearization, GradientMatchesFiniteDifferencesWhenClosed) {
	std::mt19937 rng(41);
	for (dda::ContactKind kind : {dda::ContactKind::VertexFace, dda::ContactKind::EdgeEdge}) {
		for (int trial = 0; trial < 20; ++trial) {
			const double offset = trial < 10 ? 1.0 : 1e3;
			const Configuration c = randomConfiguration(rng, kind, 0.0, offset);
			const dda::LinearizedDistance lin = dda::linearizeNormalDistance(c.stencil, c.ci, c.cj);
			ASSERT_TRUE(lin.valid);
			EXPECT_NEAR(lin.d0, 0, 1e-12 * offset);
			const auto fd = finiteDifferences(
			    [&](const Vector12& Di, const Vector12& Dj) { return exactOrNaN(c.stencil, c.ci, c.cj, Di, Dj); });
			const auto e = stacked(lin);
			const double scale = e.cwiseAbs().maxCoeff();
			ASSERT_GT(scale, 0.5);
			for (int k = 0; k < 24; ++k) EXPECT_NEAR(e(k), fd(k), 1e-6 * scale) << "unknown " << k << " trial " << trial;
		}
	}
}

TEST(ContactLinearization, FixedAreaDiffersFromExactDerivativeByGapTerm) {
	// For Delta0 != 0: d(d_n) = sigma dDelta/S - d0 dS/S; the linearisation
	// keeps only the first term. Check fd(d_n) - e == -d0 fd(S)/S per unknown,
	// and that the dropped term is really there (not a vacuous check).
	std::mt19937 rng(42);
	for (dda::ContactKind kind : {dda::ContactKind::VertexFace, dda::ContactKind::EdgeEdge}) {
		for (double gap : {0.3, -0.2}) {
			for (int trial = 0; trial < 8; ++trial) {
				const Configuration c = randomConfiguration(rng, kind, gap, trial < 4 ? 1.0 : 1e3);
				const dda::LinearizedDistance lin = dda::linearizeNormalDistance(c.stencil, c.ci, c.cj);
				ASSERT_TRUE(lin.valid);
				EXPECT_NEAR(lin.d0, gap, 1e-11 * (trial < 4 ? 1 : 1e3));
				const auto fd = finiteDifferences(
				    [&](const Vector12& Di, const Vector12& Dj) { return exactOrNaN(c.stencil, c.ci, c.cj, Di, Dj); });
				const auto fdArea = finiteDifferences([&](const Vector12& Di, const Vector12& Dj) {
					return dda::stencilArea(c.stencil.kind, dda::movedStencilPoints(c.stencil, c.ci, c.cj, Di, Dj));
				});
				const auto e = stacked(lin);
				const Eigen::Matrix<double, 24, 1> dropped = -lin.d0 * fdArea / lin.area;
				const double scale = e.cwiseAbs().maxCoeff();
				EXPECT_GT(dropped.cwiseAbs().maxCoeff(), 1e-2 * scale);
				for (int k = 0; k < 24; ++k) {
					EXPECT_NEAR(fd(k) - e(k), dropped(k), 1e-6 * scale) << "unknown " << k;
					// Translations do not change S.
					if (k % 12 < 3) EXPECT_NEAR(dropped(k), 0, 1e-6 * scale);
				}
			}
		}
	}
}

TEST(ContactLinearization, RigidMotionOfBothBlocksLeavesDistanceUnchanged) {
	// Delta is invariant under rigid motions, so e_i.D_i + e_j.D_j = 0 when
	// both blocks translate by t and turn by omega about the same point o:
	// D_b = (t + omega x (c_b - o), omega, 0). Also e translations = +-n.
	std::mt19937 rng(43);
	for (dda::ContactKind kind : {dda::ContactKind::VertexFace, dda::ContactKind::EdgeEdge}) {
		for (double gap : {0.0, 0.4, -0.1}) {
			const Configuration c = randomConfiguration(rng, kind, gap, 10.0);
			const dda::LinearizedDistance lin = dda::linearizeNormalDistance(c.stencil, c.ci, c.cj);
			ASSERT_TRUE(lin.valid);
			EXPECT_NEAR((lin.ei.head<3>() + lin.ej.head<3>()).norm(), 0, 1e-13);
			EXPECT_NEAR(lin.ei.head<3>().norm(), 1, 1e-13);  // d_n moves 1:1 with a translation along n
			for (int k = 0; k < 5; ++k) {
				const Vector3 t = randomVector(rng, 1), omega = randomVector(rng, 1), o = randomVector(rng, 10);
				Vector12 Di = Vector12::Zero(), Dj = Vector12::Zero();
				Di << t + omega.cross(c.ci - o), omega, Eigen::Matrix<double, 6, 1>::Zero();
				Dj << t + omega.cross(c.cj - o), omega, Eigen::Matrix<double, 6, 1>::Zero();
				EXPECT_NEAR(lin.ei.dot(Di) + lin.ej.dot(Dj), 0, 1e-12 * 30);
			}
		}
	}
}

TEST(ContactLinearization, AgreesWithDistanceFunctions) {
	std::vector<Vector3> box;
	for (int k = 0; k < 8; ++k) box.emplace_back(k & 1, (k >> 1) & 1, -double((k >> 2) & 1));
	for (const Placement& place : placements(51, 6, 1e3)) {
		std::vector<Vector3> moved;
		for (const Vector3& x : box) moved.push_back(place(x));
		const dda::ConvexPolyhedron poly = dda::buildConvexPolyhedron(moved);
		const int f = faceAlong(poly, place.R * Vector3::UnitZ());
		const auto corners = dda::chooseFaceCorners(poly.vertices, poly.faces[f]);
		for (const Vector3& q : {Vector3(0.3, 0.6, 0.2), Vector3(0.9, 0.1, -0.05), Vector3(0, 0, 0)}) {
			const Vector3 p = place(q);
			const auto stencil = dda::vertexFaceStencil(p, poly.vertices[corners[0]], poly.vertices[corners[1]],
			                                            poly.vertices[corners[2]]);
			const auto lin = dda::linearizeNormalDistance(stencil, place(Vector3(0.5, 0.5, 1)), place(Vector3(0.5, 0.5, -0.5)));
			const auto r = dda::vertexFaceDistance(p, poly.vertices, poly.faces[f], 1e-9);
			EXPECT_NEAR(lin.d0, r.distance, 1e-10);
			EXPECT_NEAR((lin.ei.head<3>() - r.normal).norm(), 0, 1e-12);
		}
	}
	// Edge-edge, both orientations of the reference.
	std::mt19937 rng(52);
	for (int trial = 0; trial < 20; ++trial) {
		const Vector3 p1 = randomVector(rng, 1), p2 = randomVector(rng, 1);
		const Vector3 p3 = randomVector(rng, 1), p4 = randomVector(rng, 1);
		const Vector3 ref = randomVector(rng, 1);
		const auto r = dda::edgeEdgeDistance(p1, p2, p3, p4, ref, 1e-9);
		ASSERT_FALSE(r.parallel);
		const auto lin = dda::linearizeNormalDistance(dda::edgeEdgeStencil(p1, p2, p3, p4, ref), Vector3::Zero(),
		                                              Vector3::Ones());
		EXPECT_NEAR(lin.d0, r.distance, 1e-13);
		EXPECT_NEAR((lin.ej.head<3>() - r.normal).norm(), 0, 1e-13);  // moving j along n opens the gap
	}
}

TEST(ContactLinearization, DegenerateStencilsAreInvalidNotNaN) {
	const Vector3 ci(0, 0, 1), cj(0, 0, -1);
	// Parallel edges: S = 0.
	auto lin = dda::linearizeNormalDistance(
	    dda::edgeEdgeStencil(Vector3(-1, 0, 0), Vector3(1, 0, 0), Vector3(-1, 0.3, 0.2), Vector3(1, 0.3, 0.2),
	                         Vector3::UnitZ()),
	    ci, cj);
	EXPECT_FALSE(lin.valid);
	EXPECT_EQ(lin.d0, 0);
	EXPECT_TRUE(lin.ei.allFinite() && lin.ej.allFinite());
	// Zero-length edge.
	lin = dda::linearizeNormalDistance(
	    dda::edgeEdgeStencil(Vector3(0, 0, 0), Vector3(0, 0, 0), Vector3(-1, 0.3, 0.2), Vector3(1, 0.3, 0.2),
	                         Vector3::UnitZ()),
	    ci, cj);
	EXPECT_FALSE(lin.valid);
	// Collinear face corners.
	lin = dda::linearizeNormalDistance(
	    dda::vertexFaceStencil(Vector3(0, 0, 1), Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(2, 0, 0)), ci, cj);
	EXPECT_FALSE(lin.valid);
	EXPECT_FALSE(dda::exactNormalDistance(
	                 dda::vertexFaceStencil(Vector3(0, 0, 1), Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(2, 0, 0)),
	                 ci, cj, Vector12::Zero(), Vector12::Zero())
	                 .has_value());
	// Vertex exactly on a corner of the face, and on an edge: closed, finite,
	// and the gradient is still that of the plane (translation part = n).
	for (const Vector3& q : {Vector3(0, 0, 0), Vector3(0.5, 0, 0)}) {
		lin = dda::linearizeNormalDistance(
		    dda::vertexFaceStencil(q, Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(0, 1, 0)), ci, cj);
		EXPECT_TRUE(lin.valid);
		EXPECT_EQ(lin.d0, 0);
		EXPECT_TRUE(lin.ei.allFinite() && lin.ej.allFinite());
		EXPECT_NEAR((lin.ei.head<3>() - Vector3::UnitZ()).norm(), 0, 1e-15);
	}
	// Coplanar crossing edges (closed edge-edge contact): d0 = 0, valid.
	lin = dda::linearizeNormalDistance(
	    dda::edgeEdgeStencil(Vector3(-1, 0, 0), Vector3(1, 0, 0), Vector3(0, -1, 0), Vector3(0, 1, 0), Vector3::UnitZ()),
	    ci, cj);
	EXPECT_TRUE(lin.valid);
	EXPECT_EQ(lin.d0, 0);
	EXPECT_NEAR((lin.ej.head<3>() - Vector3::UnitZ()).norm(), 0, 1e-15);
}

TEST(ContactLinearization, ChooseFaceCornersPicksLargestTriangleInOrder) {
	// A convex hexagon, counter-clockwise, listed from a rotated start; its
	// unique largest triangle is (1, 3, 5) of the original numbering (twice
	// the area 4.2; the runner-up (0, 3, 5) has 4).
	const std::vector<Vector3> v{{2, 0, 0}, {1.2, 0.5, 0}, {0.5, 0.6, 0}, {-2, 0, 0}, {-1, -0.7, 0}, {0, -1, 0}};
	const std::vector<int> face{3, 4, 5, 0, 1, 2};
	double largest = 0;
	for (int a = 0; a < 6; ++a)
		for (int b = 0; b < 6; ++b)
			for (int d = 0; d < 6; ++d) largest = std::max(largest, (v[b] - v[a]).cross(v[d] - v[a]).norm());
	const auto c = dda::chooseFaceCorners(v, face);
	EXPECT_NEAR((v[c[1]] - v[c[0]]).cross(v[c[2]] - v[c[0]]).norm(), largest, 1e-15);
	EXPECT_EQ(c, (std::array<int, 3>{3, 5, 1}));
	EXPECT_GT((v[c[1]] - v[c[0]]).cross(v[c[2]] - v[c[0]]).z(), 0);  // still counter-clockwise
	EXPECT_THROW(dda::chooseFaceCorners(v, {0, 1}), dda::InputError);
	EXPECT_THROW(dda::chooseFaceCorners(v, {0, 1, 9}), dda::InputError);
}

}  // namespace
