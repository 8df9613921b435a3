// Tests of the pair narrow phase (pkg/dda/contact/PairDetection): is the pair
// within the contact distance, its structural type, and its vertex-face and
// edge-edge sub-contacts.
//
// Each of the seven structural types is placed once exactly (shapes with
// exactly representable corners: boxes, octahedra and square prisms standing
// on an edge, touching at a corner, an edge or a face) and once generically
// (slightly apart or penetrating, turned by a random rotation of the whole
// scene). Gaps are compared with closed forms; a box swept towards another
// checks the hit/miss transition at exactly d0 (as libccd's boxbox tests);
// random boxes and tetrahedra near contact check the invariants against a
// brute-force separating-axis twin.
#include "TestScenes.hpp"
#include "dda/contact/Distance.hpp"
#include "dda/contact/Linearization.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/geometry/MassProperties.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"
#include "dda/solver/World.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace {

using dda::ContactKind;
using dda::ContactType;
using dda::DetectionSettings;
using dda::EntranceFeature;
using dda::PairContacts;
using dda::SubContact;
using dda::Vector3;
using Matrix3 = Eigen::Matrix3d;

constexpr double kPi = 3.14159265358979323846;
constexpr double kContactDistance = 1e-3;  // d0 [m] for the unit-sized blocks below
constexpr double kLengthTolerance = 1e-8;  // [m]
constexpr double kRoundoff = 1e-12;        // [m], round-off of unit-sized coordinates

// A block: its topology and current corners, as the narrow phase sees it.
using Block = dda::testing::NarrowBlock;

Block makeBlock(const std::vector<Vector3>& points) { return dda::testing::narrowBlock(points); }

// x -> R x + o applied to every corner.
Block moved(const Block& b, const Matrix3& R, const Vector3& o) {
	std::vector<Vector3> points;
	for (const Vector3& p : b.vertices) points.push_back(R * p + o);
	return makeBlock(points);
}

Block box(const Vector3& lower, const Vector3& upper) {
	std::vector<Vector3> p;
	for (int k = 0; k < 8; ++k)
		p.emplace_back(k & 1 ? upper.x() : lower.x(), k & 2 ? upper.y() : lower.y(), k & 4 ? upper.z() : lower.z());
	return makeBlock(p);
}

// Regular octahedron: corners centre +- r e_k (exact for exact input).
Block octahedron(const Vector3& centre, double r) {
	std::vector<Vector3> p;
	for (int k = 0; k < 3; ++k) {
		p.push_back(centre + r * Vector3::Unit(k));
		p.push_back(centre - r * Vector3::Unit(k));
	}
	return makeBlock(p);
}

// Square prism along x, x in [x0, x1], cross-section the square |y| + |z - zc| <= 1
// standing on an edge: its top edge is (y, z) = (0, zc + 1), its bottom edge
// (0, zc - 1).
Block prismAlongX(double x0, double x1, double zc) {
	std::vector<Vector3> p;
	for (double x : {x0, x1}) {
		p.emplace_back(x, 0, zc + 1);
		p.emplace_back(x, 1, zc);
		p.emplace_back(x, 0, zc - 1);
		p.emplace_back(x, -1, zc);
	}
	return makeBlock(p);
}

// The same prism along y: y in [y0, y1], |x| + |z - zc| <= 1.
Block prismAlongY(double y0, double y1, double zc) {
	std::vector<Vector3> p;
	for (double y : {y0, y1}) {
		p.emplace_back(0, y, zc + 1);
		p.emplace_back(1, y, zc);
		p.emplace_back(0, y, zc - 1);
		p.emplace_back(-1, y, zc);
	}
	return makeBlock(p);
}

