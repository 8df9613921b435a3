// An edge entrance whose edge runs on across a face at the other entrance
// edge (EdgeEntrance.cpp, crossingsAcrossEntranceFaces), in closed form: the
// second crossing of that edge with the face's boundary is a sub-contact of
// the pair while it is within d0, with the two lines' distance as its gap.
//
// The placement: a fixed square pyramid, apex (0, 0, 1), base corners
// (+-1, +-1, 0); its face F through the apex and (1, +-1, 0) has the outward
// normal n = (1, 0, 1)/sqrt(2) and the edges e1 (apex to (1, 1, 0)) and e4
// (apex to (1, -1, 0)). A thin tetrahedron (a "knife") lies with its edge b
// across F near the apex: b crosses e1 at height h1 above F (along n) and
// rises away from F towards e4 (direction -y + r n, r > 0), so it crosses e4
// further up; beyond e1 it runs on over the neighbouring face and dips below
// F's plane there, outside the pyramid. The pair's closest features are e1
// and b (the entrance is their edge pair: the knife's low end makes F's own
// axis separate the pair less, and the best face is not F), and the knife
// touches along b over F: the crossing of b with e4 is the edge-on-face
// contact's second point. Without it the knife turns about the first crossing
// and drives b through e4 within a step (random convex hulls at E = 1e11 Pa:
// the second crossing was found first 0.88 mm deep, with 4.0e5 J in its
// spring; doc/benchmarks.md, "Energy of random hulls").
// Oracle: the distance of two skew lines, |(q - p) . (u x v)| / |u x v|, with
// both closest points inside both segments (computed here, independently of
// the narrow phase). The scene is also turned by random rotations (seed
// printed) and given in both orders. Units: m.
#include "TestScenes.hpp"
#include "dda/contact/PairDetection.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using dda::ContactKind;
using dda::DetectionSettings;
using dda::SubContact;
using dda::Vector3;
using Matrix3 = Eigen::Matrix3d;

constexpr unsigned kSeed = 20261126;  // the random rotations'

using Block = dda::testing::NarrowBlock;

// The edge of `b` joining corners p and q (given as points), -1 when none.
int edgeBetween(const Block& b, const Vector3& p, const Vector3& q) {
	for (std::size_t e = 0; e < b.shape.edges.size(); ++e) {
		const Vector3& u = b.vertices[b.shape.edges[e][0]];
		const Vector3& v = b.vertices[b.shape.edges[e][1]];
		if (((u - p).norm() < 1e-12 && (v - q).norm() < 1e-12) || ((u - q).norm() < 1e-12 && (v - p).norm() < 1e-12))
			return static_cast<int>(e);
	}
	return -1;
}

// Distance of segments p0p1 and q0q1 whose lines' closest points lie strictly
// inside both (asserted).
double skewDistance(const Vector3& p0, const Vector3& p1, const Vector3& q0, const Vector3& q1) {
	const Vector3 u = p1 - p0, v = q1 - q0, w = q0 - p0;
	const Vector3 n = u.cross(v);
	const double nn = n.squaredNorm();
	const double s = w.cross(v).dot(n) / nn, t = w.cross(u).dot(n) / nn;
	EXPECT_GT(s, 1e-3);
	EXPECT_LT(s, 1 - 1e-3);
	EXPECT_GT(t, 1e-3);
	EXPECT_LT(t, 1 - 1e-3);
	return std::abs(w.dot(n)) / std::sqrt(nn);
}

