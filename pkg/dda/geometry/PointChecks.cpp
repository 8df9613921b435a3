// The checks of a block's raw points (PointChecks.hpp).
#include "PointChecks.hpp"

#include "dda/core/Errors.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <charconv>
#include <numeric>
#include <utility>

namespace dda::hull {
namespace {
using Point3 = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
Point3 toPoint3(const Vector3& p) { return Point3(p.x(), p.y(), p.z()); }
}  // namespace

std::string formatNumber(double x) {
	char buffer[64];
	const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
	return std::string(buffer, result.ptr);
}

std::string formatPoint(const Vector3& p) {
	return "(" + formatNumber(p.x()) + ", " + formatNumber(p.y()) + ", " + formatNumber(p.z()) + ")";
}

void requireEnoughPoints(const std::vector<Vector3>& points) {
	if (points.size() < kMinPointCount) {
		throw InputError("a block needs at least " + std::to_string(kMinPointCount) + " points, got " +
		                 std::to_string(points.size()));
	}
}

void requireFiniteCoordinates(const std::vector<Vector3>& points) {
	for (std::size_t i = 0; i < points.size(); ++i) {
		if (!points[i].allFinite()) {
			throw InputError("point " + std::to_string(i) + " has a non-finite coordinate: " + formatPoint(points[i]));
		}
	}
}

double boundingBoxDiagonal(const std::vector<Vector3>& points) {
	Vector3 lo = points.front();
	Vector3 hi = points.front();
	for (const Vector3& p : points) {
		lo = lo.cwiseMin(p);
		hi = hi.cwiseMax(p);
	}
	return (hi - lo).norm();
}

// Throws for the pair (i, j), i < j, that comes first in input order among all
// pairs closer than the coincidence tolerance. Sorting by x and sweeping keeps
// this near-linear for ordinary blocks.
void requireDistinctPoints(const std::vector<Vector3>& points) {
	const double tolerance = kCoincidenceRelativeTolerance * boundingBoxDiagonal(points);

	std::vector<int> byX(points.size());
	std::iota(byX.begin(), byX.end(), 0);
	std::sort(byX.begin(), byX.end(), [&](int a, int b) { return points[a].x() < points[b].x(); });

	std::pair<int, int> first{-1, -1};
	for (std::size_t s = 0; s < byX.size(); ++s) {
		for (std::size_t t = s + 1; t < byX.size(); ++t) {
			const Vector3& p = points[byX[s]];
			const Vector3& q = points[byX[t]];
			if (q.x() - p.x() > tolerance) break;
			const bool coincide = (p == q) || (p - q).norm() < tolerance;
			if (!coincide) continue;
			const std::pair<int, int> pair{std::min(byX[s], byX[t]), std::max(byX[s], byX[t])};
			if (first.first < 0 || pair < first) first = pair;
		}
	}
	if (first.first < 0) return;

	const Vector3& p = points[first.first];
	const Vector3& q = points[first.second];
	std::string message = "points " + std::to_string(first.first) + " and " + std::to_string(first.second) +
	                      " coincide at " + formatPoint(p);
	if (p != q) {
		message += " (" + formatPoint(q) + " is " + formatNumber((p - q).norm()) + " away, closer than " +
		           formatNumber(kCoincidenceRelativeTolerance) + " x the bounding-box diagonal)";
	}
	throw InputError(message);
}

// Exact: the points span 3D iff some four of them are not coplanar. Points
// are distinct here, so points 0 and 1 define a line.
void requireVolume(const std::vector<Vector3>& points) {
	const Point3 p0 = toPoint3(points[0]);
	const Point3 p1 = toPoint3(points[1]);
	std::size_t third = 2;
	while (third < points.size() && CGAL::collinear(p0, p1, toPoint3(points[third]))) ++third;
	if (third < points.size()) {
		const Point3 p2 = toPoint3(points[third]);
		for (std::size_t i = 2; i < points.size(); ++i) {
			if (!CGAL::coplanar(p0, p1, p2, toPoint3(points[i]))) return;
		}
	}
	throw InputError("all " + std::to_string(points.size()) + " points are coplanar: the block has no volume");
}

}  // namespace dda::hull