Matrix3 rotationAbout(const Vector3& axis, double angle) {
	return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

Matrix3 randomRotation(std::mt19937& rng) {
	std::normal_distribution<double> normal(0.0, 1.0);
	Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
	q.normalize();
	return q.toRotationMatrix();
}

DetectionSettings settings(double d0 = kContactDistance) {
	DetectionSettings s;
	s.contactDistance = d0;
	s.lengthTolerance = kLengthTolerance;
	s.hysteresis = std::max(0.1 * d0, kLengthTolerance);
	return s;
}

std::optional<PairContacts> detect(const Block& a, const Block& b, const DetectionSettings& s = settings(),
                                   const EntranceFeature& previous = {}) {
	return dda::detectPairContacts(a.geometry(), b.geometry(), s, previous);
}

int countKind(const PairContacts& r, ContactKind kind) {
	return static_cast<int>(std::count_if(r.contacts.begin(), r.contacts.end(),
	                                       [&](const SubContact& c) { return c.kind == kind; }));
}

std::string describe(const PairContacts& r) {
	std::string s = std::string(dda::contactTypeName(r.type)) + " entrance " + std::to_string(r.entrance.kind) + "/" +
	                std::to_string(r.entrance.feature) + "/" + std::to_string(r.entrance.other) + " sep " +
	                std::to_string(r.separation) + " contacts:";
	for (const SubContact& c : r.contacts)
		s += std::string(c.kind == ContactKind::VertexFace ? " VF" : " EE") + (c.firstIsA ? "(A" : "(B") +
		     std::to_string(c.feature1) + "," + std::to_string(c.feature2) + " gap " + std::to_string(c.gap) + ")";
	return s;
}

// Invariants of every result: finite, gaps within d0, each gap the linearised
// d0 of its stencil and normal . (pointI - pointJ), stencil points the corners
// of the named features, vertex-face normals the face's outward normal and
// gaps its plane distance, edge-edge gaps the distance of the edges' lines.
void checkInvariants(const PairContacts& r, const Block& a, const Block& b, const DetectionSettings& s) {
	SCOPED_TRACE(describe(r));
	EXPECT_TRUE(std::isfinite(r.separation));
	EXPECT_TRUE(r.normal.allFinite());
	EXPECT_NEAR(r.normal.norm(), 1, 1e-12);
	EXPECT_LE(r.separation, s.contactDistance);
	for (const SubContact& c : r.contacts) {
		const Block& bi = c.firstIsA ? a : b;
		const Block& bj = c.firstIsA ? b : a;
		EXPECT_TRUE(std::isfinite(c.gap));
		EXPECT_TRUE(c.normal.allFinite() && c.pointI.allFinite() && c.pointJ.allFinite());
		EXPECT_NEAR(c.normal.norm(), 1, 1e-12);
		EXPECT_LE(c.gap, s.contactDistance + s.lengthTolerance);
		// The one sub-contact whose stencil is of the other kind: two edges
		// parallel within the angle tolerance that overlap with no other
		// contact, keyed as their edge-edge contact, measured as the point of
		// edge 1 deepest inside block j against that point's own entrance face
		// (ParallelEdges.cpp, nearParallelEdgeContact).
		const bool nearParallel = c.kind == ContactKind::EdgeEdge && c.stencil.kind == ContactKind::VertexFace;
		if (!nearParallel) EXPECT_EQ(c.kind, c.stencil.kind);
		const dda::LinearizedDistance lin = dda::linearizeNormalDistance(c.stencil, bi.centroid, bj.centroid);
		EXPECT_TRUE(lin.valid);
		EXPECT_NEAR(c.gap, lin.d0, 1e-12 * std::max(1.0, std::abs(lin.d0)));
		EXPECT_NEAR(c.gap, c.normal.dot(c.pointI - c.pointJ), kRoundoff);
		if (nearParallel) {
			const auto& e1 = bi.shape.edges.at(c.feature1);
			const Vector3 p0 = bi.vertices[e1[0]], p1 = bi.vertices[e1[1]];
			const double t = (c.pointI - p0).dot(p1 - p0) / (p1 - p0).squaredNorm();
			EXPECT_TRUE(t >= 0 && t <= 1);
			EXPECT_NEAR((p0 + t * (p1 - p0) - c.pointI).norm(), 0, kRoundoff);  // on edge 1
			EXPECT_EQ(c.stencil.points[0], c.pointI);
			EXPECT_LT(c.gap, -s.lengthTolerance);  // only ever penetrating
			bool onAFace = false;
			for (const std::vector<int>& face : bj.shape.faces) {
				bool all = true;
				for (int k = 1; k < 4; ++k)
					all = all && std::any_of(face.begin(), face.end(),
					                         [&](int v) { return bj.vertices[v] == c.stencil.points[k]; });
				if (!all) continue;
				onAFace = true;
				const dda::VertexFaceResult vf = dda::vertexFaceDistance(c.pointI, bj.vertices, face, 0.0);
				EXPECT_NEAR((vf.normal - c.normal).norm(), 0, 1e-9);
				EXPECT_NEAR(c.gap, vf.distance, 1e-9);
			}
			EXPECT_TRUE(onAFace);
		} else if (c.kind == ContactKind::VertexFace) {
			const std::vector<int>& face = bj.shape.faces.at(c.feature2);
			EXPECT_EQ(c.stencil.points[0], bi.vertices.at(c.feature1));
			EXPECT_EQ(c.pointI, bi.vertices.at(c.feature1));
			for (int k = 1; k < 4; ++k) {
				EXPECT_TRUE(std::any_of(face.begin(), face.end(),
				                        [&](int v) { return bj.vertices[v] == c.stencil.points[k]; }));
			}
			const dda::VertexFaceResult vf = dda::vertexFaceDistance(c.pointI, bj.vertices, face, 0.0);
			EXPECT_NEAR((vf.normal - c.normal).norm(), 0, 1e-9);
			EXPECT_NEAR(c.gap, vf.distance, 1e-9);
		} else {
			const auto& e1 = bi.shape.edges.at(c.feature1);
			const auto& e2 = bj.shape.edges.at(c.feature2);
			EXPECT_EQ(c.stencil.points[0], bi.vertices[e1[0]]);
			EXPECT_EQ(c.stencil.points[1], bi.vertices[e1[1]]);
			EXPECT_EQ(c.stencil.points[2], bj.vertices[e2[0]]);
			EXPECT_EQ(c.stencil.points[3], bj.vertices[e2[1]]);
			const dda::EdgeEdgeResult ee =
			    dda::edgeEdgeDistance(c.stencil.points[0], c.stencil.points[1], c.stencil.points[2],
			                          c.stencil.points[3], -c.normal, s.lengthTolerance);
			EXPECT_FALSE(ee.parallel);
			EXPECT_TRUE(ee.interior);
			EXPECT_NEAR(c.gap, ee.distance, kRoundoff);
			EXPECT_NEAR((c.pointI - ee.closestI).norm(), 0, kRoundoff);
			EXPECT_NEAR((c.pointJ - ee.closestJ).norm(), 0, kRoundoff);
		}
	}
}

// Detects, checks the invariants and the expected type; returns the result.
PairContacts expectContact(const Block& a, const Block& b, ContactType type, const DetectionSettings& s = settings()) {
	const std::optional<PairContacts> r = detect(a, b, s);
	if (!r) {
		ADD_FAILURE() << "expected a " << dda::contactTypeName(type) << " contact, got none";
		return {};
	}
	SCOPED_TRACE(describe(*r));
	checkInvariants(*r, a, b, s);
	EXPECT_STREQ(dda::contactTypeName(r->type), dda::contactTypeName(type));
	EXPECT_FALSE(r->contacts.empty());
	return *r;
}

// The whole scene turned by a random rotation and moved: a generic placement.
struct Scene {
	Matrix3 R = Matrix3::Identity();
	Vector3 o = Vector3::Zero();
};
std::vector<Scene> genericScenes(unsigned seed, int count) {
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> u(-3, 3);
	std::vector<Scene> out;
	for (int k = 0; k < count; ++k) out.push_back({randomRotation(rng), Vector3(u(rng), u(rng), u(rng))});
	return out;
}

// ------------------------------------------------------------------ names

TEST(ContactDetection, TypeNames) {
	EXPECT_STREQ(dda::contactTypeName(ContactType::VertexVertex), "VV");
	EXPECT_STREQ(dda::contactTypeName(ContactType::VertexEdge), "VE");
	EXPECT_STREQ(dda::contactTypeName(ContactType::VertexFace), "VF");
	EXPECT_STREQ(dda::contactTypeName(ContactType::EdgeEdgeCrossing), "EE");
	EXPECT_STREQ(dda::contactTypeName(ContactType::EdgeEdgeParallel), "EEp");
	EXPECT_STREQ(dda::contactTypeName(ContactType::EdgeFace), "EF");
	EXPECT_STREQ(dda::contactTypeName(ContactType::FaceFace), "FF");
}

// ------------------------------------------------------------------ vertex-vertex

TEST(ContactDetection, VertexVertexExactOctahedraCornerOnCorner) {
	const Block a = octahedron(Vector3(0, 0, 0), 1);
	const Block b = octahedron(Vector3(0, 0, 2), 1);  // bottom corner exactly on a's top corner
	const PairContacts r = expectContact(a, b, ContactType::VertexVertex);
	EXPECT_EQ(r.separation, 0);
	for (const SubContact& c : r.contacts) {
		EXPECT_EQ(c.gap, 0);
		EXPECT_EQ(c.pointI, Vector3(0, 0, 1));
	}
}

TEST(ContactDetection, VertexVertexExactCubesCornerOnCorner) {
	const Block a = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const Block b = box(Vector3(1, 1, 1), Vector3(2, 2, 2));
	const PairContacts r = expectContact(a, b, ContactType::VertexVertex);
	ASSERT_EQ(r.contacts.size(), 1u);  // the coincident corner gives no second contact
	EXPECT_EQ(r.contacts[0].gap, 0);
	EXPECT_EQ(r.contacts[0].pointI, Vector3(1, 1, 1));
	EXPECT_EQ(countKind(r, ContactKind::EdgeEdge), 0);  // collinear edges and crossings at corners: none
}

TEST(ContactDetection, VertexVertexGenericApartAndPenetrating) {
	const Block a = octahedron(Vector3(0, 0, 0), 1);
	// b's bottom corner at the origin, turned by 0.3 rad about a tilted axis.
	const Block b0 = moved(octahedron(Vector3(0, 0, 1), 1), rotationAbout(Vector3(1, 2, 0.5), 0.3), Vector3::Zero());
	for (double h : {4e-4, -2e-4}) {
		for (const Scene& scene : genericScenes(21, 5)) {
			const Block sa = moved(a, scene.R, scene.o);
			const Block sb = moved(b0, scene.R, scene.R * Vector3(0.5e-4, -0.3e-4, 1 + h) + scene.o);
			SCOPED_TRACE("h " + std::to_string(h));
			const PairContacts r = expectContact(sa, sb, ContactType::VertexVertex);
			// Apart: every gap positive. Penetrating: b's corner is inside a (a's
			// corner may still be outside b's turned faces).
			const auto negative = [](const SubContact& c) { return c.gap < 0; };
			if (h > 0) EXPECT_TRUE(std::none_of(r.contacts.begin(), r.contacts.end(), negative));
			else EXPECT_TRUE(std::any_of(r.contacts.begin(), r.contacts.end(), negative));
		}
	}
}

// ------------------------------------------------------------------ vertex-edge

TEST(ContactDetection, VertexEdgeExactCornerOnEdge) {
	const Block a = prismAlongX(-1, 1, 0);             // top edge (x, 0, 1)
	const Block b = octahedron(Vector3(0.25, 0, 2), 1);  // bottom corner (0.25, 0, 1)
	const PairContacts r = expectContact(a, b, ContactType::VertexEdge);
	for (const SubContact& c : r.contacts) {
		EXPECT_EQ(c.gap, 0);
		EXPECT_NEAR((c.pointI - Vector3(0.25, 0, 1)).norm(), 0, kRoundoff);
	}
}

TEST(ContactDetection, VertexEdgeGenericCornerNearMiddleOfEdge) {
	// b: a cube standing on a corner (body diagonal vertical), that corner near
	// the middle of the top edge y = z = 0.5 of the box a.
	const Block a = box(Vector3(-0.5, -0.5, -0.5), Vector3(0.5, 0.5, 0.5));
	const Matrix3 tilt = Eigen::Quaterniond::FromTwoVectors(Vector3(1, 1, 1), Vector3(0, 0, 1)).toRotationMatrix();
	const Block cube = moved(box(Vector3(0, 0, 0), Vector3(0.6, 0.6, 0.6)), rotationAbout(Vector3::UnitZ(), 0.4) * tilt,
	                         Vector3::Zero());  // corner 0 at the origin, the lowest
	for (const Vector3& offset : {Vector3(0.1, 0.5 + 2e-4, 0.5 + 3e-4), Vector3(-0.2, 0.5 - 1e-4, 0.5 - 2e-4)}) {
		for (const Scene& scene : genericScenes(31, 5)) {
			const PairContacts r =
			    expectContact(moved(a, scene.R, scene.o), moved(cube, scene.R, scene.R * offset + scene.o),
			                  ContactType::VertexEdge);
			for (const SubContact& c : r.contacts) EXPECT_EQ(c.gap < 0, offset.z() < 0.5);
		}
	}
}

// ------------------------------------------------------------------ vertex-face

TEST(ContactDetection, VertexFaceExactCornerOnFace) {
	const Block a = box(Vector3(-2, -2, -1), Vector3(2, 2, 0));
	const Block b = octahedron(Vector3(0.3, -0.7, 1), 1);  // bottom corner (0.3, -0.7, 0)
	const PairContacts r = expectContact(a, b, ContactType::VertexFace);
	ASSERT_EQ(r.contacts.size(), 1u);
	const SubContact& c = r.contacts[0];
	EXPECT_EQ(c.kind, ContactKind::VertexFace);
	EXPECT_FALSE(c.firstIsA);  // b's corner on a's face
	EXPECT_EQ(c.gap, 0);
	EXPECT_EQ(c.pointI, Vector3(0.3, -0.7, 0));
	EXPECT_EQ(c.normal, Vector3(0, 0, 1));
}

TEST(ContactDetection, VertexFaceGenericTiltedCube) {
	const Block a = box(Vector3(-2, -2, -1), Vector3(2, 2, 0));
	const Matrix3 tilt = Eigen::Quaterniond::FromTwoVectors(Vector3(1, 1, 1), Vector3(0, 0, 1)).toRotationMatrix();
	const Block cube = moved(box(Vector3(0, 0, 0), Vector3(1, 1, 1)), rotationAbout(Vector3::UnitZ(), 1.1) * tilt,
	                         Vector3::Zero());
	for (double h : {7e-4, 0.0, -5e-4}) {
		for (const Scene& scene : genericScenes(41, 5)) {
			const PairContacts r =
			    expectContact(moved(a, scene.R, scene.o), moved(cube, scene.R, scene.R * Vector3(0.2, 0.4, h) + scene.o),
			                  ContactType::VertexFace);
			ASSERT_EQ(r.contacts.size(), 1u);
			EXPECT_NEAR(r.contacts[0].gap, h, kRoundoff * 10);
		}
	}
}

// ------------------------------------------------------------------ edge-edge

TEST(ContactDetection, EdgeEdgeCrossingExact) {
	const Block a = prismAlongX(-1, 1, 0);  // top edge (x, 0, 1)
	const Block b = prismAlongY(-1, 1, 2);  // bottom edge (0, y, 1)
	const PairContacts r = expectContact(a, b, ContactType::EdgeEdgeCrossing);
	EXPECT_EQ(r.entrance.kind, EntranceFeature::EdgePair);
	ASSERT_EQ(r.contacts.size(), 1u);
	const SubContact& c = r.contacts[0];
	EXPECT_EQ(c.kind, ContactKind::EdgeEdge);
	EXPECT_EQ(c.gap, 0);
	EXPECT_EQ(c.pointI, Vector3(0, 0, 1));
	EXPECT_EQ(c.pointJ, Vector3(0, 0, 1));
}

TEST(ContactDetection, EdgeEdgeCrossingGenericAtAnAngle) {
	const Block a = prismAlongX(-1, 1, 0);
	const Block b0 = moved(prismAlongY(-1, 1, 2), rotationAbout(Vector3::UnitZ(), 0.5), Vector3(0.2, 0.1, 0));
	for (double h : {6e-4, -3e-4}) {
		for (const Scene& scene : genericScenes(51, 5)) {
			const Block sa = moved(a, scene.R, scene.o);
			const Block sb = moved(b0, scene.R, scene.R * Vector3(0, 0, h) + scene.o);
			const PairContacts r = expectContact(sa, sb, ContactType::EdgeEdgeCrossing);
			EXPECT_EQ(r.entrance.kind, EntranceFeature::EdgePair);
			ASSERT_EQ(r.contacts.size(), 1u);
			EXPECT_EQ(r.contacts[0].kind, ContactKind::EdgeEdge);
			EXPECT_NEAR(r.contacts[0].gap, h, 1e-11);  // both edges horizontal: the line distance is h
			EXPECT_NEAR(r.separation, h, 1e-11);
			// The normal pushes block i (a) down, away from b.
			EXPECT_TRUE(r.contacts[0].firstIsA);
			EXPECT_NEAR((r.contacts[0].normal - scene.R * Vector3(0, 0, -1)).norm(), 0, 1e-12);
		}
	}
}

TEST(ContactDetection, EdgeEdgeParallelExactEdgeOnEdge) {
	const Block a = prismAlongX(-1, 1, 0);       // top edge x in [-1, 1]
	const Block b = prismAlongX(-0.5, 1.5, 2);   // bottom edge x in [-0.5, 1.5], on a's top edge
	const PairContacts r = expectContact(a, b, ContactType::EdgeEdgeParallel);
	EXPECT_EQ(countKind(r, ContactKind::EdgeEdge), 0);
	EXPECT_EQ(r.contacts.size(), 2u);  // b's corner (-0.5, 0, 1) and a's corner (1, 0, 1)
	for (const SubContact& c : r.contacts) EXPECT_EQ(c.gap, 0);
}

TEST(ContactDetection, EdgeEdgeParallelGeneric) {
	const Block a = prismAlongX(-1, 1, 0);
	const Block b0 = prismAlongX(-0.5, 1.5, 2);
	for (double h : {8e-4, -4e-4}) {
		for (const Scene& scene : genericScenes(61, 5)) {
			const PairContacts r =
			    expectContact(moved(a, scene.R, scene.o), moved(b0, scene.R, scene.R * Vector3(0, 0, h) + scene.o),
			                  ContactType::EdgeEdgeParallel);
			// The two corners at the ends of the overlap, against the faces at
			// 45 degrees: gap h / sqrt(2). Penetrating, b's end edges also dip
			// below a's top edge: short edge-edge contacts, never between the
			// parallel edges (checked with the invariants).
			EXPECT_EQ(countKind(r, ContactKind::VertexFace), 2);
			if (h > 0) EXPECT_EQ(countKind(r, ContactKind::EdgeEdge), 0);
			for (const SubContact& c : r.contacts) {
				if (c.kind == ContactKind::VertexFace) EXPECT_NEAR(c.gap, h / std::sqrt(2.0), 1e-11);
				else EXPECT_TRUE(c.gap < 0 && c.gap >= h);
			}
		}
	}
}

// Two ridges crossing at a small angle, below the angle tolerance: a's top
// edge (x, 0, 1), x in [-1, 1], and b's bottom edge, 1 long, turned by theta
// about z and lowered by delta, crossing a's at (0, 0, 1 - delta). With
// theta x 0.5 > |delta| the ends of either edge lie outside the other
// block (b's ends 5 mm aside of a's ridge for theta = 0.01), so no corner
// contact can stand for the overlap, and near-parallel edges give no
// crossing. Closed form: the deepest point of either ridge inside the other
// prism is the crossing, delta below the other ridge, at delta / sqrt(2)
// from both faces at 45 degrees; the pair's penetration depth is delta
// (along z, the edges' common normal). The pair must have a contact of gap
// -delta / sqrt(2) (no deeper than the penetration), and none negative when
// apart. Before nearParallelEdgeContact its lowest gap was positive while
// the prisms overlapped (the coverage oracle's convex pile, seed 6).
TEST(ContactDetection, NearParallelEdgesCrossingInsideHaveAContactAsDeepAsTheirOverlap) {
	const Block a = prismAlongX(-1, 1, 0);
	const Block b0 = prismAlongX(-0.5, 0.5, 2);
	DetectionSettings s = settings(1e-3);
	s.angleTolerance = 0.05;  // World's largest (pairDetectionSettings)
	for (const double theta : {0.01, 0.03})
		for (const double delta : {-5e-4, 1e-4, 1e-3, 3e-3})
			for (const Scene& scene : genericScenes(67, 4)) {
				SCOPED_TRACE("theta " + std::to_string(theta) + ", delta " + std::to_string(delta));
				const Matrix3 turn = rotationAbout(Vector3::UnitZ(), theta);
				const Block b = moved(b0, scene.R * turn, scene.R * Vector3(0, 0, -delta) + scene.o);
				const Block aMoved = moved(a, scene.R, scene.o);
				const std::optional<PairContacts> r = detect(aMoved, b, s);
				ASSERT_TRUE(r.has_value());
				SCOPED_TRACE(describe(*r));
				checkInvariants(*r, aMoved, b, s);
				double lowest = std::numeric_limits<double>::infinity();
				for (const SubContact& c : r->contacts) lowest = std::min(lowest, c.gap);
				if (delta < 0) {
					EXPECT_GE(lowest, -s.lengthTolerance);
					continue;
				}
				ASSERT_FALSE(r->contacts.empty());
				EXPECT_NEAR(lowest, -delta / std::sqrt(2.0), 1e-9);
				EXPECT_GE(lowest, -delta - s.lengthTolerance);
				// It is the edge pair's: a's ridge and b's.
				const auto ridges = std::find_if(r->contacts.begin(), r->contacts.end(), [&](const SubContact& c) {
					return c.kind == ContactKind::EdgeEdge && std::abs(c.gap - lowest) < 1e-12;
				});
				ASSERT_NE(ridges, r->contacts.end());
				EXPECT_EQ(ridges->stencil.kind, ContactKind::VertexFace);
			}
}

// The same crossing ridges (theta = 0.01, delta = 1e-3): the depth of a
// point of a ridge inside the other prism falls linearly from delta / sqrt(2)
// at the crossing to half that at |x| theta = delta / 2 along it. The pair's
// near-parallel contact of the last step (keptEdgePoint) keeps its point, a
// material point of its edge, while that point lies at least half as deep as
// the crossing: at 0.3 delta / theta from the crossing its gap is -0.7 delta
// / sqrt(2); at 0.6 delta / theta the crossing's point is taken. And a pair
// overlapping by less than lengthTolerance has the contact only when it had
// it (made at the tolerance, kept while it overlaps): a contact made and
// dropped at one threshold came back compressed every other step in a
// jointed mass at rest.
TEST(ContactDetection, NearParallelEdgeContactKeepsItsPointWhileHalfAsDeep) {
	const Block a = prismAlongX(-1, 1, 0);
	const Block b0 = prismAlongX(-0.5, 0.5, 2);
	const double theta = 0.01;
	for (const Scene& scene : genericScenes(71, 3)) {
		const Block aMoved = moved(a, scene.R, scene.o);
		const auto place = [&](double delta) {
			return moved(b0, scene.R * rotationAbout(Vector3::UnitZ(), theta), scene.R * Vector3(0, 0, -delta) + scene.o);
		};
		const auto nearParallel = [](const PairContacts& r) {
			return std::find_if(r.contacts.begin(), r.contacts.end(), [](const SubContact& c) {
				return c.kind == ContactKind::EdgeEdge && c.stencil.kind == ContactKind::VertexFace;
			});
		};
		DetectionSettings s = settings(1e-3);
		s.angleTolerance = 0.05;
		const double delta = 1e-3;
		const Block b = place(delta);
		const std::optional<PairContacts> first = detect(aMoved, b, s);
		ASSERT_TRUE(first.has_value());
		const auto c0 = nearParallel(*first);
		ASSERT_NE(c0, first->contacts.end()) << describe(*first);
		ASSERT_NEAR(c0->gap, -delta / std::sqrt(2.0), 1e-9);
		// The edge the point lies on, through the crossing.
		const Block& owner = c0->firstIsA ? aMoved : b;
		const std::array<int, 2> ends = owner.shape.edges[c0->feature1];
		const Vector3 along = (owner.vertices[ends[1]] - owner.vertices[ends[0]]).normalized();
		for (const double share : {0.3, 0.6}) {
			SCOPED_TRACE("kept point at " + std::to_string(share) + " delta / theta");
			s.keptEdgePoint = {c0->firstIsA, c0->feature1, c0->feature2, c0->pointI + share * delta / theta * along};
			const std::optional<PairContacts> r = detect(aMoved, b, s);
			ASSERT_TRUE(r.has_value());
			checkInvariants(*r, aMoved, b, s);
			const auto c = nearParallel(*r);
			ASSERT_NE(c, r->contacts.end()) << describe(*r);
			if (share < 0.5) {
				EXPECT_LT((c->pointI - s.keptEdgePoint.point).norm(), 1e-9);
				EXPECT_NEAR(c->gap, -(1 - share) * delta / std::sqrt(2.0), 1e-8);
			} else {
				EXPECT_LT((c->pointI - c0->pointI).norm(), 1e-9);
				EXPECT_NEAR(c->gap, -delta / std::sqrt(2.0), 1e-9);
			}
		}
		// Overlapping by half the tolerance: none made, one kept.
		const double shallow = 0.5 * s.lengthTolerance;
		const Block c = place(shallow);
		s.keptEdgePoint = {};
		const std::optional<PairContacts> fresh = detect(aMoved, c, s);
		ASSERT_TRUE(fresh.has_value());
		EXPECT_EQ(nearParallel(*fresh), fresh->contacts.end()) << describe(*fresh);
		s.keptEdgePoint = {c0->firstIsA, c0->feature1, c0->feature2, c0->pointI};
		const std::optional<PairContacts> kept = detect(aMoved, c, s);
		ASSERT_TRUE(kept.has_value());
		const auto k = nearParallel(*kept);
		ASSERT_NE(k, kept->contacts.end()) << describe(*kept);
		EXPECT_LT(k->gap, 0);
		EXPECT_GE(k->gap, -shallow - s.lengthTolerance);
	}
}

// ------------------------------------------------------------------ edge-face

TEST(ContactDetection, EdgeFaceExactPrismOnFloor) {
	const Block a = box(Vector3(-2, -2, -1), Vector3(2, 2, 0));
	const Block b = prismAlongX(-1, 1, 1);  // bottom edge (x, 0, 0)
	const PairContacts r = expectContact(a, b, ContactType::EdgeFace);
	EXPECT_EQ(r.entrance.kind, EntranceFeature::FaceOfA);
	ASSERT_EQ(r.contacts.size(), 2u);
	for (const SubContact& c : r.contacts) {
		EXPECT_EQ(c.gap, 0);
		EXPECT_FALSE(c.firstIsA);
	}
}

TEST(ContactDetection, EdgeFaceGenericTiltedPrism) {
	const Block a = box(Vector3(-2, -2, -1), Vector3(2, 2, 0));
	// Prism along x turned about z and rocked slightly about its bottom edge.
	const Matrix3 turn = rotationAbout(Vector3::UnitZ(), 0.7) * rotationAbout(Vector3::UnitX(), 0.2);
	const Block b0 = moved(prismAlongX(-1, 1, 1), turn, Vector3(0.3, 0.2, 0));
	for (double h : {5e-4, -5e-4}) {
		for (const Scene& scene : genericScenes(71, 5)) {
			const PairContacts r =
			    expectContact(moved(a, scene.R, scene.o), moved(b0, scene.R, scene.R * Vector3(0, 0, h) + scene.o),
			                  ContactType::EdgeFace);
			ASSERT_EQ(r.contacts.size(), 2u);
			for (const SubContact& c : r.contacts) EXPECT_NEAR(c.gap, h, 1e-11);
		}
	}
}

// ------------------------------------------------------------------ face-face

TEST(ContactDetection, FaceFaceExactIdenticalCubesStacked) {
	const Block a = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const Block b = box(Vector3(0, 0, 1), Vector3(1, 1, 2));
	const PairContacts r = expectContact(a, b, ContactType::FaceFace);
	EXPECT_EQ(r.entrance.kind, EntranceFeature::FaceOfA);  // tie: A before B
	EXPECT_EQ(r.normal, Vector3(0, 0, 1));
	ASSERT_EQ(r.contacts.size(), 4u);  // b's 4 bottom corners; a's coincident corners give none
	for (const SubContact& c : r.contacts) {
		EXPECT_EQ(c.kind, ContactKind::VertexFace);
		EXPECT_FALSE(c.firstIsA);
		EXPECT_EQ(c.gap, 0);
	}
}

TEST(ContactDetection, FaceFaceExactCoplanarOffsetFaces) {
	const Block a = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const Block b = box(Vector3(0.5, 0.25, 1), Vector3(1.5, 1.25, 2));
	const PairContacts r = expectContact(a, b, ContactType::FaceFace);
	EXPECT_EQ(r.contacts.size(), 4u);
	EXPECT_EQ(countKind(r, ContactKind::EdgeEdge), 2);  // b's edges cross a's top edges at 2 points
	EXPECT_EQ(countKind(r, ContactKind::VertexFace), 2);  // 1 corner of b inside a's top face, 1 of a's inside b's bottom
	for (const SubContact& c : r.contacts) EXPECT_EQ(c.gap, 0);
}

TEST(ContactDetection, FaceFaceGenericTurnedCube) {
	const Block a = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const Block b0 = moved(box(Vector3(-0.3, -0.3, 0), Vector3(0.3, 0.3, 0.6)), rotationAbout(Vector3::UnitZ(), 0.35),
	                       Vector3(0.55, 0.45, 1));
	for (double h : {6e-4, -2e-4}) {
		for (const Scene& scene : genericScenes(81, 5)) {
			const PairContacts r =
			    expectContact(moved(a, scene.R, scene.o), moved(b0, scene.R, scene.R * Vector3(0, 0, h) + scene.o),
			                  ContactType::FaceFace);
			ASSERT_EQ(r.contacts.size(), 4u);
			for (const SubContact& c : r.contacts) EXPECT_NEAR(c.gap, h, 1e-11);
		}
	}
}

// A cube turned 45 degrees about z on an identical cube: the two squares cross
// at the 8 corners of an octagon, each an edge-edge contact; no corner lies
// over the other square, so no vertex-face contacts.
TEST(ContactDetection, TurnedCubeOnCubeGivesEightEdgeEdgeContactsAtOctagonCorners) {
	const Block a = box(Vector3(-0.5, -0.5, -1), Vector3(0.5, 0.5, 0));
	const Matrix3 R = rotationAbout(Vector3::UnitZ(), kPi / 4);
	const double c = std::sqrt(0.5) - 0.5;  // octagon corners at (+-0.5, +-c), (+-c, +-0.5)
	for (double h : {3e-4, 0.0, -3e-4}) {
		const Block b = moved(box(Vector3(-0.5, -0.5, 0), Vector3(0.5, 0.5, 1)), R, Vector3(0, 0, h));
		SCOPED_TRACE("h " + std::to_string(h));
		const PairContacts r = expectContact(a, b, ContactType::FaceFace);
		ASSERT_EQ(r.contacts.size(), 8u);
		EXPECT_EQ(countKind(r, ContactKind::EdgeEdge), 8);
		for (const SubContact& s : r.contacts) {
			EXPECT_NEAR(s.gap, h, kRoundoff);
			const Vector3& p = s.firstIsA ? s.pointI : s.pointJ;  // on a's top edges
			const bool onX = std::abs(std::abs(p.x()) - 0.5) < 1e-12 && std::abs(std::abs(p.y()) - c) < 1e-12;
			const bool onY = std::abs(std::abs(p.y()) - 0.5) < 1e-12 && std::abs(std::abs(p.x()) - c) < 1e-12;
			EXPECT_TRUE(onX || onY) << p.transpose();
			EXPECT_NEAR(p.z(), 0, 1e-15);
		}
	}
}

TEST(ContactDetection, SmallCubeOnFloorGivesFourVertexFaceContactsOnFloorTop) {
	const Block floor = box(Vector3(-5, -5, -1), Vector3(5, 5, 0));
	for (double h : {5e-4, 0.0, -5e-4}) {
		const Block cube = moved(box(Vector3(-0.5, -0.5, 0), Vector3(0.5, 0.5, 1)), rotationAbout(Vector3::UnitZ(), 0.3),
		                         Vector3(1, 2, h));
		SCOPED_TRACE("h " + std::to_string(h));
		for (bool floorFirst : {true, false}) {
			const Block& a = floorFirst ? floor : cube;
			const Block& b = floorFirst ? cube : floor;
			const PairContacts r = expectContact(a, b, ContactType::FaceFace);
			EXPECT_EQ(r.entrance.kind, floorFirst ? EntranceFeature::FaceOfA : EntranceFeature::FaceOfB);
			ASSERT_EQ(r.contacts.size(), 4u);
			for (const SubContact& c : r.contacts) {
				EXPECT_EQ(c.kind, ContactKind::VertexFace);
				EXPECT_EQ(c.firstIsA, !floorFirst);  // the cube's corners
				EXPECT_EQ(c.feature2, r.entrance.feature);
				EXPECT_EQ(c.normal, Vector3(0, 0, 1));
				EXPECT_NEAR(c.gap, h, 1e-15);
				EXPECT_NEAR(c.pointI.z(), h, 1e-15);
			}
		}
	}
}

// ------------------------------------------------------------------ zero contact distance

// Exact placements are touching, not apart, with d0 = 0: the sign of a corner
// exactly on a plane (or of two exactly intersecting edges) is decided exactly.
TEST(ContactDetection, ExactPlacementsAreFoundWithZeroContactDistance) {
	const DetectionSettings s = settings(0.0);
	const Block floor = box(Vector3(-2, -2, -1), Vector3(2, 2, 0));
	const Block px = prismAlongX(-1, 1, 0);
	struct Case {
		Block a, b;
		ContactType type;
	};
	const std::vector<Case> cases{
	    {octahedron(Vector3(0, 0, 0), 1), octahedron(Vector3(0, 0, 2), 1), ContactType::VertexVertex},
	    {px, octahedron(Vector3(0.25, 0, 2), 1), ContactType::VertexEdge},
	    {floor, octahedron(Vector3(0.3, -0.7, 1), 1), ContactType::VertexFace},
	    {px, prismAlongY(-1, 1, 2), ContactType::EdgeEdgeCrossing},
	    {px, prismAlongX(-0.5, 1.5, 2), ContactType::EdgeEdgeParallel},
	    {floor, prismAlongX(-1, 1, 1), ContactType::EdgeFace},
	    {box(Vector3(0, 0, 0), Vector3(1, 1, 1)), box(Vector3(0, 0, 1), Vector3(1, 1, 2)), ContactType::FaceFace},
	};
	for (const Case& c : cases) {
		SCOPED_TRACE(dda::contactTypeName(c.type));
		const PairContacts r = expectContact(c.a, c.b, c.type, s);
		EXPECT_EQ(r.separation, 0);
		for (const SubContact& sub : r.contacts) EXPECT_EQ(sub.gap, 0);
	}
}

// A corner exactly on a slanted face (x/2 + y/3 + z/5 = 1, every value an
// exact binary fraction): the double distance from the face plane is round-off
// of either sign, the exact predicate makes it 0, so the pair touches.
TEST(ContactDetection, CornerExactlyOnSlantedFaceTouchesWithZeroContactDistance) {
	const DetectionSettings s = settings(0.0);
	const Block a = makeBlock({{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 5}});
	const Vector3 out(1.5, 1, 0.6);  // along the face's outward normal (15, 10, 6)
	for (const Vector3& p : {Vector3(0.5, 0.75, 2.5), Vector3(1, 0.75, 1.25), Vector3(0.25, 1.5, 1.875),
	                         Vector3(1.5, 0.375, 0.625), Vector3(0.125, 2.25, 0.9375)}) {
		ASSERT_EQ(p.x() / 2 + p.y() / 3 + p.z() / 5, 1);
		const Block b = makeBlock(
		    {p, p + out + Vector3(0.3, 0, 0), p + out + Vector3(0, 0.3, 0), p + out + Vector3(0, 0, 0.3)});
		SCOPED_TRACE("corner " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()));
		const PairContacts r = expectContact(a, b, ContactType::VertexFace, s);
		EXPECT_EQ(r.separation, 0);
		ASSERT_EQ(r.contacts.size(), 1u);
		EXPECT_EQ(r.contacts[0].pointI, p);
		EXPECT_NEAR(r.contacts[0].gap, 0, 1e-15);
	}
}

