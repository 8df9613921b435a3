// Exact signs for the narrow phase (PairDetection.hpp: "Signs that decide
// topology ... use CGAL's exact predicates; distances are doubles"): which side
// of a plane a point lies on, whether two directions are parallel, the sign of
// a triple product of unit normals. Where a cheap round-off bound exists, a
// double-precision filter settles the sign first and CGAL only decides what
// the filter cannot; this is the one file of the narrow phase that includes
// CGAL. Units: m for points and lengths; the tolerances are dimensionless.
#pragma once

#include "dda/core/Types.hpp"

namespace dda::narrow {

// A double distance from a plane (or between two lines) below this fraction of
// the lengths it is computed from is round-off (dimensionless): its sign is
// then decided exactly by CGAL. Rule: the distance carries an error of a few
// DBL_EPSILON x (lengths involved) x (conditioning of the face triangle, which
// chooseFaceCorners keeps near 1); 1e-12 is ~4500 DBL_EPSILON, far above that
// and far below kDefaultRelativeLengthTolerance (1e-8).
inline constexpr double kRoundoffRelative = 1e-12;

// Orientation of point d against the plane through a, b, c (CGAL::orientation,
// exact): +1 when d lies on the side (b - a) x (c - a) points to, -1 on the
// other side, 0 when the four points are exactly coplanar.
int exactOrientation(const Vector3& a, const Vector3& b, const Vector3& c, const Vector3& d);

// Two edge directions are parallel: exactly (cross product of the double
// vectors zero, decided by CGAL) or within the angle tolerance.
// sinTolerance = sin(angleTolerance); la = |da|, lb = |db|.
// `cross` = da x db and `crossNorm` = |cross| as computed by the callers
// (Eigen's cross() and norm()).
// A component a_j b_k - a_k b_j of a cross product computed in double is
// within 4 DBL_EPSILON max|a_i| max|b_i| of its exact value (barring
// underflow); above this factor the exact cross product is not zero.
inline constexpr double kCrossRoundoffRelative = 1e-14;

// Whether da and db are exactly collinear (CGAL), for the cases the filter
// of parallelDirections cannot settle.
bool exactlyCollinear(const Vector3& da, const Vector3& db);

inline bool parallelDirections(const Vector3& da, const Vector3& db, const Vector3& cross, double crossNorm, double la,
                               double lb, double sinTolerance) {
	if (crossNorm <= sinTolerance * la * lb) return true;
	// Not within the angle: parallel only when exactly collinear. A component
	// of the double cross product above its round-off bound proves it is not.
	const double scale = da.cwiseAbs().maxCoeff() * db.cwiseAbs().maxCoeff();
	if (scale > 1e-250 && scale < 1e250 && cross.cwiseAbs().maxCoeff() > kCrossRoundoffRelative * scale) return false;
	return exactlyCollinear(da, db);
}
bool parallelDirections(const Vector3& da, const Vector3& db, double sinTolerance);

// |x . (y x z)| computed in double for unit vectors x, y, z (normalized face
// normals, components within 1 + 4 DBL_EPSILON of 1 in magnitude) is within
// about 21 DBL_EPSILON (~5e-15) of the exact triple product of those doubles;
// above this bound its sign is the exact sign (dimensionless).
inline constexpr double kUnitTripleRoundoff = 1e-13;

// The sign of x . (y x z) when the filter cannot tell (|approx| within the
// round-off bound): exact. First tryTripleSign (below), then CGAL.
int unitOrientationExact(const Vector3& x, const Vector3& y, const Vector3& z);

// The sign of x . (y x z) from a round-off bound of the operands' own
// magnitudes, or 0 when it cannot tell (then only an exact computation can).
// kUnitTripleRoundoff bounds the error for unit vectors of any direction;
// where the triple product is tiny because the vectors' components are
// (normals of faces aligned with the axes, turned a little: products of
// 1e-14 components), the error is as tiny, and this bound says so.
//
// Bound (u = 2^-53, rounding to nearest, no underflow or overflow; the
// products and differences below, fused or not): with a_i = |y_j z_k| +
// |y_k z_j| ((i, j, k) cyclic) and P = sum_i |x_i| a_i, the computed
// c_i = y_j z_k - y_k z_j is within gamma_2 a_i of the exact one (a product
// and a difference), and the computed d = sum_i x_i c_i within gamma_3
// sum_i |x_i| |c_i| <= gamma_3 (1 + gamma_2) P of sum_i x_i c_i
// (gamma_n = n u / (1 - n u), Higham's inner-product bound); so
// |d - x . (y x z)| <= (gamma_2 + gamma_3 + gamma_2 gamma_3) P < 6 u P. The
// computed P~ (sums and products of non-negative numbers, five roundings on
// any path) is at least P (1 - u)^5, so 6 u P < 7 u P~ < 2^-50 P~, a product
// by a power of two, exact. |d| > 2^-50 P~ therefore leaves the exact value
// on d's side of zero. Range: the function declines unless every component
// is within 2^64 (nothing overflows) and P~ >= 2^-900; a product that
// underflows then adds at most 2^-1075 (times |x_i| <= 2^64, some ten of
// them: below 2^-1000), far less than the u P~ >= 2^-953 between 7 u P~ and
// the bound.
int tryTripleSign(const Vector3& x, const Vector3& y, const Vector3& z);

// Exact sign of the triple product x . (y x z) of three unit vectors, given
// its double value `approx`. Inline: the narrow phase's edge axes call it a
// few hundred times per pair, and the filter settles nearly all of them.
inline int unitOrientation(double approx, const Vector3& x, const Vector3& y, const Vector3& z) {
	if (approx > kUnitTripleRoundoff) return 1;
	if (approx < -kUnitTripleRoundoff) return -1;
	return unitOrientationExact(x, y, z);
}

}  // namespace dda::narrow
