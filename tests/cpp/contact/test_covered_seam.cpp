// A corner at the seam of two flush fixed blocks (OwnEntrance.cpp,
// insideCoveredSeam in ownEntranceContact), in closed form.
//
// The placement: a fixed floor N, [-1.5, 1.5] x [-1, 1.5] x [-h, 0], and a
// fixed wall W standing on it, [-1, 1] x [-0.4, 0] x [0, 2]: W's bottom face
// lies on N's top, covered whole (internal, markInternalFaces), and N reaches
// h below it everywhere (its cover depth, a closed form here: h). A free
// tetrahedron B has its lowest corner q at (x0, -e, -dz) and its other corners
// up and away from the wall (y > 0): q is e behind the plane of W's inner face
// G (y = 0, outward +y) and dz below the floor's top. For dz > 0.8 e the edges
// of B at q pass under W's bottom edge, so B and W alone do not overlap (the
// axis of that edge, an edge of an internal face, separates them by a few
// nm to a few mm), yet q is inside the fixed mass: inside N (0 < dz < h,
// under W). The fixed mass at q is held by both surfaces of the seam's
// concave corner: N's pair measures q along z, and W's pair must measure it
// along G's normal: a vertex-face contact of q on G with gap -e (the
// distance of q from G's plane, computed here from the placement). Without
// it, B's corner slid under W's edge through the floor's penalty layer (dz
// of a few nm at E = 1e11 Pa), rose into W with no force from W, and was
// found 175 um deep a few steps later (random hulls in a box, seed 2,
// dt 2.5e-4 s: 8.2e3 J in one step, a fifth of the run's largest energy
// change). One placement has q inside W (dz < 0) behind G by
// more than the pair's penetration (W's bottom, internal, is nearer): there
// too the contact is -e.
// And where q is outside the fixed mass, no contact: a floor thinner than dz
// (q below it), and a wedge-shaped neighbour under W that thins to nothing
// at W's inner edge (cover depth 0: q outside the wedge for dz > 1.25 e).
// And where q lies on the fixed mass's surface at a junction of fixed
// blocks, no contact deeper than the pair's overlap: a fixed tetrahedron T
// whose three side faces are each covered by a fixed frustum (a cut rock
// mass's block held among its held neighbours, only its base exposed), and
// a free block whose lowest corner rests on T's apex, within the contact
// distance of T's base. The corner is past no
// covered face and on every frustum's surface; measured against T's base, its
// only exposed face, it would take the tetrahedron's height as its depth.
// Each placement is turned by random rotations (seed printed), both orders.
// Units: m.
#include "TestScenes.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"
#include "dda/geometry/InternalFaces.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace {

using dda::ContactKind;
using dda::DetectionSettings;
using dda::PairContacts;
using dda::SubContact;
using dda::Vector3;
using Matrix3 = Eigen::Matrix3d;

constexpr double kLengthTolerance = 1e-9;  // [m]
constexpr double kRoundoff = 1e-12;        // [m], round-off of unit-sized coordinates
constexpr unsigned kSeed = 20261126;       // the random rotations'

using Solid = dda::testing::NarrowBlock;
using dda::testing::boxPoints;

// The convex hull of R p for the points p.
Solid makeSolid(const std::vector<Vector3>& points, const Matrix3& R) {
	std::vector<Vector3> turned;
	for (const Vector3& p : points) turned.push_back(R * p);
	return dda::testing::narrowBlock(turned);
}

// The wall on its neighbour, both marked by markInternalFaces (the core's own
// marking of fixed blocks): W's flags and cover depths.
Solid wallOn(const std::vector<Vector3>& neighbour, const Matrix3& R) {
	Solid wall = makeSolid(boxPoints({-1, -0.4, 0}, {1, 0, 2}), R);
	const Solid below = makeSolid(neighbour, R);
	std::vector<std::vector<char>> flags;
	std::vector<std::vector<dda::FaceCover>> covers;
	dda::markInternalFaces({{&wall.shape, &wall.vertices}, {&below.shape, &below.vertices}}, 1e-9, 1e-6, flags,
	                       &covers);
	wall.internal = flags[0];
	wall.cover = covers[0];
	return wall;
}