// Two identical cubes turned by a random rotation, the upper one built on the
// lower one's top corners (the same doubles): the top face is planar only to
// round-off, yet with d0 = 0 the pair touches face to face, corners coincide
// and give one contact each.
TEST(ContactDetection, TurnedCubesSharingCornersTouchWithZeroContactDistance) {
	const DetectionSettings s = settings(0.0);
	std::mt19937 rng(7);
	for (int trial = 0; trial < 20; ++trial) {
		const Block a =
		    moved(box(Vector3(-0.5, -0.5, -0.5), Vector3(0.5, 0.5, 0.5)), randomRotation(rng), Vector3(0.3, -0.2, 0.1));
		std::vector<Vector3> upper;
		for (int k = 4; k < 8; ++k) upper.push_back(a.vertices[k]);                                  // a's top corners
		for (int k = 4; k < 8; ++k) upper.push_back(2 * a.vertices[k] - a.vertices[k - 4]);  // one height up
		const Block b = makeBlock(upper);
		SCOPED_TRACE("trial " + std::to_string(trial));
		const PairContacts r = expectContact(a, b, ContactType::FaceFace, s);
		EXPECT_EQ(r.contacts.size(), 4u);
		for (const SubContact& c : r.contacts) EXPECT_NEAR(c.gap, 0, 1e-15);
	}
}