// (h1: b's height above F at e1 [m]; r: its rise towards e4 per unit length
// [-]; c: where it crosses e1, the point c (1, 1, -1) from the apex [m].)
TEST(EdgeEntrance, AnEdgeAcrossAFaceAtTheOtherEdgeHasItsSecondCrossing) {
	const double d0 = 0.02;
	DetectionSettings s;
	s.contactDistance = d0;
	s.lengthTolerance = 1e-8;
	s.hysteresis = 0.1 * d0;
	std::printf("EdgeEntrance: random rotations of seed %u\n", kSeed);
	const Vector3 n = Vector3(1, 0, 1).normalized();
	struct Case {
		double h1, r, c;
	};
	for (const Case& k : {Case{0.002, 1.0, 0.005}, Case{0.002, 0.5, 0.005}, Case{0.002, 0.3, 0.01}}) {
		// b: through the point h1 above e1's point c (1, 1, -1) from the apex,
		// direction -y + r n; 0.3 m beyond e1, 0.03 m beyond e4.
		const Vector3 onE1 = Vector3(0, 0, 1) + k.c * Vector3(1, 1, -1);
		const Vector3 p = onE1 + k.h1 * n;
		const Vector3 d = (Vector3(0, -1, 0) + k.r * n).normalized();
		const Vector3 b0 = p - 0.3 * d, b1 = p + (2 * k.c + 0.03) * d;
		const Vector3 mid = 0.5 * (b0 + b1), side = n.cross(d);
		const Vector3 apex(0, 0, 1), e1End(1, 1, 0), e4End(1, -1, 0);
		const std::vector<Vector3> pyramid{apex, e1End, {-1, 1, 0}, {-1, -1, 0}, e4End};
		const std::vector<Vector3> knife{b0, b1, mid + 0.3 * n + 0.15 * side, mid + 0.3 * n - 0.15 * side};
		const double firstGap = skewDistance(apex, e1End, b0, b1);
		const double secondGap = skewDistance(apex, e4End, b0, b1);
		ASSERT_LT(firstGap, secondGap);
		ASSERT_LT(secondGap, d0);
		for (const Matrix3& R : dda::testing::sceneRotations(kSeed, 3)) {
			std::vector<Vector3> P, K;
			for (const Vector3& x : pyramid) P.push_back(R * x);
			for (const Vector3& x : knife) K.push_back(R * x);
			const Block A = dda::testing::narrowBlock(P), B = dda::testing::narrowBlock(K);
			const int e1 = edgeBetween(A, R * apex, R * e1End), e4 = edgeBetween(A, R * apex, R * e4End);
			const int eb = edgeBetween(B, R * b0, R * b1);
			ASSERT_GE(e1, 0);
			ASSERT_GE(e4, 0);
			ASSERT_GE(eb, 0);
			for (const bool swap : {false, true}) {
				const auto r = swap ? dda::detectPairContacts(B.geometry(), A.geometry(), s)
				                    : dda::detectPairContacts(A.geometry(), B.geometry(), s);
				ASSERT_TRUE(r.has_value());
				const std::string what = dda::testing::describePair(*r);
				// The placement is the one meant: the entrance is the edge pair
				// (e1, b), at the lines' distance.
				ASSERT_EQ(r->entrance.kind, dda::EntranceFeature::EdgePair) << what;
				EXPECT_NEAR(r->separation, firstGap, 1e-12) << what;
				// The second crossing: b against e4, the lines' distance as its
				// gap, its normal along e4 x b.
				const Vector3 axis = (R * (e4End - apex)).cross(R * (b1 - b0)).normalized();
				int found = 0;
				for (const SubContact& c : r->contacts) {
					if (c.kind != ContactKind::EdgeEdge) continue;
					const bool bIsI = c.firstIsA == swap;  // block i is the knife
					const int edgeOfA = bIsI ? c.feature2 : c.feature1, edgeOfB = bIsI ? c.feature1 : c.feature2;
					if (edgeOfA != e4 || edgeOfB != eb) continue;
					++found;
					EXPECT_NEAR(c.gap, secondGap, 1e-12) << what;
					EXPECT_NEAR(std::abs(c.normal.dot(axis)), 1.0, 1e-12) << what;
				}
				EXPECT_EQ(found, 1) << "h1 " << k.h1 << " r " << k.r << " c " << k.c << ": " << what;
				// And nothing deeper than the pair is apart (it does not overlap).
				for (const SubContact& c : r->contacts) EXPECT_GT(c.gap, 0.0) << what;
			}
		}
	}
}

}  // namespace
