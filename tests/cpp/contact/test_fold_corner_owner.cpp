// The fold rule's symmetric case in closed form: a corner of the block that
// owns the entrance face, not on that face, over a face of the other block
// (FaceEntrance.cpp, faceEntranceContacts). The corner has a vertex-face
// contact with that face, its distance from the block as the gap, while
// within d0.
//
// The placement: a fixed "roof" A, base [-1, L] x [-W, W] at z = 0, its top
// two faces meeting at a ridge along y at x = 0, z = 1: F1 (x <= 0) on the
// plane z = 1 + s x, outward normal n1 = (-s, 0, 1)/sqrt(1 + s^2), and F2
// (0 <= x <= L) on z = 1 - s x: a nearly planar top split at a shallow fold.
// Its corners P = (L, +-W, 1 - s L), F2's far corners, lie 2 s L / sqrt(1 +
// s^2) below F1's plane. A slab B (0.2 m thick, wider than A: |y| <= W +
// 0.1) lies over both faces, its bottom face G rising from F1's plane by t
// (a slope along F1, t > 0): G's lower edge (x = -xq along F1) is h above
// F1, inside F1's projection in x but 0.1 m beyond A's sides in y; G runs on
// past the fold to beyond x = L, over P. Closed form: F1 is the pair's
// entrance, h its separation (B's lowest corners along F1's normal are h
// above it; G's axis separates less, A's left corners lying below G by h - t
// (1 - xq) along F1, and F2's axis less, by 2 s xq), and the pair touches
// where G's lower edge crosses F1's sides. P lies below G, its projection on
// G inside G: its distance from B is its distance from G's plane,
// g = (h + t (xq + u) + v) / sqrt(1 + t^2) with (u, -v) P's coordinates
// along and below F1 from the ridge, and g < d0: a contact is due. B rocking
// about its lower edge brings G down onto P. The entering block's corners
// have their rules (F1's vertex-face contacts, the fold rule for corners
// beside F1); F1's own corners are measured against their own entrance face;
// P is neither. Oracle: P's distance from B, by brute force over B's faces
// (the distance to the nearest point of each face's triangles), computed here
// independently of the narrow phase; and that it equals P's signed distance
// from G's plane. The scene is also turned by random rotations (seed
// printed) and given in both orders. Units: m.
#include "TestScenes.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace {

using dda::ContactKind;
using dda::DetectionSettings;
using dda::PairContacts;
using dda::SubContact;
using dda::Vector3;
using Matrix3 = Eigen::Matrix3d;
using Block = dda::testing::NarrowBlock;

constexpr unsigned kSeed = 20261127;  // the random rotations'

using dda::testing::faceWith;
using dda::testing::vertexAt;

// The point of triangle (a, b, c) nearest x (Ericson, Real-Time Collision
// Detection, 5.1.5), by its Voronoi regions.
Vector3 nearestOnTriangle(const Vector3& x, const Vector3& a, const Vector3& b, const Vector3& c) {
	const Vector3 ab = b - a, ac = c - a, ax = x - a;
	const double d1 = ab.dot(ax), d2 = ac.dot(ax);
	if (d1 <= 0 && d2 <= 0) return a;
	const Vector3 bx = x - b;
	const double d3 = ab.dot(bx), d4 = ac.dot(bx);
	if (d3 >= 0 && d4 <= d3) return b;
	const double vc = d1 * d4 - d3 * d2;
	if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
	const Vector3 cx = x - c;
	const double d5 = ab.dot(cx), d6 = ac.dot(cx);
	if (d6 >= 0 && d5 <= d6) return c;
	const double vb = d5 * d2 - d1 * d6;
	if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
	const double va = d3 * d6 - d5 * d4;
	if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
	const double denominator = 1 / (va + vb + vc);
	return a + ab * (vb * denominator) + ac * (vc * denominator);
}

// The distance of x, outside the convex block b, from b: the nearest point of
// b's boundary, over every face's fan of triangles.
double distanceOutside(const Vector3& x, const Block& b) {
	double nearest = std::numeric_limits<double>::infinity();
	for (const std::vector<int>& face : b.shape.faces)
		for (std::size_t k = 1; k + 1 < face.size(); ++k)
			nearest = std::min(nearest, (x - nearestOnTriangle(x, b.vertices[face[0]], b.vertices[face[k]],
			                                                   b.vertices[face[k + 1]]))
			                                .norm());
	return nearest;
}