// ------------------------------------------------------------------ far pairs, sweep

// Box b swept along x towards box a (libccd boxbox style): contact exactly when
// the gap is at most d0. All values are exact binary fractions.
TEST(ContactDetection, SweepAlongAxisHitsExactlyAtContactDistance) {
	const double d0 = 0.125;
	const DetectionSettings s = settings(d0);
	const Block a = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const double step = std::ldexp(1.0, -30);
	for (double gap : {1.0, 0.25, d0 + step, d0, d0 - step, 0.0625, 0.0, -step, -0.0625, -0.25}) {
		const Block b = box(Vector3(1 + gap, 0.25, 0.5), Vector3(2 + gap, 1.25, 1.5));
		const std::optional<PairContacts> r = detect(a, b, s);
		SCOPED_TRACE("gap " + std::to_string(gap));
		ASSERT_EQ(r.has_value(), gap <= d0);
		if (!r) continue;
		checkInvariants(*r, a, b, s);
		EXPECT_EQ(r->separation, gap);
		EXPECT_STREQ(dda::contactTypeName(r->type), "FF");
		EXPECT_EQ(r->entrance.kind, EntranceFeature::FaceOfA);
		EXPECT_EQ(r->normal, Vector3(1, 0, 0));
		EXPECT_GE(r->contacts.size(), 1u);
		for (const SubContact& c : r->contacts) EXPECT_EQ(c.gap, gap);
	}
}

// The same along a skew line: for axis-aligned boxes the separation is the
// largest per-axis gap.
TEST(ContactDetection, SweepAlongSkewLineHitsAtLargestAxisGap) {
	const double d0 = 0.125;
	const DetectionSettings s = settings(d0);
	const Block a = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const Vector3 direction(1, 0.5, -0.25);
	for (int k = -40; k <= 40; ++k) {
		const double t = 1 + k / 64.0;
		const Vector3 offset = t * direction;
		const Block b = moved(box(Vector3(0, 0, 0), Vector3(1, 1, 1)), Matrix3::Identity(), offset);
		const double expected = offset.cwiseAbs().maxCoeff() - 1;  // largest per-axis gap
		const std::optional<PairContacts> r = detect(a, b, s);
		SCOPED_TRACE("t " + std::to_string(t));
		ASSERT_EQ(r.has_value(), expected <= d0);
		if (!r) continue;
		checkInvariants(*r, a, b, s);
		EXPECT_NEAR(r->separation, expected, 1e-15);
	}
}