// B: its corner q at (x0, -e, -dz), the others up and away from the wall.
Solid tetrahedron(double x0, double e, double dz, const Matrix3& R) {
	const Vector3 q(x0, -e, -dz);
	return makeSolid({q, q + Vector3(0.3, 0.5, 0.4), q + Vector3(-0.3, 0.5, 0.4), q + Vector3(0.05, 0.3, 0.9)}, R);
}

DetectionSettings settings(double contactDistance = 0.01) {
	DetectionSettings s;
	s.contactDistance = contactDistance;
	s.lengthTolerance = kLengthTolerance;
	s.hysteresis = 0.001;
	return s;
}

std::vector<PairContacts> bothOrders(const Solid& wall, const Solid& block, double contactDistance = 0.01) {
	std::vector<PairContacts> out;
	for (const bool swap : {false, true}) {
		const auto r = swap ? dda::detectPairContacts(wall.geometry(), block.geometry(), settings(contactDistance))
		                    : dda::detectPairContacts(block.geometry(), wall.geometry(), settings(contactDistance));
		out.push_back(r ? *r : PairContacts{});
	}
	return out;
}

// q's sub-contacts: the vertex-face contacts of vertex q (pointI, block i's
// vertex).
std::vector<SubContact> cornerContacts(const PairContacts& r, const Vector3& q) {
	std::vector<SubContact> out;
	for (const SubContact& c : r.contacts)
		if (c.kind == ContactKind::VertexFace && (c.pointI - q).norm() < 1e-12) out.push_back(c);
	return out;
}

TEST(CoveredSeam, ACornerUnderAWallInsideTheFloorIsHeldByTheWallsInnerFace) {
	std::printf("CoveredSeam: random rotations of seed %u\n", kSeed);
	for (const Matrix3& R : dda::testing::sceneRotations(kSeed, 4)) {
		const Solid wall = wallOn(boxPoints({-1.5, -1, -0.5}, {1.5, 1.5, 0}), R);
		int covered = 0;
		for (std::size_t f = 0; f < wall.internal.size(); ++f) {
			if (!wall.internal[f]) continue;
			++covered;
			EXPECT_NEAR(wall.cover[f].depth, 0.5, kRoundoff) << "the floor's thickness under the wall";
		}
		ASSERT_EQ(covered, 1);
		const Vector3 inward = R * Vector3::UnitY();  // G's outward normal
		for (const auto& [x0, e, dz] : {std::array<double, 3>{0.3, 2e-8, 5e-8}, std::array<double, 3>{-0.6, 1e-4, 3e-4},
		                                std::array<double, 3>{0.1, 2e-3, 3e-3}, std::array<double, 3>{0.7, 7.3e-5, -2e-5}}) {
			std::ostringstream trace;
			trace << "rotation\n" << R << "\nx0 " << x0 << ", e " << e << ", dz " << dz;
			SCOPED_TRACE(trace.str());
			const Solid block = tetrahedron(x0, e, dz, R);
			const Vector3 q = R * Vector3(x0, -e, -dz);
			for (const PairContacts& r : bothOrders(wall, block)) {
				SCOPED_TRACE(dda::testing::describePair(r));
				const std::vector<SubContact> atQ = cornerContacts(r, q);
				ASSERT_EQ(atQ.size(), 1u) << "the corner in the fixed mass has no contact with the wall";
				EXPECT_NEAR(atQ[0].gap, -e, kRoundoff);
				EXPECT_NEAR(std::abs(atQ[0].normal.dot(inward)), 1, kRoundoff);
				for (const SubContact& c : r.contacts) EXPECT_GE(c.gap, -e - kLengthTolerance);
			}
		}
	}
}