// (s: the fold's slope [-]; L: P's distance past the ridge along x [m]; h: G's
// lower edge above F1 [m]; t: G's slope along F1 [-]; xq: G's lower edge
// before the ridge along F1 [m].)
TEST(FoldCornerOwner, ACornerOfTheEntranceFacesBlockOverAFaceOfTheOtherHasItsContact) {
	const double d0 = 0.02, W = 0.3;
	DetectionSettings settings;
	settings.contactDistance = d0;
	settings.lengthTolerance = 1e-8;
	settings.hysteresis = 0.1 * d0;
	std::printf("FoldCornerOwner: random rotations of seed %u\n", kSeed);
	double worst = 0;  // the largest |gap - oracle| [m]
	struct Case {
		double s, L, h, t, xq;
	};
	for (const Case& k : {Case{0.01, 0.3, 0.001, 0.005, 0.3}, Case{0.02, 0.2, 0.0005, 0.002, 0.2},
	                      Case{0.005, 0.5, 0.002, 0.01, 0.4}}) {
		const double root = std::sqrt(1 + k.s * k.s);
		const Vector3 ridge(0, 0, 1), along = Vector3(1, 0, k.s) / root, n1 = Vector3(-k.s, 0, 1) / root;
		const Vector3 Y = Vector3::UnitY();
		const std::vector<Vector3> roof{{-1, -W, 0}, {k.L, -W, 0}, {k.L, W, 0}, {-1, W, 0}, {0, -W, 1}, {0, W, 1},
		                                {-1, -W, 1 - k.s}, {-1, W, 1 - k.s}, {k.L, -W, 1 - k.s * k.L},
		                                {k.L, W, 1 - k.s * k.L}};
		const Vector3 P(k.L, W, 1 - k.s * k.L);
		// B: G's corners at u = -xq and u = uR along F1 from the ridge, v = h +
		// t (u + xq) above it; the top 0.2 m above along n1.
		const double uR = k.L + 0.3;
		std::vector<Vector3> slab;
		for (const double u : {-k.xq, uR})
			for (const double y : {-W - 0.1, W + 0.1})
				for (const double up : {0.0, 0.2})
					slab.push_back(ridge + u * along + y * Y + (k.h + k.t * (u + k.xq) + up) * n1);
		const Vector3 g0 = slab[0], gAlong = slab[4] - slab[0];  // G's lower corner, G's rise
		const Vector3 nG = -gAlong.cross(Y).normalized();  // G's outward normal (down, towards A)
		// The placement is the one meant: P 2 s L / sqrt(1 + s^2) below F1's
		// plane, its projection on G inside G, within d0 of B, its distance
		// g in closed form.
		const double u = along.dot(P - ridge), v = -n1.dot(P - ridge);
		const double g = (k.h + k.t * (k.xq + u) + v) / std::sqrt(1 + k.t * k.t);
		ASSERT_NEAR(v, 2 * k.s * k.L / root, 1e-15);
		ASSERT_LT(u, uR);
		ASSERT_GT(u, -k.xq);
		ASSERT_LT(g, d0);
		ASSERT_GT(g, 2 * k.h);
		ASSERT_NEAR(nG.dot(P - g0), g, 1e-15);
		ASSERT_NEAR(nG.dot(n1), -1 / std::sqrt(1 + k.t * k.t), 1e-15);
		for (const Matrix3& R : dda::testing::sceneRotations(kSeed, 3)) {
			std::vector<Vector3> Ar, Br;
			for (const Vector3& x : roof) Ar.push_back(R * x);
			for (const Vector3& x : slab) Br.push_back(R * x);
			const Block A = dda::testing::narrowBlock(Ar), B = dda::testing::narrowBlock(Br);
			const int f1 = faceWith(A, {R * Vector3(0, -W, 1), R * Vector3(0, W, 1), R * Vector3(-1, W, 1 - k.s)});
			const int gFace = faceWith(B, {R * slab[0], R * slab[2], R * slab[4], R * slab[6]});
			const int p = vertexAt(A, R * P);
			ASSERT_GE(f1, 0);
			ASSERT_GE(gFace, 0);
			ASSERT_GE(p, 0);
			// The oracle: P's distance from B, by brute force.
			const double oracle = distanceOutside(R * P, B);
			ASSERT_NEAR(oracle, g, 1e-12);
			for (const bool swap : {false, true}) {
				const auto r = swap ? dda::detectPairContacts(B.geometry(), A.geometry(), settings)
				                    : dda::detectPairContacts(A.geometry(), B.geometry(), settings);
				ASSERT_TRUE(r.has_value());
				const std::string what = dda::testing::describePair(*r);
				// F1 of A is the entrance, the pair h apart along its normal.
				EXPECT_EQ(r->entrance.kind, swap ? dda::EntranceFeature::FaceOfB : dda::EntranceFeature::FaceOfA)
				    << what;
				EXPECT_EQ(r->entrance.feature, f1) << what;
				EXPECT_NEAR(r->separation, k.h, 1e-12) << what;
				// P against G: its distance from B, along G's normal.
				int found = 0;
				for (const SubContact& c : r->contacts) {
					if (c.kind != ContactKind::VertexFace) continue;
					const bool aIsI = c.firstIsA != swap;  // block i is the roof
					if (!aIsI || c.feature1 != p) continue;
					++found;
					EXPECT_EQ(c.feature2, gFace) << what;
					EXPECT_NEAR(c.gap, oracle, 1e-12) << what;
					worst = std::max(worst, std::abs(c.gap - oracle));
					EXPECT_NEAR(c.normal.dot(R * nG), 1.0, 1e-12) << what;
				}
				EXPECT_EQ(found, 1) << "s " << k.s << " L " << k.L << " h " << k.h << " t " << k.t
				                    << ": P " << oracle << " from B, " << what;
				// Nothing deeper than the pair is apart (it does not overlap).
				for (const SubContact& c : r->contacts) EXPECT_GT(c.gap, 0.0) << what;
			}
		}
	}
	std::printf("FoldCornerOwner: largest |gap - oracle| %.3g m\n", worst);
}

}  // namespace