TEST(ContactDetection, PairFartherThanContactDistanceGivesNothing) {
	const Block a = octahedron(Vector3(0, 0, 0), 1);
	for (const Scene& scene : genericScenes(91, 5)) {
		// Corner above corner, gap 2 d0: no axis is within d0.
		const Block b = moved(octahedron(Vector3(0, 0, 2 + 2 * kContactDistance), 1), scene.R, scene.o);
		EXPECT_FALSE(detect(moved(a, scene.R, scene.o), b).has_value());
	}
	// Crossing edges 2 d0 apart.
	const Block p = prismAlongX(-1, 1, 0);
	const Block q = prismAlongY(-1, 1, 2 + 2 * kContactDistance);
	EXPECT_FALSE(detect(p, q).has_value());
	EXPECT_TRUE(detect(p, prismAlongY(-1, 1, 2 + 0.5 * kContactDistance)).has_value());
}

// ------------------------------------------------------------------ symmetry, hysteresis

void expectMirrored(const PairContacts& ab, const PairContacts& ba) {
	EXPECT_EQ(ab.type, ba.type);
	EXPECT_EQ(ab.separation, ba.separation);
	EXPECT_NEAR((ab.normal + ba.normal).norm(), 0, 1e-15);
	switch (ab.entrance.kind) {
		case EntranceFeature::FaceOfA: EXPECT_EQ(ba.entrance.kind, EntranceFeature::FaceOfB); break;
		case EntranceFeature::FaceOfB: EXPECT_EQ(ba.entrance.kind, EntranceFeature::FaceOfA); break;
		case EntranceFeature::EdgePair: EXPECT_EQ(ba.entrance.kind, EntranceFeature::EdgePair); break;
		case EntranceFeature::None: ADD_FAILURE() << "no entrance"; break;
	}
	if (ab.entrance.kind == EntranceFeature::EdgePair) {
		EXPECT_EQ(ab.entrance.feature, ba.entrance.other);
		EXPECT_EQ(ab.entrance.other, ba.entrance.feature);
	} else {
		EXPECT_EQ(ab.entrance.feature, ba.entrance.feature);
	}
	ASSERT_EQ(ab.contacts.size(), ba.contacts.size());
	for (std::size_t k = 0; k < ab.contacts.size(); ++k) {
		const SubContact &x = ab.contacts[k], &y = ba.contacts[k];
		EXPECT_EQ(x.kind, y.kind);
		EXPECT_NEAR(x.gap, y.gap, 1e-15);
		if (x.firstIsA == !y.firstIsA) {  // the same block owns the vertex or edge 1
			EXPECT_EQ(x.feature1, y.feature1);
			EXPECT_EQ(x.feature2, y.feature2);
			EXPECT_NEAR((x.normal - y.normal).norm(), 0, 1e-15);
			EXPECT_EQ(x.pointI, y.pointI);
			EXPECT_EQ(x.pointJ, y.pointJ);
		} else {  // an edge entrance: block i is A in both orders, roles swap
			EXPECT_EQ(x.kind, ContactKind::EdgeEdge);
			EXPECT_EQ(x.feature1, y.feature2);
			EXPECT_EQ(x.feature2, y.feature1);
			EXPECT_NEAR((x.normal + y.normal).norm(), 0, 1e-15);
			EXPECT_NEAR((x.pointI - y.pointJ).norm(), 0, 1e-15);
			EXPECT_NEAR((x.pointJ - y.pointI).norm(), 0, 1e-15);
		}
	}
}

TEST(ContactDetection, SwappingBlocksMirrorsTheResult) {
	const Block floor = box(Vector3(-2, -2, -1), Vector3(2, 2, 0));
	const Block turned = moved(box(Vector3(-0.3, -0.3, 0), Vector3(0.3, 0.3, 0.6)),
	                           rotationAbout(Vector3(0.1, 0.2, 1), 0.35),
	                           Vector3(0.5, 0.4, -2e-4));
	const Block p = prismAlongX(-1, 1, 0);
	const Block q = moved(prismAlongY(-1, 1, 2), rotationAbout(Vector3::UnitZ(), 0.5), Vector3(0.2, 0.1, -1e-4));
	const Block oct = octahedron(Vector3(0.3, -0.2, 1 + 3e-4), 1);
	const std::vector<std::pair<const Block*, const Block*>> pairs{
	    {&floor, &turned}, {&p, &q}, {&floor, &oct}, {&p, &oct}};
	for (const auto& [a, b] : pairs) {
		for (const Scene& scene : genericScenes(101, 3)) {
			const Block sa = moved(*a, scene.R, scene.o), sb = moved(*b, scene.R, scene.o);
			const std::optional<PairContacts> ab = detect(sa, sb), ba = detect(sb, sa);
			ASSERT_TRUE(ab && ba);
			SCOPED_TRACE(describe(*ab) + " | " + describe(*ba));
			EXPECT_FALSE(ab->contacts.empty());
			expectMirrored(*ab, *ba);
		}
	}
}

TEST(ContactDetection, HysteresisKeepsPreviousEntranceFaceOnTie) {
	const Block a = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const Block b = box(Vector3(0.25, 0, 1), Vector3(1.25, 1, 2));
	const std::optional<PairContacts> fresh = detect(a, b);
	ASSERT_TRUE(fresh);
	EXPECT_EQ(fresh->entrance.kind, EntranceFeature::FaceOfA);  // tie: A first
	int bottomOfB = -1;
	for (std::size_t f = 0; f < b.shape.faces.size(); ++f)
		if (dda::faceNormal(b.vertices, b.shape.faces[f]).z() < -0.5) bottomOfB = static_cast<int>(f);
	ASSERT_GE(bottomOfB, 0);
	const EntranceFeature previous{EntranceFeature::FaceOfB, bottomOfB, -1};
	const std::optional<PairContacts> kept = detect(a, b, settings(), previous);
	ASSERT_TRUE(kept);
	checkInvariants(*kept, a, b, settings());
	EXPECT_EQ(kept->entrance, previous);
	EXPECT_EQ(kept->normal, Vector3(0, 0, 1));
	ASSERT_EQ(kept->contacts.size(), 4u);
	for (const SubContact& c : kept->contacts) {
		EXPECT_EQ(c.kind, ContactKind::VertexFace);
		if (c.firstIsA) EXPECT_EQ(c.feature2, bottomOfB);  // a's corners on b's bottom face
	}
	EXPECT_EQ(std::count_if(kept->contacts.begin(), kept->contacts.end(), [](const SubContact& c) { return c.firstIsA; }),
	          2);

	// b tilted so that its bottom face is 0.4 hysteresis worse than a's top: kept;
	// 3 hysteresis worse: the best face takes over.
	const double hysteresis = settings().hysteresis;
	for (double worse : {0.4 * hysteresis, 3 * hysteresis}) {
		// Turning b so that its bottom rises towards x = 1.25 by slope tan(angle),
		// its lowest corner (x = 0.25) 1e-5 above a: b's bottom plane passes
		// 0.25 tan(angle) lower at a's corners x = 0, so its separation is
		// about that much worse than a's top face's (1e-5).
		const double angle = std::atan(4 * worse);
		const Block tilted = moved(b, rotationAbout(Vector3::UnitY(), -angle), Vector3::Zero());
		const Block lifted = moved(tilted, Matrix3::Identity(),
		                           Vector3(0, 0, 1 - tilted.vertices[0].z() + 1e-5));  // lowest corner 1e-5 above a
		const std::optional<PairContacts> r = detect(a, lifted, settings(), previous);
		ASSERT_TRUE(r);
		SCOPED_TRACE("worse " + std::to_string(worse) + " " + describe(*r));
		checkInvariants(*r, a, lifted, settings());
		if (worse < hysteresis) {
			EXPECT_EQ(r->entrance, previous);
		} else {
			EXPECT_EQ(r->entrance.kind, EntranceFeature::FaceOfA);
		}
	}
}

// ------------------------------------------------------------------ randomized

// Independent twin: the separation along every face normal and every edge
// cross product, in both orientations.
double bruteForceSeparation(const Block& a, const Block& b) {
	std::vector<Vector3> axes;
	for (const Block* x : {&a, &b})
		for (const auto& face : x->shape.faces) axes.push_back(dda::faceNormal(x->vertices, face));
	for (const auto& ea : a.shape.edges) {
		for (const auto& eb : b.shape.edges) {
			const Vector3 c = (a.vertices[ea[1]] - a.vertices[ea[0]]).cross(b.vertices[eb[1]] - b.vertices[eb[0]]);
			if (c.norm() > 1e-6) axes.push_back(c.normalized());
		}
	}
	double best = -std::numeric_limits<double>::infinity();
	for (const Vector3& n : axes) {
		double minA = 1e300, maxA = -1e300, minB = 1e300, maxB = -1e300;
		for (const Vector3& x : a.vertices) {
			minA = std::min(minA, n.dot(x));
			maxA = std::max(maxA, n.dot(x));
		}
		for (const Vector3& x : b.vertices) {
			minB = std::min(minB, n.dot(x));
			maxB = std::max(maxB, n.dot(x));
		}
		best = std::max({best, minB - maxA, minA - maxB});
	}
	return best;
}

// Is some corner of `inner` inside `outer` by more than `margin` [m]?
bool cornerInside(const Block& inner, const Block& outer, double margin) {
	for (const Vector3& p : inner.vertices) {
		bool inside = true;
		for (const auto& face : outer.shape.faces) {
			const Vector3 n = dda::faceNormal(outer.vertices, face);
			if (n.dot(p - outer.vertices[face[0]]) > -margin) inside = false;
		}
		if (inside) return true;
	}
	return false;
}

Block randomShape(std::mt19937& rng) {
	std::uniform_real_distribution<double> size(0.4, 1.5);
	std::normal_distribution<double> normal(0.0, 1.0);
	if (rng() % 2) {
		const Vector3 half(size(rng) / 2, size(rng) / 2, size(rng) / 2);
		return moved(box(-half, half), randomRotation(rng), Vector3::Zero());
	}
	for (;;) {  // a tetrahedron that is not too flat
		std::vector<Vector3> p;
		for (int k = 0; k < 4; ++k) p.emplace_back(normal(rng), normal(rng), normal(rng));
		const double volume = std::abs((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))) / 6;
		if (volume < 0.1) continue;
		Vector3 mean = (p[0] + p[1] + p[2] + p[3]) / 4;
		for (Vector3& x : p) x -= mean;
		return makeBlock(p);
	}
}

