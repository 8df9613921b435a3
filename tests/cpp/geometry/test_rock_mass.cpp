// Tests of the rock-mass cutter: its exact predicates (dda/geometry/PlanePredicates.hpp), cells, slivers
// and of its keyed random choices (RockPlanes.hpp).
//
// The oracle never reuses the library's formula: the side of plane l at the
// vertex of planes (i, j, k) is computed by solving N x = d exactly in
// rationals (CGAL::Gmpq, Cramer's rule written out here) and evaluating
// n_l . x - d_l, where the library takes the sign of a 4 x 4 determinant
// through interval and Gmpzf filters. Random cases print their seed.
#include "dda/core/Errors.hpp"
#include "dda/geometry/ConvexCell.hpp"
#include "dda/geometry/PlanePredicates.hpp"
#include "dda/geometry/RockMassSlivers.hpp"
#include "dda/geometry/RockPlanes.hpp"

#include <CGAL/Gmpq.h>
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace {

using dda::Vector3;
using dda::rockmass::CutPlane;
using dda::rockmass::PlaneTriple;
using Q = CGAL::Gmpq;

struct ExactPoint {
	Q x, y, z;
};

Q det3(const Q& a, const Q& b, const Q& c, const Q& d, const Q& e, const Q& f, const Q& g, const Q& h, const Q& i) {
	return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
}

// The exact intersection of three planes (Cramer's rule in rationals).
ExactPoint solve(const std::vector<CutPlane>& p, const PlaneTriple& t) {
	const auto n = [&](int r, int c) { return Q(p[t[r]].normal[c]); };
	const auto d = [&](int r) { return Q(p[t[r]].offset); };
	const Q D = det3(n(0, 0), n(0, 1), n(0, 2), n(1, 0), n(1, 1), n(1, 2), n(2, 0), n(2, 1), n(2, 2));
	const Q X = det3(d(0), n(0, 1), n(0, 2), d(1), n(1, 1), n(1, 2), d(2), n(2, 1), n(2, 2));
	const Q Y = det3(n(0, 0), d(0), n(0, 2), n(1, 0), d(1), n(1, 2), n(2, 0), d(2), n(2, 2));
	const Q Z = det3(n(0, 0), n(0, 1), d(0), n(1, 0), n(1, 1), d(1), n(2, 0), n(2, 1), d(2));
	return {X / D, Y / D, Z / D};
}

int referenceSide(const std::vector<CutPlane>& p, const PlaneTriple& t, int l) {
	const ExactPoint x = solve(p, t);
	const CutPlane& q = p[l];
	const Q s = Q(q.normal.x()) * x.x + Q(q.normal.y()) * x.y + Q(q.normal.z()) * x.z - Q(q.offset);
	return static_cast<int>(CGAL::sign(s));
}

int librarySide(const std::vector<CutPlane>& p, const PlaneTriple& t, int l,
                dda::rockmass::PredicateCounters* counters = nullptr) {
	return dda::rockmass::vertexSide(p, t, dda::rockmass::vertexBounds(p, t), l, counters);
}

Vector3 randomUnit(std::mt19937_64& rng) {
	std::normal_distribution<double> g;
	return Vector3(g(rng), g(rng), g(rng)).normalized();
}

constexpr std::uint64_t kSeed = 20240619;

TEST(RockMassPredicates, RandomQuadruplesAgreeWithRationalReference) {
	std::cout << "seed " << kSeed << std::endl;
	std::mt19937_64 rng(kSeed);
	std::uniform_real_distribution<double> offset(-50, 50), scale(-6, 6);
	int checked = 0;
	for (int trial = 0; trial < 3000; ++trial) {
		std::vector<CutPlane> p;
		for (int k = 0; k < 4; ++k) p.push_back({randomUnit(rng) * std::pow(10.0, scale(rng)), offset(rng)});
		const PlaneTriple t{0, 1, 2};
		if (dda::rockmass::tripleSign(p, t) == 0) continue;
		ASSERT_EQ(librarySide(p, t, 3), referenceSide(p, t, 3)) << "seed " << kSeed << " trial " << trial;
		ASSERT_EQ(dda::rockmass::vertexSideExact(p, t, 3), referenceSide(p, t, 3));
		++checked;
	}
	EXPECT_GT(checked, 2900);
}

// Integer and dyadic planes through one exact point: the fourth plane passes
// exactly through the vertex (sign 0), or one ulp of its offset off it.
TEST(RockMassPredicates, VertexExactlyOnAPlaneAndOneUlpOff) {
	std::cout << "seed " << kSeed + 1 << std::endl;
	std::mt19937_64 rng(kSeed + 1);
	std::uniform_int_distribution<int> coefficient(-8, 8), coordinate(-64, 64);
	dda::rockmass::PredicateCounters counters;
	int zeros = 0;
	for (int trial = 0; trial < 2000; ++trial) {
		const Vector3 x(coordinate(rng) / 8.0, coordinate(rng) / 4.0, coordinate(rng) / 2.0);  // dyadic
		std::vector<CutPlane> p;
		for (int k = 0; k < 4; ++k) {
			const Vector3 n(coefficient(rng), coefficient(rng), coefficient(rng));
			p.push_back({n, n.dot(x)});  // exact: small integers times dyadic numbers
		}
		const PlaneTriple t{0, 1, 2};
		if (dda::rockmass::tripleSign(p, t) == 0 || p[3].normal.isZero()) continue;
		const int side = librarySide(p, t, 3, &counters);
		ASSERT_EQ(side, 0) << "seed " << kSeed + 1 << " trial " << trial;
		ASSERT_EQ(side, referenceSide(p, t, 3));
		++zeros;
		for (double direction : {-1.0, 1.0}) {
			std::vector<CutPlane> q = p;
			q[3].offset = std::nextafter(q[3].offset, direction * HUGE_VAL);
			ASSERT_EQ(librarySide(q, t, 3, &counters), referenceSide(q, t, 3)) << "trial " << trial;
			ASSERT_NE(referenceSide(q, t, 3), 0);
		}
	}
	EXPECT_GT(zeros, 1500);
	EXPECT_GT(counters.exactDecided, 0u);  // the filters cannot decide an exact zero
}

// Nearly parallel planes: the second normal differs from the first by one
// ulp in one component; the vertex is far away and ill-conditioned.
TEST(RockMassPredicates, NearlyParallelPlanes) {
	std::cout << "seed " << kSeed + 2 << std::endl;
	std::mt19937_64 rng(kSeed + 2);
	std::uniform_real_distribution<double> offset(-1, 1);
	int checked = 0;
	for (int trial = 0; trial < 1000; ++trial) {
		std::vector<CutPlane> p;
		const Vector3 n = randomUnit(rng);
		Vector3 m = n;
		m[trial % 3] = std::nextafter(m[trial % 3], 2.0);
		p.push_back({n, offset(rng)});
		p.push_back({m, trial % 2 ? p[0].offset : offset(rng)});
		p.push_back({randomUnit(rng), offset(rng)});
		p.push_back({trial % 4 < 2 ? n : randomUnit(rng), offset(rng)});
		const PlaneTriple t{0, 1, 2};
		if (dda::rockmass::tripleSign(p, t) == 0) continue;
		ASSERT_EQ(librarySide(p, t, 3), referenceSide(p, t, 3)) << "seed " << kSeed + 2 << " trial " << trial;
		++checked;
	}
	EXPECT_GT(checked, 900);
}

TEST(RockMassPredicates, ExactlyParallelPlanesDoNotMeet) {
	std::vector<CutPlane> p{{Vector3(1, 2, 3), 1}, {Vector3(2, 4, 6), 5}, {Vector3(0, 0, 1), 0}};
	EXPECT_EQ(dda::rockmass::tripleSign(p, {0, 1, 2}), 0);
	EXPECT_FALSE(dda::rockmass::vertexBounds(p, {0, 1, 2}).bounded);
	EXPECT_THROW(dda::rockmass::vertexPoint(p, {0, 1, 2}), dda::InputError);
}

// The rounded point is the exact point rounded toward zero: the same for
// every triple of planes through it, and within one ulp of it.
TEST(RockMassPredicates, VertexPointIsTheExactPointRoundedTowardZero) {
	std::cout << "seed " << kSeed + 3 << std::endl;
	std::mt19937_64 rng(kSeed + 3);
	std::uniform_real_distribution<double> offset(-20, 20);
	for (int trial = 0; trial < 500; ++trial) {
		std::vector<CutPlane> p;
		for (int k = 0; k < 3; ++k) p.push_back({randomUnit(rng), offset(rng)});
		const PlaneTriple t{0, 1, 2};
		if (dda::rockmass::tripleSign(p, t) == 0) continue;
		const ExactPoint x = solve(p, t);
		const Vector3 got = dda::rockmass::vertexPoint(p, t);
		const Q exact[3] = {x.x, x.y, x.z};
		for (int c = 0; c < 3; ++c) {
			const Q rounded(got[c]);
			// |rounded| <= |exact| < |next double away from zero|
			EXPECT_TRUE(CGAL::abs(rounded) <= CGAL::abs(exact[c])) << "trial " << trial;
			EXPECT_TRUE(CGAL::abs(Q(std::nextafter(got[c], exact[c] < 0 ? -HUGE_VAL : HUGE_VAL))) > CGAL::abs(exact[c]) ||
			            rounded == exact[c]);
		}
	}
	// Four planes through the exact point (1/3, 1/7, 1/11), which no double is: normals (3a, 7b, 11c),
	// offsets a + b + c. Every triple gives the same bits, each plane is exactly on the others' vertex.
	const Q third = Q(1) / Q(3), seventh = Q(1) / Q(7), eleventh = Q(1) / Q(11);
	std::vector<CutPlane> p;
	for (const Vector3& abc : {Vector3(1, 2, -1), Vector3(-2, 1, 1), Vector3(1, -3, 2), Vector3(2, 1, 3)})
		p.push_back({Vector3(3 * abc.x(), 7 * abc.y(), 11 * abc.z()), abc.sum()});
	const Vector3 first = dda::rockmass::vertexPoint(p, {0, 1, 2});
	EXPECT_TRUE(Q(first.x()) < third && Q(std::nextafter(first.x(), 1.0)) > third);
	EXPECT_TRUE(Q(first.y()) < seventh && Q(first.z()) < eleventh);
	int triples = 0;
	for (const PlaneTriple& t : {PlaneTriple{0, 1, 3}, PlaneTriple{0, 2, 3}, PlaneTriple{1, 2, 3}}) {
		if (dda::rockmass::tripleSign(p, t) == 0) continue;
		++triples;
		EXPECT_EQ(dda::rockmass::vertexPoint(p, t), first);
		for (int l = 0; l < 4; ++l) EXPECT_EQ(librarySide(p, t, l), 0);
	}
	EXPECT_EQ(triples, 3);
}

TEST(RockMassPlanes, PoleConvention) {
	// dip 30 towards the east (+x): the pole leans west-up... i.e. its x part is +sin 30, and the plane
	// descends towards +x: moving along +x on it, z falls.
	const Vector3 n = dda::rockmass::poleOf(30, 90);
	EXPECT_NEAR(n.x(), 0.5, 1e-15);
	EXPECT_EQ(n.y(), 0.0);
	EXPECT_NEAR(n.z(), std::sqrt(3.0) / 2, 1e-15);
	const double dzdx = -n.x() / n.z();
	EXPECT_LT(dzdx, 0);
	EXPECT_EQ(dda::rockmass::poleOf(90, 90), Vector3(1, 0, 0));
	EXPECT_EQ(dda::rockmass::poleOf(90, 0), Vector3(0, 1, 0));
	EXPECT_EQ(dda::rockmass::poleOf(0, 123), Vector3(0, 0, 1));
	EXPECT_EQ(dda::rockmass::poleOf(90, 180), Vector3(0, -1, 0));
}

// Mean cos(theta) of the Fisher distribution is coth k - 1/k.
TEST(RockMassPlanes, FisherSampleMeanAngle) {
	const Vector3 mean = dda::rockmass::poleOf(35, 200);
	for (double k : {2.0, 20.0, 200.0}) {
		double sum = 0;
		const int n = 200000;
		for (int i = 0; i < n; ++i) {
			const double u = dda::rockmass::keyedUniform(7, dda::rockmass::RandomPurpose::FisherTheta, {1, std::uint64_t(i)});
			const double v = dda::rockmass::keyedUniform(7, dda::rockmass::RandomPurpose::FisherPhi, {1, std::uint64_t(i)});
			const Vector3 s = dda::rockmass::fisherSample(mean, k, u, v);
			ASSERT_NEAR(s.norm(), 1, 1e-12);
			sum += s.dot(mean);
		}
		const double expected = 1 / std::tanh(k) - 1 / k;
		EXPECT_NEAR(sum / n, expected, 4 * std::sqrt((1 - expected * expected) / n) + 1e-4) << "k " << k;
	}
}

TEST(RockMassPlanes, KeyedUniformDependsOnItsKeyOnly) {
	using dda::rockmass::RandomPurpose;
	const double a = dda::rockmass::keyedUniform(1, RandomPurpose::Persistence, {3, 4});
	EXPECT_EQ(a, dda::rockmass::keyedUniform(1, RandomPurpose::Persistence, {3, 4}));
	EXPECT_NE(a, dda::rockmass::keyedUniform(2, RandomPurpose::Persistence, {3, 4}));
	EXPECT_NE(a, dda::rockmass::keyedUniform(1, RandomPurpose::Persistence, {4, 3}));
	EXPECT_GT(a, 0);
	EXPECT_LT(a, 1);
}

// A box cell cut by an oblique plane through two of its corners (zeros on
// the plane): the two parts' volumes add up to the box's, both are convex
// and every face has at least 3 corners.
TEST(RockMassCells, SplitThroughCorners) {
	using namespace dda::rockmass;
	std::vector<CutPlane> planes{{Vector3::UnitX(), 0}, {Vector3::UnitX(), 2}, {Vector3::UnitY(), 0},
	                             {Vector3::UnitY(), 3}, {Vector3::UnitZ(), 0}, {Vector3::UnitZ(), 4},
	                             {Vector3(3, 2, 0), 6}};  // through (2, 0, z) and (0, 3, z)
	VertexTable table(planes);
	const Cell box = boxCell(0, {0, 1, 2, 3, 4, 5}, table);
	EXPECT_DOUBLE_EQ(cellVolume(box, table), 24);
	std::vector<signed char> signs;
	ASSERT_EQ(classify(box, 6, table, signs), 3);
	const auto [below, above] = split(box, 6, signs, table);
	EXPECT_DOUBLE_EQ(cellVolume(below, table), 12);
	EXPECT_DOUBLE_EQ(cellVolume(above, table), 12);
	EXPECT_EQ(below.vertices.size(), 6u);  // a triangular prism
	EXPECT_EQ(below.faceCount(), 5);
	for (const Cell* c : {&below, &above})
		for (int f = 0; f < c->faceCount(); ++f) EXPECT_GE(c->faceStart[f + 1] - c->faceStart[f], 3);
	// clipping keeps the inside of a face ref, or nothing
	EXPECT_FALSE(clip(box, faceRef(0, false), table).has_value());  // inside x <= 0: no volume
	EXPECT_DOUBLE_EQ(cellVolume(*clip(box, faceRef(6, true), table), table), 12);
}

}  // namespace