TEST(CoveredSeam, ACornerOutsideTheFixedMassHasNoCompressedContactWithTheWall) {
	std::printf("CoveredSeam: random rotations of seed %u\n", kSeed);
	for (const Matrix3& R : dda::testing::sceneRotations(kSeed, 4)) {
		// A floor 2e-4 thick, the corner 3e-4 below its top: under it.
		const Solid onThin = wallOn(boxPoints({-1.5, -1, -2e-4}, {1.5, 1.5, 0}), R);
		// A wedge under the wall, 0.5 thick at y = -0.4 and none at y = 0
		// (cover depth 0): the corner, dz = 3 e below, is outside it.
		const Solid onWedge = wallOn({{-1, -0.4, 0}, {1, -0.4, 0}, {-1, 0, 0}, {1, 0, 0}, {-1, -0.4, -0.5},
		                              {1, -0.4, -0.5}},
		                             R);
		for (const Solid* wall : {&onThin, &onWedge}) {
			for (std::size_t f = 0; f < wall->internal.size(); ++f)
				if (wall->internal[f] && wall == &onWedge) EXPECT_EQ(wall->cover[f].depth, 0.0) << "the wedge thins to nothing";
			const double e = 1e-4, dz = 3e-4;
			std::ostringstream trace;
			trace << "rotation\n" << R << (wall == &onThin ? "\nthin floor" : "\nwedge");
			SCOPED_TRACE(trace.str());
			const Solid block = tetrahedron(0.2, e, dz, R);
			const Vector3 q = R * Vector3(0.2, -e, -dz);
			for (const PairContacts& r : bothOrders(*wall, block)) {
				SCOPED_TRACE(dda::testing::describePair(r));
				for (const SubContact& c : cornerContacts(r, q)) EXPECT_GE(c.gap, -kLengthTolerance);
			}
		}
	}
}

TEST(CoveredSeam, ACornerOnTheApexOfAHeldTetrahedronHasNoContactBeyondTheOverlap) {
	std::printf("CoveredSeam: random rotations of seed %u\n", kSeed);
	// T is flat (0.03 m high, 2 m wide), the contact distance 0.1 m: the apex
	// is within reach of T's base, as in a rock mass cut at 1 m with a
	// contact distance of a few cm.
	const Vector3 apex(0.1, 0.2, 0.03);
	const std::vector<Vector3> base{{-1, -0.8, 0}, {1.1, -0.6, 0}, {-0.2, 1, 0}};
	for (const Matrix3& R : dda::testing::sceneRotations(kSeed, 5)) {
		Solid held = makeSolid({base[0], base[1], base[2], apex}, R);
		// Each side face extruded 0.5 m outwards into a frustum widening by
		// 0.3 of the face's size: a block covering the face whole, 0.5 m deep
		// over it (its sides lean outwards).
		std::vector<Solid> covers3;
		const Vector3 inside = R * ((base[0] + base[1] + base[2] + apex) / 4);
		for (int k = 0; k < 3; ++k) {
			const Vector3 a = R * base[k], b = R * base[(k + 1) % 3], c = R * apex;
			Vector3 n = (b - a).cross(c - a).normalized();
			if (n.dot(a - inside) < 0) n = -n;
			const Vector3 m = (a + b + c) / 3;
			auto top = [&](const Vector3& p) -> Vector3 { return p + 0.5 * n + 0.3 * (p - m); };
			covers3.push_back(dda::testing::narrowBlock({a, b, c, top(a), top(b), top(c)}));
		}
		std::vector<dda::PlacedPolyhedron> fixed{{&held.shape, &held.vertices}};
		for (const Solid& p : covers3) fixed.push_back({&p.shape, &p.vertices});
		std::vector<std::vector<char>> flags;
		std::vector<std::vector<dda::FaceCover>> covers;
		dda::markInternalFaces(fixed, 1e-9, 1e-6, flags, &covers);
		held.internal = flags[0];
		held.cover = covers[0];
		int covered = 0;
		for (std::size_t f = 0; f < held.internal.size(); ++f) {
			if (!held.internal[f]) continue;
			++covered;
			EXPECT_NEAR(held.cover[f].depth, 0.5, kRoundoff) << "the frustum's height over the face";
		}
		ASSERT_EQ(covered, 3) << "every side face is covered, the base is exposed";
		// A tetrahedron standing on its lowest corner, the apex, above T.
		const Solid block = makeSolid({apex, apex + Vector3(0.3, 0.1, 0.5), apex + Vector3(-0.2, 0.25, 0.5),
		                               apex + Vector3(-0.1, -0.3, 0.5)},
		                              R);
		std::ostringstream trace;
		trace << "rotation\n" << R;
		SCOPED_TRACE(trace.str());
		for (const PairContacts& r : bothOrders(held, block, 0.1)) {
			SCOPED_TRACE(dda::testing::describePair(r));
			for (const SubContact& c : r.contacts) EXPECT_GE(c.gap, -kLengthTolerance) << "the blocks only touch";
		}
	}
}

}  // namespace