TEST(ContactDetection, RandomBoxesAndTetrahedraNearContact) {
	std::mt19937 rng(20240611);
	std::normal_distribution<double> normal(0.0, 1.0);
	std::uniform_real_distribution<double> jitter(-0.02, 0.02);
	const double d0 = 0.01;
	int found = 0, overlapping = 0, far = 0;
	for (int trial = 0; trial < 200; ++trial) {
		const Block a = randomShape(rng);
		const Block b0 = randomShape(rng);
		const Vector3 direction = Vector3(normal(rng), normal(rng), normal(rng)).normalized();
		// Touching distance along `direction` by bisection of the convex,
		// increasing separation.
		double lo = 0, hi = 10;
		for (int k = 0; k < 60; ++k) {
			const double mid = 0.5 * (lo + hi);
			(bruteForceSeparation(a, moved(b0, Matrix3::Identity(), mid * direction)) > 0 ? hi : lo) = mid;
		}
		const Block b = moved(b0, Matrix3::Identity(), (hi + jitter(rng)) * direction);
		DetectionSettings s = settings(d0);
		s.lengthTolerance = 1e-8 * 3;
		const double brute = bruteForceSeparation(a, b);
		const std::optional<PairContacts> r = detect(a, b, s);
		SCOPED_TRACE("trial " + std::to_string(trial) + " brute separation " + std::to_string(brute));
		if (brute > d0 + s.lengthTolerance) {
			EXPECT_FALSE(r.has_value());
			++far;
			continue;
		}
		if (brute < 0) EXPECT_TRUE(r.has_value());
		if (!r) continue;  // within d0 by the separating axes, but the boxes' bounds are apart
		++found;
		SCOPED_TRACE(describe(*r));
		checkInvariants(*r, a, b, s);
		EXPECT_LE(r->separation, brute + 1e-9);
		if (cornerInside(a, b, s.lengthTolerance) || cornerInside(b, a, s.lengthTolerance)) {
			++overlapping;
			EXPECT_TRUE(std::any_of(r->contacts.begin(), r->contacts.end(), [](const SubContact& c) { return c.gap < 0; }));
		}
	}
	EXPECT_GT(found, 100);
	EXPECT_GT(overlapping, 30);
	EXPECT_GT(far, 10);
}

}  // namespace

// Two turned logs side by side (from the paper's hexahedra drop, step 1128):
// the second log's corners sit 36 um below the first one's bottom face (so
// they are outside it), while the first log's bottom edge cuts 0.36 mm into
// the second log's side face. The crossings beside those corners push along
// x, the corners' contacts along z: the crossings must stay. Dropping them
// (an earlier corner-merge rule) left the pair without any penetrating
// sub-contact, and the logs sank 0.4 m into each other.
TEST(ContactDetection, OverlapOfTurnedLogsIsRepresentedByASubContact) {
	const std::vector<Vector3> log1 = {
	    {-8.3516706442490012, -10.179903089140623, 4.9194987463906799},
	    {-7.3429838252272628, -10.179903087473122, 4.9195251681233065},
	    {-8.3516706709854169, 10.179903087526171, 4.9194987460755577},
	    {-7.3429838519636945, 10.179903089193679, 4.9195251678081915},
	    {-8.3627267086338062, -10.179903089148144, 5.8742626195503655},
	    {-7.3540398896120767, -10.179903087480636, 5.8742890412829993},
	    {-8.3627267353702557, 10.179903087518657, 5.8742626192352541},
	    {-7.3540399163485244, 10.179903089186158, 5.8742890409678807}};
	const std::vector<Vector3> log2 = {
	    {-7.3433389635284092, -10.089161232484551, 4.919489375338407},
	    {-6.3311287341299289, -10.089161232483221, 4.9194999010976979},
	    {-7.343338964201207, 10.089161232481519, 4.9194893750150754},
	    {-6.3311287348027223, 10.08916123248285, 4.9194999007743618},
	    {-7.3477794472388203, -10.089161232482263, 5.8742659030389301},
	    {-6.3355692178403356, -10.089161232480933, 5.8742764287982165},
	    {-7.3477794479116136, 10.089161232483807, 5.8742659027155941},
	    {-6.3355692185131334, 10.089161232485138, 5.874276428474885}};
	const dda::ConvexPolyhedron a = dda::buildConvexPolyhedron(log1), b = dda::buildConvexPolyhedron(log2);
	const Vector3 ca = dda::computeMassProperties(a.vertices, a.faces).centroid;
	const Vector3 cb = dda::computeMassProperties(b.vertices, b.faces).centroid;
	DetectionSettings settings;
	settings.contactDistance = 0.025;
	settings.lengthTolerance = 2e-7;
	settings.hysteresis = 0.0025;
	settings.cornerMergeDistance = 0.02;  // 1e-3 x the logs' diagonal, as World sets it
	settings.angleTolerance = 1e-3;
	const auto result = dda::detectPairContacts(dda::BlockGeometry{&a, &a.vertices, ca}, dda::BlockGeometry{&b, &b.vertices, cb},
	                                            settings);
	ASSERT_TRUE(result.has_value());
	ASSERT_LT(result->separation, -3e-4);  // they overlap by 0.36 mm
	double deepest = 0;
	for (const SubContact& c : result->contacts) deepest = std::min(deepest, c.gap);
	EXPECT_LT(deepest, 0.9 * result->separation) << "no sub-contact carries the overlap";
}

// Two slender blocks of bench/colliders.py's random deposit (blocks 208 and
// 267 of the 1,000-block scene) crossing 3.9 mm apart: the pair's entrance is
// an edge pair; its best face axis lies about 0.7 m deep (crossed logs). The
// face search of the edge entrance once took its depth limit from that face
// axis and gave two edge crossings 1.02 m and 0.99 m "deep" between blocks that
// do not touch (71 negative gaps in a deposit built without any overlap). No
// sub-contact of a pair may be deeper than the pair's penetration allows.
TEST(ContactDetection, EdgeEntranceOfCrossedLogsApartHasNoDeepSubContacts) {
	const std::vector<Vector3> log1 = {
	    {5.8905440647062832, 7.7240932513911806, 2.5726767893382103},
	    {8.0317262217166761, 6.2507437197789608, 2.5713944292490027},
	    {5.7637350192601726, 7.5396774404604949, 2.7190344321411444},
	    {7.9049171762705654, 6.0663279088482751, 2.7177520720519368},
	    {5.8196975042169594, 7.6212998704976433, 2.3817697149314352},
	    {7.9608796612273522, 6.1479503388854235, 2.3804873548422276},
	    {5.6928884587708488, 7.4368840595669576, 2.5281273577343693},
	    {7.8340706157812416, 5.9635345279547378, 2.5268449976451617}};
	const std::vector<Vector3> log2 = {
	    {7.6730227786901164, 7.2470197837098365, 2.8887584189403088},
	    {5.3801272983420132, 5.7223336855066069, 3.0512076760008719},
	    {7.5561195839800295, 7.4426899051781428, 3.0752086852912321},
	    {5.2632241036319263, 5.9180038069749132, 3.2376579423517948},
	    {7.5603766780049773, 7.3926172378128401, 2.6653328299785186},
	    {5.2674811976568741, 5.8679311396096105, 2.8277820870390813},
	    {7.4434734832948903, 7.5882873592811464, 2.8517830963294415},
	    {5.1505780029467871, 6.0636012610779169, 3.0142323533900046}};
	const dda::ConvexPolyhedron a = dda::buildConvexPolyhedron(log1), b = dda::buildConvexPolyhedron(log2);
	const Vector3 ca = dda::computeMassProperties(a.vertices, a.faces).centroid;
	const Vector3 cb = dda::computeMassProperties(b.vertices, b.faces).centroid;
	DetectionSettings settings;
	settings.contactDistance = 0.01;
	settings.lengthTolerance = 3e-8;
	settings.hysteresis = 1e-3;
	settings.cornerMergeDistance = 2e-3;
	settings.angleTolerance = 5e-3;
	const auto result = dda::detectPairContacts(dda::BlockGeometry{&a, &a.vertices, ca}, dda::BlockGeometry{&b, &b.vertices, cb},
	                                            settings);
	ASSERT_TRUE(result.has_value());
	EXPECT_EQ(result->entrance.kind, EntranceFeature::EdgePair);
	EXPECT_NEAR(result->separation, 3.9e-3, 1e-4);
	ASSERT_FALSE(result->contacts.empty());
	for (const SubContact& c : result->contacts)
		EXPECT_GE(c.gap, -settings.lengthTolerance) << "a sub-contact " << c.gap << " m deep between blocks apart";
}

// Two pairs of slender blocks of bench/colliders.py's 10,000-block deposit
// (blocks 1581 and 1817, 3.7 mm apart; 7003 and 7062, 0.28 mm apart), with
// the settings World gives them (d0 = 1 cm, allowed displacement 4 mm). An
// edge of one block passes an edge of the other's entrance face about 1 cm
// away, on the far side of the face's plane: the crossing's stencil, signed by
// the edges' outward directions, took that distance as a penetration. Each
// pair had one edge-edge sub-contact about 9 mm "deep" (closed at the first
// step, a push of 1 cm of penalty spring between blocks that do not touch; 4
// such in the deposit, 24 in the 50,000-block one), because a face entrance's
// crossings could lie d0 deeper than the pair's penetration. Blocks that do
// not overlap have no sub-contact deeper than the length tolerance.
TEST(ContactDetection, EdgeCrossingsOfBlocksApartAreNeverDeep) {
	const std::vector<std::vector<Vector3>> blocks = {
	    {{0.745555184390051, 12.001337305239087, 3.799824323623012},
	     {0.5401898040352835, 12.01097108487229, 2.6089061969474336},
	     {0.5393008580974489, 12.098320800050473, 3.8361759541980005},
	     {0.33393547774268145, 12.107954579683675, 2.6452578275224212},
	     {0.840264544566901, 12.208249456793183, 3.7851661558503027},
	     {0.6348991642121337, 12.217883236426385, 2.5942480291747243},
	     {0.634010218274299, 12.305232951604568, 3.8215177864252903},
	     {0.42864483791953156, 12.314866731237771, 2.630599659749712}},
	    {{0.6021424774571142, 12.048944473357789, 3.889031056504369},
	     {0.18298112208327638, 9.895780747109974, 4.1544733100657245},
	     {0.8443479073518616, 11.984438502119756, 3.748251807454271},
	     {0.42518655197802374, 9.83127477587194, 4.013694061015626},
	     {0.7321126965809328, 12.051088299530925, 4.1116576397430835},
	     {0.31295134120709506, 9.897924573283108, 4.377099893304439},
	     {0.9743181264756802, 11.98658232829289, 3.970878390692985},
	     {0.5551567711018424, 9.833418602045075, 4.236320644254341}},
	    {{7.140621596014642, 14.227962579673665, 13.430882304955013},
	     {7.4265188873964565, 14.270157560315036, 14.530458537338859},
	     {7.2558817913125875, 14.100502160046865, 13.405805018916057},
	     {7.541779082694401, 14.142697140688236, 14.505381251299903},
	     {7.255736281755718, 14.33878415377581, 13.396699053336304},
	     {7.541633573137531, 14.380979134417181, 14.49627528572015},
	     {7.370996477053662, 14.21132373414901, 13.371621767297349},
	     {7.656893768435476, 14.253518714790381, 14.471197999681195}},
	    {{6.69414943716485, 14.507673557341674, 14.89426935952585},
	     {8.1329573358774, 13.885084572167203, 14.215156826373018},
	     {6.729235887959081, 14.393103891076107, 15.073639447465567},
	     {8.16804378667163, 13.770514905901639, 14.394526914312733},
	     {6.5908127400277525, 14.353929714428041, 14.816281647113273},
	     {8.029620638740303, 13.731340729253573, 14.137169113960441},
	     {6.6258991908219835, 14.239360048162476, 14.995651735052988},
	     {8.064707089534533, 13.616771062988006, 14.316539201900154}}};
	const std::vector<double> apart = {3.67e-3, 2.8e-4};  // the pairs' distances [m] (separating axes)
	for (int p = 0; p < 2; ++p) {
		SCOPED_TRACE("pair " + std::to_string(p));
		const dda::Block a = dda::makeBlock(blocks[2 * p], dda::Material{}, false);
		const dda::Block b = dda::makeBlock(blocks[2 * p + 1], dda::Material{}, false);
		const DetectionSettings settings =
		    dda::pairDetectionSettings(dda::boundingDiagonal(a), dda::boundingDiagonal(b), 0.01, 0.004);
		const auto result = dda::detectPairContacts(dda::BlockGeometry{a.shape.get(), &a.vertices, a.centroid},
		                                            dda::BlockGeometry{b.shape.get(), &b.vertices, b.centroid}, settings);
		ASSERT_TRUE(result.has_value());
		EXPECT_NEAR(result->separation, apart[p], 1e-4);
		ASSERT_FALSE(result->contacts.empty());
		for (const SubContact& c : result->contacts)
			EXPECT_GE(c.gap, -settings.lengthTolerance) << "a sub-contact " << c.gap << " m deep between blocks apart";
	}
}

