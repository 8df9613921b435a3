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
bool parallelDirections(const Vector3& da, const Vector3& db, const Vector3& cross, double crossNorm, double la,
                        double lb, double sinTolerance);
bool parallelDirections(const Vector3& da, const Vector3& db, double sinTolerance);

// Exact sign of the triple product x . (y x z) of three unit vectors, given
// its double value `approx`.
int unitOrientation(double approx, const Vector3& x, const Vector3& y, const Vector3& z);

}  // namespace dda::narrow
