// Tests of the narrow phase's rules for internal faces (a face covered whole
// by a flush fixed neighbour, or shared with another part of a concave block:
// BlockGeometry::internalFaces), each in a closed-form placement where that
// rule alone decides the pair's sub-contacts: the pair overlaps by a known
// depth e, so the depth bound (no sub-contact deeper than the pair's
// penetration, OwnEntrance.cpp) keeps every sub-contact the rule is about.
//   - A face facing an internal face of the other block is no entrance
//     (facesInternal, SeparatingAxes.cpp): a cube on the seam of a two-part
//     slab.
//   - A corner more than d0 across an internal face gets no contact from the
//     block (ownEntranceContact, OwnEntrance.cpp): a slab over the ridge of a
//     wedge-shaped part whose sloping face is covered.
//   - A corner beyond two internal faces and beyond the exposed face's
//     polygon gets no contact (the ridge rule of ownEntranceContact): a slab
//     past the covered corner of a floor block.
// Each placement is also turned by random rotations of the whole scene (seed
// printed): the closed forms are invariant, the narrow phase must be too.
// Units: m.
#include "TestScenes.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using dda::ContactKind;
using dda::DetectionSettings;
using dda::PairContacts;
using dda::SubContact;
using dda::Vector3;
using Matrix3 = Eigen::Matrix3d;

constexpr double kLengthTolerance = 1e-8;  // [m]
constexpr double kRoundoff = 1e-12;        // [m], round-off of unit-sized coordinates
constexpr unsigned kSeed = 20251126;       // the random rotations'

// A block as the narrow phase sees it, with its internal faces.
struct Block {
	dda::ConvexPolyhedron shape;
	std::vector<Vector3> vertices;
	Vector3 centroid = Vector3::Zero();
	std::vector<char> internal;
	dda::BlockGeometry geometry() const {
		bool any = false;
		for (char c : internal) any = any || c;
		return {&shape, &vertices, centroid, any ? &internal : nullptr};
	}
	Vector3 outwardNormal(int f) const { return dda::faceNormal(vertices, shape.faces[f]); }
};

// The convex hull of R p for the points p, its faces whose outward normal is
// R n for one of `covered` (unit n) marked internal.
Block makeBlock(const std::vector<Vector3>& points, const Matrix3& R, const std::vector<Vector3>& covered = {}) {
	std::vector<Vector3> turned;
	for (const Vector3& p : points) turned.push_back(R * p);
	Block b;
	b.shape = dda::buildConvexPolyhedron(turned);
	b.vertices = b.shape.vertices;
	for (const Vector3& p : turned) b.centroid += p;
	b.centroid /= static_cast<double>(turned.size());
	b.internal.assign(b.shape.faces.size(), 0);
	for (std::size_t f = 0; f < b.shape.faces.size(); ++f)
		for (const Vector3& n : covered)
			if (b.outwardNormal(static_cast<int>(f)).dot(R * n) > 1 - 1e-9) b.internal[f] = 1;
	return b;
}

using dda::testing::boxPoints;

std::vector<Matrix3> rotations(int count) { return dda::testing::sceneRotations(kSeed, count); }

DetectionSettings settings(double d0) {
	DetectionSettings s;
	s.contactDistance = d0;
	s.lengthTolerance = kLengthTolerance;
	s.hysteresis = 0.1 * d0;
	return s;
}

std::string describe(const PairContacts& r) { return dda::testing::describePair(r); }