// Two pairs of the 50,000-block slender deposit (bodies 22145/22146, a
// hexahedron and a triangular prism 5.65 mm apart; 44194/45600, 6.5 mm apart:
// /work/shared/repro/ghost_pairs.json, corners in m), with World's settings
// for d0 = 1 cm. Their best axis is an edge pair whose edges do not cross
// strictly inside, so the entrance falls back to the best face, which lies
// 0.16 and 0.11 m deep; its separation was taken as the depth bound, and the
// pairs got an edge-edge sub-contact 0.25 m deep (closed, locked, 5.1e7 N)
// and a vertex-face one 2.6 mm deep. Every sub-contact of a pair apart must
// have a positive gap, and the pairs, within d0, must keep a contact: the
// ends of the fallback's edges against their own entrance faces.
TEST(ContactDetection, GhostPairsOfTheDepositHaveNoNegativeGap) {
	const std::vector<std::vector<Vector3>> blocks = {
	    {{18.925986157, 6.450697633, 17.003494633},
	     {18.838917728, 6.428241197, 16.752056349},
	     {19.381541205, 5.968348375, 16.832063324},
	     {19.294472776, 5.945891939, 16.580625039},
	     {19.746758846, 7.13273078, 16.497382015},
	     {19.659690417, 7.110274345, 16.24594373},
	     {20.202313894, 6.650381522, 16.325950706},
	     {20.115245465, 6.627925087, 16.074512421}},
	    {{20.220258301, 5.706508503, 16.327361119},
	     {19.750287835, 6.132223302, 16.25940593},
	     {20.014291509, 5.858464939, 16.561993541},
	     {21.309794737, 6.934980369, 16.488183383},
	     {20.839824271, 7.360695168, 16.420228194},
	     {21.103827946, 7.086936805, 16.722815806}},
	    {{15.876995769, 10.467384398, 32.625686741},
	     {15.96078133, 10.325168142, 32.677523562},
	     {16.503924233, 10.974056481, 33.193784437},
	     {16.587709793, 10.831840226, 33.245621259},
	     {16.49784601, 10.219282278, 31.773819417},
	     {16.58163157, 10.077066022, 31.825656238},
	     {17.124774473, 10.725954362, 32.341917114},
	     {17.208560033, 10.583738106, 32.393753935}},
	    {{17.171292881, 11.473600174, 33.859889617},
	     {16.97806806, 10.728634305, 33.407046159},
	     {16.987206688, 11.21649584, 33.964439189},
	     {15.984836048, 12.105948105, 33.325875682},
	     {15.791611227, 11.360982237, 32.873032224},
	     {15.800749855, 11.848843772, 33.430425254}}};
	const std::vector<double> apart = {5.6e-3, 6.4e-3};  // below their separating axes' 5.65 and 6.5 mm [m]
	for (int p = 0; p < 2; ++p) {
		SCOPED_TRACE("pair " + std::to_string(p));
		ASSERT_GT(bruteForceSeparation(makeBlock(blocks[2 * p]), makeBlock(blocks[2 * p + 1])), apart[p]);
		const dda::Block a = dda::makeBlock(blocks[2 * p], dda::Material{}, false);
		const dda::Block b = dda::makeBlock(blocks[2 * p + 1], dda::Material{}, false);
		for (const double allowed : {0.0, 0.004}) {  // before the first step, and the deposit's
			const DetectionSettings settings =
			    dda::pairDetectionSettings(dda::boundingDiagonal(a), dda::boundingDiagonal(b), 0.01, allowed);
			for (const bool swap : {false, true}) {
				const dda::BlockGeometry ga{a.shape.get(), &a.vertices, a.centroid};
				const dda::BlockGeometry gb{b.shape.get(), &b.vertices, b.centroid};
				const auto result =
				    swap ? dda::detectPairContacts(gb, ga, settings) : dda::detectPairContacts(ga, gb, settings);
				ASSERT_TRUE(result.has_value()) << "a pair within d0 not reported";
				EXPECT_FALSE(result->contacts.empty()) << "a pair within d0 without sub-contacts";
				for (const SubContact& c : result->contacts)
					EXPECT_GE(c.gap, -settings.lengthTolerance)
					    << "a sub-contact " << c.gap << " m deep between blocks apart";
			}
		}
	}
}

// A part of a concave block (the unit cube, its face x = 1 shared with the
// next part: internal) and a box crossing the part's ridge, the edge (x, z) =
// (1, 1) along y that the top face shares with the internal face: the box's
// lowest edge, 0.2 m long, runs along (1, 0, -1), h above the ridge along
// (1, 0, 1) / sqrt(2), slightly turned (a generic placement). Closed form:
// the two are h apart, separated only along the cross product of the two
// edges (every face axis shows an overlap: the box's edge dips below the top
// face's plane beyond the seam). No sub-contact may then have a negative gap,
// and beyond d0 the pair has no contact. The ridge's axis was left out when
// its edge lay on an internal face: the pair seemed to overlap by 7 cm (a
// face axis), and the box's lower corner beyond the seam, below the top
// face's plane but outside the part, took a gap of -7 cm 0.5 mm apart (as
// in the roofs of tests/cpp/contact/test_contact_coverage.cpp: -9.2 cm, 3.2
// cm outside).
TEST(ContactDetection, InternalEdgesBoundThePenetrationOfAPartAcrossItsRidge) {
	const Block part = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	std::vector<char> internal(part.shape.faces.size(), 0);
	for (std::size_t f = 0; f < part.shape.faces.size(); ++f)
		internal[f] = dda::faceNormal(part.vertices, part.shape.faces[f]).x() > 0.5;
	ASSERT_EQ(std::count(internal.begin(), internal.end(), 1), 1);
	const Vector3 along = Vector3(1, 0, -1).normalized(), out = Vector3(1, 0, 1).normalized();
	const Vector3 u = (out + Vector3::UnitY()).normalized(), v = (out - Vector3::UnitY()).normalized();
	const double d0 = 0.1;
	const DetectionSettings s = settings(d0);
	for (const double h : {0.0005, 0.02, 0.08, 0.15}) {
		SCOPED_TRACE("h = " + std::to_string(h));
		std::vector<Vector3> corners;
		const Vector3 edge = Vector3(1, 0.5, 1) + h * out;
		for (const double t : {-0.1, 0.1})
			for (const double a : {0.0, 0.5})
				for (const double b : {0.0, 0.5}) corners.push_back(edge + t * along + a * u + b * v);
		// Turned by 0.01 rad about the common normal through the edges' crossing.
		const Block crossing = moved(makeBlock(corners), rotationAbout(out, 0.01),
		                             edge - rotationAbout(out, 0.01) * edge);
		const double apart = bruteForceSeparation(part, crossing);
		ASSERT_NEAR(apart, h, 1e-12);
		for (const bool swap : {false, true}) {
			SCOPED_TRACE(swap ? "swapped" : "part first");
			const dda::BlockGeometry gp{&part.shape, &part.vertices, part.centroid, &internal};
			const dda::BlockGeometry gc = crossing.geometry();
			const auto result = swap ? dda::detectPairContacts(gc, gp, s) : dda::detectPairContacts(gp, gc, s);
			if (h > d0) {
				EXPECT_FALSE(result.has_value()) << describe(*result);
				continue;
			}
			ASSERT_TRUE(result.has_value());
			SCOPED_TRACE(describe(*result));
			EXPECT_FALSE(result->contacts.empty());
			for (const SubContact& c : result->contacts)
				EXPECT_GE(c.gap, -kLengthTolerance) << "a sub-contact between blocks " << apart << " m apart";
		}
	}
}

