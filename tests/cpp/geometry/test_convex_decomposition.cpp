// convexDecomposition: a closed non-convex triangulated surface into convex
// parts. Oracles: the closed-form volume and centroid of an L prism and of
// random star-shaped prisms (seed printed), the parts' own acceptance as a
// concave block after conformParts, and refusals of open, non-manifold and
// self-intersecting surfaces naming the problem.
#include "dda/geometry/ConvexDecomposition.hpp"
#include "dda/geometry/ConvexParts.hpp"
#include "dda/geometry/MassProperties.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace dda {
namespace {

using Triangles = std::vector<std::array<int, 3>>;

// The prism over a polygon star-shaped about `centre` (counter-clockwise in
// x, y), from z = 0 to `height`: sides as two triangles per edge, the caps as
// fans about the centre (its points added last).
void prism(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& centre, double height,
           std::vector<Vector3>& points, Triangles& triangles) {
	const int n = static_cast<int>(polygon.size());
	for (const auto& p : polygon) points.emplace_back(p.x(), p.y(), 0);
	for (const auto& p : polygon) points.emplace_back(p.x(), p.y(), height);
	points.emplace_back(centre.x(), centre.y(), 0);
	points.emplace_back(centre.x(), centre.y(), height);
	const int bottom = 2 * n, top = 2 * n + 1;
	for (int k = 0; k < n; ++k) {
		const int a = k, b = (k + 1) % n;
		triangles.push_back({a, b, n + b});
		triangles.push_back({a, n + b, n + a});
		triangles.push_back({bottom, b, a});
		triangles.push_back({top, n + a, n + b});
	}
}

// Area and centroid of a simple polygon (shoelace).
void polygonMoments(const std::vector<Eigen::Vector2d>& p, double& area, Eigen::Vector2d& centroid) {
	area = 0;
	centroid.setZero();
	for (std::size_t k = 0; k < p.size(); ++k) {
		const auto& a = p[k];
		const auto& b = p[(k + 1) % p.size()];
		const double cross = a.x() * b.y() - b.x() * a.y();
		area += cross / 2;
		centroid += (a + b) * cross / 6;
	}
	centroid /= area;
}

void expectSolid(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& centre, double height) {
	std::vector<Vector3> points;
	Triangles triangles;
	prism(polygon, centre, height, points, triangles);
	const std::vector<std::vector<Vector3>> parts = conformParts(convexDecomposition(points, triangles));
	std::vector<ConvexPolyhedron> polyhedra;
	std::vector<MassProperties> each;
	for (const auto& corners : parts) {
		polyhedra.push_back(buildConvexPolyhedron(corners));
		each.push_back(computeMassProperties(polyhedra.back().vertices, polyhedra.back().faces));
	}
	EXPECT_NO_THROW(checkConvexParts(polyhedra));
	double area;
	Eigen::Vector2d c;
	polygonMoments(polygon, area, c);
	const MassProperties whole = unionMassProperties(each);
	EXPECT_NEAR(whole.volume, area * height, 1e-12 * area * height);
	EXPECT_LT((whole.centroid - Vector3(c.x(), c.y(), height / 2)).norm(), 1e-12 * std::sqrt(area));
	EXPECT_GE(parts.size(), 2u);
}

TEST(ConvexDecomposition, AnLPrismIsSplitIntoPartsWithItsVolumeAndCentroid) {
	expectSolid({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, {0.5, 0.5}, 1);
}

TEST(ConvexDecomposition, RandomStarShapedPrismsKeepTheirVolumeAndCentroid) {
	const unsigned seed = 7;
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> unit(0, 1);
	for (int trial = 0; trial < 5; ++trial) {
		SCOPED_TRACE("seed " + std::to_string(seed) + ", trial " + std::to_string(trial));
		const int n = 6 + trial;
		std::vector<Eigen::Vector2d> polygon;
		for (int k = 0; k < n; ++k) {
			const double angle = 2 * M_PI * (k + 0.3 * unit(rng)) / n;
			const double radius = k % 2 ? 0.6 + 0.4 * unit(rng) : 2 + unit(rng);  // alternate: reflex corners
			polygon.emplace_back(3 + radius * std::cos(angle), -1 + radius * std::sin(angle));
		}
		expectSolid(polygon, {3, -1}, 0.5 + unit(rng));
	}
}

void expectRefused(const std::vector<Vector3>& points, const Triangles& triangles, const std::string& words) {
	try {
		convexDecomposition(points, triangles);
		ADD_FAILURE() << "accepted; expected an error with '" << words << "'";
	} catch (const InputError& error) {
		EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
	}
}

TEST(ConvexDecomposition, BadSurfacesAreRefusedNamingTheProblem) {
	std::vector<Vector3> points;
	Triangles triangles;
	prism({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, {0.5, 0.5}, 1, points, triangles);
	Triangles open(triangles.begin() + 1, triangles.end());
	expectRefused(points, open, "open");
	Triangles outOfRange = triangles;
	outOfRange[3][1] = 99;
	expectRefused(points, outOfRange, "out of range");
	Triangles repeated = triangles;
	repeated[0][1] = repeated[0][0];
	expectRefused(points, repeated, "repeats a corner");
	std::vector<Vector3> nan = points;
	nan[2].x() = std::nan("");
	expectRefused(nan, triangles, "not finite");
	// Two closed prisms overlapping: the union of two surfaces that cross.
	std::vector<Vector3> both = points;
	Triangles crossing = triangles;
	std::vector<Vector3> more;
	Triangles second;
	prism({{0.5, 0.5}, {2.5, 0.5}, {2.5, 1.5}, {0.5, 1.5}}, {1.5, 1}, 1, more, second);
	const int offset = static_cast<int>(both.size());
	for (const Vector3& x : more) both.push_back(x + Vector3(0, 0, 0.3));
	for (auto t : second) crossing.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
	expectRefused(both, crossing, "intersects itself");
}

}  // namespace
}  // namespace dda

namespace dda {
namespace {
// sharedFaces on a grid of unit cubes: exactly the neighbours' faces, each 1 m^2.
TEST(ConvexParts, SharedFacesOfACubeGridAreTheNeighboursFaces) {
	const int nx = 3, ny = 2, nz = 2;
	std::vector<ConvexPolyhedron> cubes;
	for (int i = 0; i < nx; ++i)
		for (int j = 0; j < ny; ++j)
			for (int k = 0; k < nz; ++k) {
				std::vector<Vector3> corners;
				for (int c = 0; c < 8; ++c) corners.emplace_back(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
				cubes.push_back(buildConvexPolyhedron(corners));
			}
	const std::vector<SharedFace> shared = sharedFaces(cubes);
	EXPECT_EQ(static_cast<int>(shared.size()), (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1));
	for (const SharedFace& s : shared) {
		EXPECT_NEAR(s.area, 1.0, 1e-12);
		const Vector3 d = cubes[s.b].vertices[0] - cubes[s.a].vertices[0];
		EXPECT_NEAR(d.norm(), 1.0, 1e-12);  // neighbours only
		EXPECT_LT(s.a, s.b);
	}
}
}  // namespace
}  // namespace dda