// A free cube (0.5 m) on a free slab of two parts, [0, 2] x [0, 1] x [0, 0.5]
// and [2, 4] x [0, 1] x [0, 0.5], sharing the face x = 2 (internal to both),
// the cube sunk e into the slab's top, its front face x = xf near the seam:
// before it (within d0), just past it (by less and by more than e), and well
// past it. Closed form: the slab's top z = 0.5 is the only surface the cube
// touches; the seam lies inside the slab. So the cube's overlap with the slab
// is the layer 0.5 - e < z < 0.5 under its bottom, pushed out along z only:
// every sub-contact of either part has a normal along z, none a component
// along the seam's normal x (which would stop or throw a cube sliding over
// the seam), and none is deeper than e; and the two parts together measure
// the overlap (a sub-contact of gap -e).
// The cube's front face x = xf is opposed to the second part's internal face
// x = 2 (the two axes tie: both are the blocks' projected separation along
// x), and from d0 before the seam to e past it (xf - 2 < e) that axis
// separates the pair the most: taken as the entrance, it measured the second part's seam edge across it (an edge-edge
// contact with normal x, gap 2 - xf, before the seam as after it).
TEST(InternalFaceRules, ACubeOnTheSeamOfATwoPartSlabIsPushedOnlyAlongTheSlabsNormal) {
	const double d0 = 0.01;
	const DetectionSettings s = settings(d0);
	std::printf("InternalFaceRules: random rotations of seed %u\n", kSeed);
	for (const Matrix3& R : rotations(3)) {
		const Block first = makeBlock(boxPoints({0, 0, 0}, {2, 1, 0.5}), R, {Vector3::UnitX()});
		const Block second = makeBlock(boxPoints({2, 0, 0}, {4, 1, 0.5}), R, {-Vector3::UnitX()});
		ASSERT_EQ(std::count(first.internal.begin(), first.internal.end(), 1), 1);
		ASSERT_EQ(std::count(second.internal.begin(), second.internal.end(), 1), 1);
		const Vector3 up = R * Vector3::UnitZ();
		for (const double xf : {1.995, 1.9995, 2.0005, 2.002, 2.02})
			for (const double e : {1e-4, 3e-3}) {
				std::ostringstream trace;
				trace << "rotation\n" << R << "\nxf " << xf << ", e " << e;
				SCOPED_TRACE(trace.str());
				const Block cube = makeBlock(boxPoints({xf - 0.5, 0.25, 0.5 - e}, {xf, 0.75, 1 - e}), R);
				double lowest = 1;
				for (const Block* part : {&first, &second})
					for (const bool swap : {false, true}) {
						const auto r = swap ? dda::detectPairContacts(part->geometry(), cube.geometry(), s)
						                    : dda::detectPairContacts(cube.geometry(), part->geometry(), s);
						if (!r) continue;
						SCOPED_TRACE(std::string(part == &first ? "first part" : "second part") +
						             (swap ? ", part first: " : ", cube first: ") + describe(*r));
						for (const SubContact& c : r->contacts) {
							EXPECT_NEAR(std::abs(c.normal.dot(up)), 1, kRoundoff) << "a push along the seam";
							EXPECT_GE(c.gap, -e - kLengthTolerance);
							lowest = std::min(lowest, c.gap);
						}
					}
				EXPECT_NEAR(lowest, -e, kRoundoff) << "the overlap of the cube and the slab is not measured";
			}
	}
}

// A fixed wedge-shaped block W whose top face z = 0 (x in [0, 0.5]) meets its
// sloping face at 45 degrees along the ridge x = z = 0: cross-section (x, z)
// (0, 0), (0.5, 0), (0.5, -0.2), (0.2, -0.2), y in [0, 1]. The sloping face,
// outward normal (-1, 0, -1) / sqrt(2), is covered by a fixed neighbour
// (internal); that neighbour's top continues W's top past the ridge (a flat
// floor). A free slab [qx, 1] x [0.2, 0.8] x [-e, 0.3] lies on the floor
// sunk e, its bottom face (larger than W's top) the pair's entrance, its
// corners (qx, 0.2 or 0.8, -e) beyond the ridge. Closed form: the pair
// overlaps by e (the slab's bottom against W's top; every other axis is
// deeper); such a corner lies outside W, sqrt(qx^2 + e^2) from W's ridge
// when qx + e < 0, else (e - qx) / sqrt(2) from the sloping face, and that
// is more than d0 for the placements below: no contact of the pair at it (d0 is the contact
// distance), though it lies below W's top plane, within d0 of W's top in
// projection, no deeper than the overlap. The pair's sub-contacts are then
// exactly the four crossings of W's top edges x = 0 and x = 0.5 with the
// slab's bottom edges y = 0.2 and y = 0.8, each of gap -e along z. The
// corner is the neighbour's contact, which measures it through its own faces.
// Before the corner's distance across internal faces counted, it took
// gap -e against W's top.
TEST(InternalFaceRules, ACornerMoreThanContactDistanceAcrossAnInternalFaceHasNoContact) {
	const double d0 = 0.01;
	const DetectionSettings s = settings(d0);
	const std::vector<Vector3> wedge = {{0, 0, 0},     {0.5, 0, 0},     {0.5, 0, -0.2}, {0.2, 0, -0.2},
	                                    {0, 1, 0},     {0.5, 1, 0},     {0.5, 1, -0.2}, {0.2, 1, -0.2}};
	const Vector3 slope = Vector3(-1, 0, -1).normalized();
	std::printf("InternalFaceRules: random rotations of seed %u\n", kSeed);
	for (const Matrix3& R : rotations(3)) {
		const Block W = makeBlock(wedge, R, {slope});
		ASSERT_EQ(std::count(W.internal.begin(), W.internal.end(), 1), 1);
		const Vector3 up = R * Vector3::UnitZ();
		for (const auto& [qx, e] : {std::pair{-0.9 * d0, 0.6 * d0}, std::pair{-0.7 * d0, 0.9 * d0}, std::pair{-0.99 * d0, 0.45 * d0}}) {
			// The corner's distance from W: from the ridge, or from the sloping
			// face when its foot on that face's line lies past the ridge.
			const double apart = qx + e < 0 ? std::hypot(qx, e) : (e - qx) / std::sqrt(2.0);
			ASSERT_GT(apart, d0 + kLengthTolerance);
			std::ostringstream trace;
			trace << "rotation\n" << R << "\nqx " << qx << ", e " << e;
			SCOPED_TRACE(trace.str());
			const Block slab = makeBlock(boxPoints({qx, 0.2, -e}, {1, 0.8, 0.3}), R);
			for (const bool swap : {false, true}) {
				const auto r = swap ? dda::detectPairContacts(W.geometry(), slab.geometry(), s)
				                    : dda::detectPairContacts(slab.geometry(), W.geometry(), s);
				ASSERT_TRUE(r.has_value());
				SCOPED_TRACE(std::string(swap ? "wedge first: " : "slab first: ") + describe(*r));
				EXPECT_NEAR(r->separation, -e, kRoundoff);
				ASSERT_EQ(r->contacts.size(), 4u);
				for (const SubContact& c : r->contacts) {
					EXPECT_EQ(c.kind, ContactKind::EdgeEdge);
					EXPECT_NEAR(c.gap, -e, kRoundoff);
					EXPECT_NEAR(std::abs(c.normal.dot(up)), 1, kRoundoff);
					const Vector3 p = R.transpose() * c.pointI;  // the crossing, unturned
					EXPECT_TRUE(std::abs(p.x()) < 1e-9 || std::abs(p.x() - 0.5) < 1e-9) << p.transpose();
					EXPECT_TRUE(std::abs(p.y() - 0.2) < 1e-9 || std::abs(p.y() - 0.8) < 1e-9) << p.transpose();
				}
			}
		}
	}
}