// A box (0.5 x 0.5 x 0.3 m) resting on the unit cube's top face, sunk delta
// into it, turned by theta about the vertical, its corner P farthest along x
// eps past the top face's edge x = 1 (eps < 0: on the face), below the top
// face's plane by delta. Closed form: for eps > 0 P lies outside the cube,
// eps from its side face x = 1; the overlap's corners near P are where P's
// two bottom edges cross the cube's edge (x, z) = (1, 1), delta deep. So P's
// contact is against the side face with gap eps (open), and the two
// crossings carry -delta; no corner outside the cube has a negative gap.
// With its edges turned 0.01 rad from the cube's (within the angle
// tolerance) P stands for the near-parallel edges' contact and keeps -delta
// on the top face (outsideBeyondFaceEdge, FaceEntrance.cpp). Before, P took
// -delta on the top face's plane whatever theta, up to d0 past the edge.
TEST(ContactDetection, CornerPastAFaceEdgeOutsideTheBlockHasNoNegativeGap) {
	const Block cube = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const double d0 = 0.1, delta = 1e-3;
	DetectionSettings s = settings(d0);
	s.angleTolerance = 0.05;  // World's largest (pairDetectionSettings)
	for (const double theta : {kPi / 6, 0.01})
		for (const double eps : {-0.01, 0.001, 0.02, 0.08}) {
			SCOPED_TRACE("theta " + std::to_string(theta) + ", eps " + std::to_string(eps));
			const Matrix3 R = rotationAbout(Vector3::UnitZ(), theta);
			std::vector<Vector3> corners;
			for (int k = 0; k < 8; ++k)
				corners.push_back(R * Vector3(k & 1 ? 0.25 : -0.25, k & 2 ? 0.25 : -0.25, k & 4 ? 0.3 : 0.0));
			int p = 0;
			for (int k = 1; k < 8; ++k)
				if (corners[k].x() > corners[p].x() || (corners[k].x() == corners[p].x() && corners[k].z() < corners[p].z()))
					p = k;
			const Vector3 shift = Vector3(1 + eps, 0.5, 1 - delta) - corners[p];
			for (Vector3& x : corners) x += shift;
			const Block block = makeBlock(corners);
			const auto result = detect(cube, block, s);
			ASSERT_TRUE(result.has_value());
			SCOPED_TRACE(describe(*result));
			checkInvariants(*result, cube, block, s);
			const auto pContact = std::find_if(result->contacts.begin(), result->contacts.end(), [&](const SubContact& c) {
				return c.kind == ContactKind::VertexFace && !c.firstIsA && c.feature1 == p;
			});
			ASSERT_NE(pContact, result->contacts.end());
			if (eps < 0 || theta < s.angleTolerance) {
				EXPECT_NEAR(pContact->gap, -delta, 1e-12);  // on the top face
				EXPECT_NEAR(pContact->normal.z(), 1, 1e-12);
			} else {
				EXPECT_NEAR(pContact->gap, eps, 1e-12);  // on the side face x = 1
				EXPECT_NEAR(pContact->normal.x(), 1, 1e-12);
				int crossings = 0;
				for (const SubContact& c : result->contacts) {
					if (c.kind == ContactKind::VertexFace && !c.firstIsA && block.vertices[c.feature1].x() > 1 + kLengthTolerance)
						EXPECT_GE(c.gap, -kLengthTolerance) << "corner " << c.feature1 << " outside the cube";
					crossings += c.kind == ContactKind::EdgeEdge && std::abs(c.gap + delta) < 1e-12;
				}
				EXPECT_EQ(crossings, 2);
			}
		}
}

// Three pairs the narrow-phase oracle found in its 2,000,000-pair run (seed
// 20250917, pairs 415996, 666220 and 1160967 of
// tests/cpp/contact/test_narrow_phase_oracle.cpp), with World's settings for d0 = 1 cm:
// a pair 9.19 mm apart whose entrance face ties with the face the corners lie over (no sub-contact before); a pair overlapping by 0.38 mm, same tie (no sub-contact before); a box along a slender block, edges 0.0103 rad from parallel (the entrance crossing was 6.12 mm deep for a 5.84 mm overlap). Each must keep a sub-contact, and none may be deeper than the
// pair's overlap (its separating-axis value, every face normal and edge
// cross product).
TEST(ContactDetection, OracleFoundPairsKeepASubContactNoDeeperThanTheOverlap) {
	const std::vector<std::vector<Vector3>> blocks = {
	    {{-99.847840057879836, 41.443940016756862, -41.91048947971931},
	     {-99.831771189353177, 41.523906657719394, -41.919394900181587},
	     {-99.795115708008268, 41.439759629898063, -41.852892069985487},
	     {-99.779046839481609, 41.519726270860595, -41.861797490447763},
	     {-99.830242405759648, 41.438566487082845, -41.926988280698886},
	     {-99.814173537232989, 41.518533128045377, -41.935893701161163},
	     {-99.777518055888081, 41.434386100224046, -41.869390870965063},
	     {-99.761449187361421, 41.514352741186578, -41.87829629142734}},
	    {{-85.888679543471298, 33.12750400082713, -53.599682137520546},
	     {-114.20474777128125, 50.535898700973874, -29.253635695324519},
	     {-86.770029545456467, 33.791299213838258, -53.055005520763935},
	     {-110.32547039781298, 48.277884546609691, -32.83872701513269},
	     {-87.257516445325805, 33.822105449507809, -52.566164185117572},
	     {-108.2411815006823, 46.676652596748923, -34.504777974304325},
	     {-90.904860224626702, 36.160378966658712, -49.589838231027699},
	     {-107.86171629383986, 46.61150601069648, -35.093945446874763}},
	    {{76.591050245511553, 26.621079524843438, 44.796742740559644},
	     {76.585909060334671, 26.634853185523706, 44.689532662758403},
	     {76.770807559545645, 26.523204178072625, 44.765721476472478},
	     {76.395660564164601, 26.260762544791419, 44.760492376908296},
	     {76.390519378987719, 26.274536205471687, 44.653282299107062},
	     {76.575417878198706, 26.162887198020609, 44.729471112821138}},
	    {{75.738897075660702, 25.942977753370453, 44.666543751509103},
	     {76.40231459568966, 27.320855242782443, 44.951710536403624},
	     {76.531797519824678, 25.651749369506899, 45.043217572978868},
	     {77.215474055530208, 26.772179726746444, 45.32366372221172},
	     {75.873853238021752, 25.844255448883416, 44.560313156280799},
	     {76.348478232892631, 27.14720210472727, 44.669285108255075},
	     {76.938397405405624, 25.596083914883426, 45.054264533437909},
	     {77.472424521971135, 27.016556680323617, 45.180459308490967}},
	    {{98.384171329590927, 30.150233387868678, -25.778551816348866},
	     {97.984805424801564, 30.052078510439856, -25.836736598975818},
	     {98.369622314687263, 30.084608008282252, -25.567984189605752},
	     {97.9702564098979, 29.98645313085343, -25.626168972232705},
	     {98.362407560572393, 30.225728271557774, -25.756526877991284},
	     {97.96304165578303, 30.127573394128952, -25.814711660618237},
	     {98.347858545668728, 30.160102891971349, -25.545959251248171},
	     {97.948492640879365, 30.061948014542526, -25.604144033875123}},
	    {{88.100041458467743, 27.671570465781954, -27.357063969510484},
	     {109.27233788876202, 32.930072000731734, -24.048117888236956},
	     {86.141346180516663, 27.326561833936594, -27.721487051181857},
	     {111.52921688894199, 33.6316771140322, -23.742899276505465},
	     {85.625954929554908, 27.086493924345369, -27.724639998110554},
	     {110.05361378914016, 33.146331386196515, -23.900349101050324},
	     {85.067418224188103, 27.096830253843805, -27.877923732185319},
	     {107.14640544351877, 32.561908363236213, -24.404611777152578}}};
	for (int p = 0; p < 3; ++p) {
		SCOPED_TRACE("pair " + std::to_string(p));
		const double overlap =
		    std::min(bruteForceSeparation(makeBlock(blocks[2 * p]), makeBlock(blocks[2 * p + 1])), 0.0);
		const dda::Block a = dda::makeBlock(blocks[2 * p], dda::Material{}, false);
		const dda::Block b = dda::makeBlock(blocks[2 * p + 1], dda::Material{}, false);
		const DetectionSettings settings =
		    dda::pairDetectionSettings(dda::boundingDiagonal(a), dda::boundingDiagonal(b), 0.01, 0.004);
		for (const bool swap : {false, true}) {
			const dda::BlockGeometry ga{a.shape.get(), &a.vertices, a.centroid};
			const dda::BlockGeometry gb{b.shape.get(), &b.vertices, b.centroid};
			const auto result =
			    swap ? dda::detectPairContacts(gb, ga, settings) : dda::detectPairContacts(ga, gb, settings);
			ASSERT_TRUE(result.has_value()) << "a pair within d0 not reported";
			EXPECT_FALSE(result->contacts.empty()) << "a pair within d0 without sub-contacts";
			for (const SubContact& c : result->contacts)
				EXPECT_GE(c.gap, overlap - 2 * settings.lengthTolerance)
				    << "a sub-contact " << c.gap << " m deep where the blocks overlap by " << -overlap << " m";
		}
	}
}

// A cube tilted 0.004 rad and turned 0.3 rad over a fixed unit cube, its
// lowest corner overhanging the fixed cube's edge x = 1 so that the pair's
// closest features are two edges crossing (an edge entrance). Its far
// corners come within d0 = 1e-2 m of the fixed cube's top face. Before, an
// edge entrance gave the crossing only: those corners were no contact and a
// cube rocking down onto its neighbour (a pile of turned cubes) sank 1.2 mm
// into it within a step. Every corner of the tilted cube within d0 of the
// top face's plane and above the face must now have its vertex-face contact,
// gap the corner's height above z = 1 (closed form), and the crossing keeps
// its one edge-edge contact.
TEST(ContactDetection, EdgeEntranceAlsoGivesTheFarCornersWithinContactDistance) {
	const Block fixed = box(Vector3(0, 0, 0), Vector3(1, 1, 1));
	const Block centred = box(Vector3(-0.5, -0.5, -0.5), Vector3(0.5, 0.5, 0.5));
	const Matrix3 R = rotationAbout(Vector3(1, 1, 0), 0.004) * rotationAbout(Vector3::UnitZ(), 0.3);
	const Block turned = moved(centred, R, Vector3::Zero());
	const Vector3 lowest = *std::min_element(turned.vertices.begin(), turned.vertices.end(),
	                                         [](const Vector3& p, const Vector3& q) { return p.z() < q.z(); });
	const Block tilted = moved(turned, Matrix3::Identity(), Vector3(1.05, 0.3, 1.0) - lowest);
	const DetectionSettings s = settings(1e-2);
	const auto r = detect(fixed, tilted, s);
	ASSERT_TRUE(r.has_value());
	SCOPED_TRACE(describe(*r));
	EXPECT_EQ(r->entrance.kind, EntranceFeature::EdgePair);
	checkInvariants(*r, fixed, tilted, s);
	const int topFace = [&] {
		for (int f = 0; f < static_cast<int>(fixed.shape.faces.size()); ++f) {
			bool top = true;
			for (int v : fixed.shape.faces[f]) top = top && fixed.vertices[v].z() == 1.0;
			if (top) return f;
		}
		return -1;
	}();
	ASSERT_GE(topFace, 0);
	int expected = 0;
	for (int v = 0; v < static_cast<int>(tilted.vertices.size()); ++v) {
		const Vector3& p = tilted.vertices[v];
		if (p.z() - 1 > s.contactDistance || p.x() < 0 || p.x() > 1 || p.y() < 0 || p.y() > 1) continue;
		++expected;
		const auto found = std::find_if(r->contacts.begin(), r->contacts.end(), [&](const SubContact& c) {
			return c.kind == ContactKind::VertexFace && !c.firstIsA && c.feature1 == v && c.feature2 == topFace;
		});
		ASSERT_NE(found, r->contacts.end()) << "corner " << v << " at height " << p.z() - 1 << " has no contact";
		EXPECT_NEAR(found->gap, p.z() - 1, kRoundoff);
	}
	EXPECT_GE(expected, 1) << "the scene must have a far corner within d0";
	const auto& entrance = r->entrance;
	EXPECT_EQ(std::count_if(r->contacts.begin(), r->contacts.end(),
	                        [&](const SubContact& c) {
		                        return c.kind == ContactKind::EdgeEdge &&
		                               (c.firstIsA ? c.feature1 == entrance.feature && c.feature2 == entrance.other
		                                           : c.feature1 == entrance.other && c.feature2 == entrance.feature);
	                        }),
	          1);
	EXPECT_EQ(r->type, ContactType::FaceFace);
}
