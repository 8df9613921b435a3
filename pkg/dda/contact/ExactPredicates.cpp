#include "ExactPredicates.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <Eigen/Geometry>

#include <array>
#include <cmath>

namespace dda::narrow {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using ExactPoint = Kernel::Point_3;
using ExactVector = Kernel::Vector_3;

ExactPoint exactPoint(const Vector3& p) { return ExactPoint(p.x(), p.y(), p.z()); }
ExactVector exactVector(const Vector3& v) { return ExactVector(v.x(), v.y(), v.z()); }

}  // namespace

int exactOrientation(const Vector3& a, const Vector3& b, const Vector3& c, const Vector3& d) {
	return static_cast<int>(CGAL::orientation(exactPoint(a), exactPoint(b), exactPoint(c), exactPoint(d)));
}

bool exactlyCollinear(const Vector3& da, const Vector3& db) {
	return CGAL::collinear(ExactPoint(0, 0, 0), exactPoint(da), exactPoint(db));
}

bool parallelDirections(const Vector3& da, const Vector3& db, double sinTolerance) {
	const Vector3 cross = da.cross(db);
	return parallelDirections(da, db, cross, cross.norm(), da.norm(), db.norm(), sinTolerance);
}

int tryTripleSign(const Vector3& x, const Vector3& y, const Vector3& z) {
	constexpr double kLargest = 0x1p64, kPermanentLow = 0x1p-900;
	if (!(x.cwiseAbs().maxCoeff() <= kLargest && y.cwiseAbs().maxCoeff() <= kLargest &&
	      z.cwiseAbs().maxCoeff() <= kLargest))
		return 0;  // too large (or NaN): exact arithmetic decides
	const double c0 = y[1] * z[2] - y[2] * z[1];
	const double c1 = y[2] * z[0] - y[0] * z[2];
	const double c2 = y[0] * z[1] - y[1] * z[0];
	const double d = x[0] * c0 + x[1] * c1 + x[2] * c2;
	const double a0 = std::abs(y[1] * z[2]) + std::abs(y[2] * z[1]);
	const double a1 = std::abs(y[2] * z[0]) + std::abs(y[0] * z[2]);
	const double a2 = std::abs(y[0] * z[1]) + std::abs(y[1] * z[0]);
	const double permanent = std::abs(x[0]) * a0 + std::abs(x[1]) * a1 + std::abs(x[2]) * a2;
	if (!(permanent >= kPermanentLow)) return 0;
	const double bound = 0x1p-50 * permanent;
	return (d > bound) - (d < -bound);
}

int unitOrientationExact(const Vector3& x, const Vector3& y, const Vector3& z) {
	if (const int sign = tryTripleSign(x, y, z)) return sign;
	// Exactly zero when each of the determinant's six terms x_i y_j z_k has a
	// zero factor (axis-aligned normals).
	bool zero = true;
	for (const auto& [i, j, k] : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{1, 2, 0}, std::array<int, 3>{2, 0, 1},
	                              std::array<int, 3>{0, 2, 1}, std::array<int, 3>{1, 0, 2}, std::array<int, 3>{2, 1, 0}})
		zero = zero && (x[i] == 0 || y[j] == 0 || z[k] == 0);
	if (zero) return 0;
	return static_cast<int>(CGAL::orientation(exactVector(x), exactVector(y), exactVector(z)));
}

}  // namespace dda::narrow
