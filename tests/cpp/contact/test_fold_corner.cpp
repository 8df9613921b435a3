// A corner of the entering block over a face beside the entrance face
// (FaceEntrance.cpp, faceEntranceContacts: corners within d0 of the entrance
// face's plane but outside its projection window, measured against their own
// entrance face), in closed form: the corner has a vertex-face contact with
// that face, its distance from the face's plane as the gap, while within d0.
//
// The placement: a fixed "roof" A, base [-1, 1]^2 at z = 0, its top two faces
// meeting at a ridge along y at x = 0, z = 1, sloping down by s: F1 (x <= 0)
// on the plane z = 1 + s x, outward normal n1 = (-s, 0, 1)/sqrt(1 + s^2), and
// F2 (x >= 0) on z = 1 - s x, n2 = (s, 0, 1)/sqrt(1 + s^2): a nearly planar
// top split at a shallow fold, as random hulls have. A tetrahedron B lies
// across the ridge: its corner Q h1 above F1 at x = -xq (the pair's closest
// feature, so F1 is the entrance) and its corner P g above F2 at x = L, more
// than d0 past the ridge (outside F1's projection window, as seen along F1's
// plane), with g < d0; its other two corners are high above. B rocks about Q
// onto F2 and P comes down on it; with no open contact there P went into A
// unopposed within a step (random hulls: a corner 0.65 m from the entrance's
// contacts, within d0 of the face beside it for 12 steps, found first
// 0.34 mm deep at E = 1e11 Pa, 3.3e4 J in one step; another 0.46 mm deep
// at 1e9 Pa, 690 J; measured with bench/energy.py --hulls).
// Oracle: P's distance from F2's plane, n2 . (P - ridge point), which is g
// by construction (computed here, independently of the narrow phase). The
// scene is also turned by random rotations (seed printed) and given in both
// orders. Units: m.
#include "TestScenes.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using dda::ContactKind;
using dda::DetectionSettings;
using dda::PairContacts;
using dda::SubContact;
using dda::Vector3;
using Matrix3 = Eigen::Matrix3d;

constexpr unsigned kSeed = 20261126;  // the random rotations'

using Block = dda::testing::NarrowBlock;

using dda::testing::faceWith;
using dda::testing::vertexAt;

Block makeBlock(const std::vector<Vector3>& points) { return dda::testing::narrowBlock(points); }

std::vector<Matrix3> rotations(int count) { return dda::testing::sceneRotations(kSeed, count); }

std::string describe(const PairContacts& r) { return dda::testing::describePair(r); }

// (s: the fold's slope [-]; L: P's distance past the ridge [m]; g: P's height
// above F2 [m]; h1: Q's height above F1 [m]; xq: Q's distance before the
// ridge [m].)
TEST(FoldCorner, ACornerOverTheFaceBesideTheEntranceHasItsContact) {
	const double d0 = 0.02;
	DetectionSettings settings;
	settings.contactDistance = d0;
	settings.lengthTolerance = 1e-8;
	settings.hysteresis = 0.1 * d0;
	std::printf("FoldCorner: random rotations of seed %u\n", kSeed);
	struct Case {
		double s, L, g, h1, xq;
	};
	for (const Case& k : {Case{0.02, 0.3, 0.018, 0.001, 0.3}, Case{0.05, 0.1, 0.015, 0.0005, 0.2},
	                      Case{0.01, 0.5, 0.016, 0.002, 0.4}}) {
		const double root = std::sqrt(1 + k.s * k.s);
		const Vector3 n1 = Vector3(-k.s, 0, 1) / root, n2 = Vector3(k.s, 0, 1) / root;
		const Vector3 ridge0(0, -1, 1), ridge1(0, 1, 1), eave0(1, -1, 1 - k.s), eave1(1, 1, 1 - k.s);
		const std::vector<Vector3> roof{{-1, -1, 0},      {1, -1, 0},       {1, 1, 0}, {-1, 1, 0}, ridge0, ridge1,
		                                {-1, -1, 1 - k.s}, {-1, 1, 1 - k.s}, eave0,     eave1};
		const Vector3 Q = Vector3(-k.xq, 0, 1 - k.s * k.xq) + k.h1 * n1;
		const Vector3 P = Vector3(k.L, 0, 1 - k.s * k.L) + k.g * n2;
		const double midX = 0.5 * (k.L - k.xq);
		const std::vector<Vector3> tetra{Q, P, {midX, 0.3, 1.3}, {midX, -0.3, 1.3}};
		// The oracle, and that the placement is the one meant: P within d0 of
		// F2, above F1's plane by more than Q (F1 the entrance at Q's height),
		// and more than d0 past the ridge.
		const double gap = n2.dot(P - Vector3(0, 0, 1));
		const double aboveF1 = n1.dot(P - Vector3(0, 0, 1));
		ASSERT_NEAR(gap, k.g, 1e-15);
		ASSERT_LT(gap, d0);
		ASSERT_GT(aboveF1, 2 * k.h1);
		ASSERT_GT(k.L, 2 * d0);
		for (const Matrix3& R : rotations(3)) {
			std::vector<Vector3> Ar, Br;
			for (const Vector3& x : roof) Ar.push_back(R * x);
			for (const Vector3& x : tetra) Br.push_back(R * x);
			const Block A = makeBlock(Ar), B = makeBlock(Br);
			const int f1 = faceWith(A, {R * ridge0, R * ridge1, R * Vector3(-1, 1, 1 - k.s)});
			const int f2 = faceWith(A, {R * ridge0, R * ridge1, R * eave0, R * eave1});
			const int p = vertexAt(B, R * P);
			ASSERT_GE(f1, 0);
			ASSERT_GE(f2, 0);
			ASSERT_GE(p, 0);
			for (const bool swap : {false, true}) {
				const auto r = swap ? dda::detectPairContacts(B.geometry(), A.geometry(), settings)
				                    : dda::detectPairContacts(A.geometry(), B.geometry(), settings);
				ASSERT_TRUE(r.has_value());
				const std::string what = describe(*r);
				// The pair is Q's height apart, along F1's normal.
				EXPECT_NEAR(r->separation, k.h1, 1e-12) << what;
				EXPECT_NEAR(std::abs(r->normal.dot(R * n1)), 1.0, 1e-9) << what;
				// P against F2: its distance from F2's plane, along F2's normal.
				int found = 0;
				for (const SubContact& c : r->contacts) {
					if (c.kind != ContactKind::VertexFace) continue;
					const bool bIsI = c.firstIsA == swap;  // block i is the tetrahedron
					if (!bIsI || c.feature1 != p) continue;
					++found;
					EXPECT_EQ(c.feature2, f2) << what;
					EXPECT_NEAR(c.gap, gap, 1e-12) << what;
					EXPECT_NEAR(c.normal.dot(R * n2), 1.0, 1e-12) << what;
				}
				EXPECT_EQ(found, 1) << "s " << k.s << " L " << k.L << " g " << k.g << ": " << what;
				// Nothing deeper than the pair is apart (it does not overlap).
				for (const SubContact& c : r->contacts) EXPECT_GT(c.gap, 0.0) << what;
			}
		}
	}
}

}  // namespace