namespace {

// Slivers (RockMassSlivers.hpp): a thin slab S = [0, e] x [0, 1] x [0, 1] beside N = [e, 1] x [0, 1] x [0, 1]
// merges (the union is the unit box); beside N1 = [e, 1] x [0, 0.5] and N2 = [e, 1] x [0.5, 1] it cannot
// (either union is L-shaped) and is reported, with the reason.
struct SlabScene {
	std::vector<dda::rockmass::CutPlane> planes{
	    {Vector3::UnitX(), -1}, {Vector3::UnitX(), 2}, {Vector3::UnitY(), -1}, {Vector3::UnitY(), 2},
	    {Vector3::UnitZ(), -1}, {Vector3::UnitZ(), 2},  // bounds
	    {Vector3::UnitX(), 0},  {Vector3::UnitX(), 1},  {Vector3::UnitY(), 0}, {Vector3::UnitY(), 1},
	    {Vector3::UnitZ(), 0},  {Vector3::UnitZ(), 1},  // the unit box, 6..11
	    {Vector3::UnitX(), 1e-3}, {Vector3::UnitY(), 0.5}};  // 12: the slab's face, 13: y = 0.5
	dda::rockmass::VertexTable table{planes};
	dda::rockmass::Cell box;
	SlabScene() {
		using namespace dda::rockmass;
		box = boxCell(0, {0, 1, 2, 3, 4, 5}, table);
		for (int p = 6; p < 12; ++p) box = *clip(box, faceRef(p, p % 2 == 0), table);
	}
	dda::rockmass::Cell clipped(const dda::rockmass::Cell& c, int plane, bool above) {
		return *dda::rockmass::clip(c, dda::rockmass::faceRef(plane, above), table);
	}
};

TEST(RockMassSlivers, ThinSlabMergesWithItsSibling) {
	using namespace dda::rockmass;
	SlabScene s;
	const Cell slab = s.clipped(s.box, 12, false), rest = s.clipped(s.box, 12, true);
	const auto problem = [&](const Cell& c) { return cellVolume(c, s.table) < 0.01 ? std::string("small") : std::string(); };
	SliverOutcome out = mergeSlivers({slab, rest}, {s.box}, problem, s.table);
	ASSERT_EQ(out.kept.size(), 1u);
	EXPECT_TRUE(out.reported.empty());
	EXPECT_EQ(out.merged, 1);
	EXPECT_DOUBLE_EQ(cellVolume(out.kept[0], s.table), 1);
	EXPECT_EQ(out.kept[0].faceCount(), 6);
}

TEST(RockMassSlivers, SlabBesideTwoBlocksIsReported) {
	using namespace dda::rockmass;
	SlabScene s;
	const Cell slab = s.clipped(s.box, 12, false), rest = s.clipped(s.box, 12, true);
	const Cell n1 = s.clipped(rest, 13, false), n2 = s.clipped(rest, 13, true);
	const auto problem = [&](const Cell& c) { return cellVolume(c, s.table) < 0.01 ? std::string("small") : std::string(); };
	SliverOutcome out = mergeSlivers({slab, n1, n2}, {s.box}, problem, s.table);
	EXPECT_EQ(out.kept.size(), 2u);
	EXPECT_EQ(out.merged, 0);
	ASSERT_EQ(out.reported.size(), 1u);
	EXPECT_NEAR(cellVolume(out.reported[0].first, s.table), 1e-3, 1e-15);
	EXPECT_NE(out.reported[0].second.find("not convex"), std::string::npos) << out.reported[0].second;
}

}  // namespace