// A fixed floor block C = [0, 1] x [0, 1] x [-1, 0] whose faces x = 0 and
// y = 0 are covered by fixed neighbours (internal; a third neighbour fills
// the quadrant x < 0, y < 0: a flat floor around C's corner (0, 0, 0)). A
// free slab [-a, 1.5] x [-a, 1.5] x [-e, 0.3] lies on the floor sunk e, its
// bottom face (larger than C's top) the pair's entrance, its corner
// (-a, -a, -e) past C's covered corner, a + e within d0. Closed form: the
// pair overlaps by e; the corner lies outside C, a sqrt(2) from C's vertical
// edge x = y = 0, inside the third neighbour: no overlap of the slab with C
// is there, so no contact of the pair at it may be compressed (a gap below
// -lengthTolerance), though it lies e below C's top plane, within d0 of C's
// top in projection, no deeper than the overlap. The pair's sub-contacts are
// then exactly C's four top corners against the slab's bottom, each of gap
// -e along z. (Beyond one covered face only, a corner at a flush seam within
// d0 is held by both blocks of the seam by design: the hand-over of a block
// sliding across it, tests/py/contact/test_flush_joint.py.)
// Without the rule the corner took gap -e against C's top, a fourth spring
// for one corner of the slab beside those of the three neighbours.
TEST(InternalFaceRules, ACornerPastACoveredCornerOfAFloorBlockHasNoCompressedContact) {
	const double d0 = 0.01;
	const DetectionSettings s = settings(d0);
	std::printf("InternalFaceRules: random rotations of seed %u\n", kSeed);
	for (const Matrix3& R : rotations(3)) {
		const Block C = makeBlock(boxPoints({0, 0, -1}, {1, 1, 0}), R, {-Vector3::UnitX(), -Vector3::UnitY()});
		ASSERT_EQ(std::count(C.internal.begin(), C.internal.end(), 1), 2);
		const Vector3 up = R * Vector3::UnitZ();
		for (const auto& [a, e] : {std::pair{0.2 * d0, 0.1 * d0}, std::pair{0.2 * d0, 0.5 * d0}, std::pair{0.4 * d0, 0.5 * d0}}) {
			ASSERT_LE(a + e, d0);  // the corner within d0 across each covered face
			std::ostringstream trace;
			trace << "rotation\n" << R << "\na " << a << ", e " << e;
			SCOPED_TRACE(trace.str());
			const Block slab = makeBlock(boxPoints({-a, -a, -e}, {1.5, 1.5, 0.3}), R);
			for (const bool swap : {false, true}) {
				const auto r = swap ? dda::detectPairContacts(C.geometry(), slab.geometry(), s)
				                    : dda::detectPairContacts(slab.geometry(), C.geometry(), s);
				ASSERT_TRUE(r.has_value());
				SCOPED_TRACE(std::string(swap ? "floor block first: " : "slab first: ") + describe(*r));
				EXPECT_NEAR(r->separation, -e, kRoundoff);
				ASSERT_EQ(r->contacts.size(), 4u);
				for (const SubContact& c : r->contacts) {
					EXPECT_EQ(c.kind, ContactKind::VertexFace);
					EXPECT_NEAR(c.gap, -e, kRoundoff);
					EXPECT_NEAR(std::abs(c.normal.dot(up)), 1, kRoundoff);
					// The corner is C's (at its top, z = 0), not the slab's.
					EXPECT_NEAR((R.transpose() * c.pointI).z(), 0, 1e-9);
				}
			}
		}
	}
}

}  // namespace
