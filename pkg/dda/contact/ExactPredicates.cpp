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

// A component a_j b_k - a_k b_j of a cross product computed in double is
// within 4 DBL_EPSILON max|a_i| max|b_i| of its exact value (barring
// underflow); above this factor the exact cross product is not zero.
constexpr double kCrossRoundoffRelative = 1e-14;

ExactPoint exactPoint(const Vector3& p) { return ExactPoint(p.x(), p.y(), p.z()); }
ExactVector exactVector(const Vector3& v) { return ExactVector(v.x(), v.y(), v.z()); }

}  // namespace

int exactOrientation(const Vector3& a, const Vector3& b, const Vector3& c, const Vector3& d) {
	return static_cast<int>(CGAL::orientation(exactPoint(a), exactPoint(b), exactPoint(c), exactPoint(d)));
}

bool parallelDirections(const Vector3& da, const Vector3& db, const Vector3& cross, double crossNorm, double la,
                        double lb, double sinTolerance) {
	if (crossNorm <= sinTolerance * la * lb) return true;
	// Not within the angle: parallel only when exactly collinear. A component
	// of the double cross product above its round-off bound proves it is not.
	const double scale = da.cwiseAbs().maxCoeff() * db.cwiseAbs().maxCoeff();
	if (scale > 1e-250 && scale < 1e250 && cross.cwiseAbs().maxCoeff() > kCrossRoundoffRelative * scale) return false;
	return CGAL::collinear(ExactPoint(0, 0, 0), exactPoint(da), exactPoint(db));
}

bool parallelDirections(const Vector3& da, const Vector3& db, double sinTolerance) {
	const Vector3 cross = da.cross(db);
	return parallelDirections(da, db, cross, cross.norm(), da.norm(), db.norm(), sinTolerance);
}

int unitOrientationExact(const Vector3& x, const Vector3& y, const Vector3& z) {
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
