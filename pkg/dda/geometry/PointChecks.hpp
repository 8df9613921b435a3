// Step 1 of buildConvexPolyhedron (ConvexPolyhedron.cpp) and of hullCorners:
// the checks of a block's raw points (count, finite coordinates, distinct
// points, volume), each an InputError naming the point and its value, and the
// number formatting of those messages. Contract: a point list that passes
// them has at least 4 finite, pairwise distinct points (beyond the
// coincidence tolerance) spanning a volume; the volume test uses CGAL's exact
// predicates. Tested by tests/cpp/geometry/test_convex_polyhedron.cpp and
// tests/py/yade/test_bad_input.py.
#pragma once

#include "dda/core/Types.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace dda::hull {

// The smallest point set with volume is a tetrahedron.
constexpr std::size_t kMinPointCount = 4;

// Two input points closer than this fraction of the bounding-box diagonal are
// treated as one (dimensionless; the absolute tolerance scales with the block).
// 1e-12 is about 4500 ulps of the diagonal: far above the round-off of any
// coordinate transformation a caller applies, far below any intended feature.
constexpr double kCoincidenceRelativeTolerance = 1e-12;

// Shortest text that reads back to the same double ("0.30000000000000004",
// "1", "nan", "-inf"); a point as "(x, y, z)".
std::string formatNumber(double x);
std::string formatPoint(const Vector3& p);

void requireEnoughPoints(const std::vector<Vector3>& points);
void requireFiniteCoordinates(const std::vector<Vector3>& points);
double boundingBoxDiagonal(const std::vector<Vector3>& points);
// Throws for the pair (i, j), i < j, that comes first in input order among
// all pairs closer than the coincidence tolerance.
void requireDistinctPoints(const std::vector<Vector3>& points);
// Exact: throws when every point lies on one plane (points distinct).
void requireVolume(const std::vector<Vector3>& points);

}  // namespace dda::hull
