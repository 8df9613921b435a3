// Exact signs on vertices that are intersections of three planes, for the
// rock-mass cutter (RockMassCutter.hpp). Units: m for offsets and points.
//
// A plane is n . x = offset with double coefficients taken as exact numbers.
// A vertex is never stored as a rounded point but as the three plane indices
// whose exact intersection it is. Every topological decision is the sign of
// a polynomial in the coefficients, decided exactly:
//   - the side of plane l at the vertex (i, j, k): s = n_l . x - d_l with x
//     the exact solution of N x = d, N = [n_i; n_j; n_k]. A column operation
//     on M = [n_i d_i; n_j d_j; n_k d_k; n_l d_l] gives det M = -s det N, so
//     sign(s) = -sign(det M) sign(det N): two determinants of the input
//     doubles, no division;
//   - whether three planes meet in a point: det N != 0.
// Each sign is first taken from interval arithmetic (CGAL::Interval_nt with
// outward rounding): the vertex's coordinates bounded once when it is made,
// then the 4x4 and 3x3 determinants in intervals; only when an interval
// holds zero (the vertex on or within round-off of the plane) are the
// determinants evaluated exactly, in CGAL::Gmpzf (GMP integers times powers
// of two: every sum and product of doubles is exact). The rounded point of a
// vertex is the exact intersection rounded toward zero coordinate by
// coordinate (GMP's mpq_get_d): a function of the exact point alone, so two
// blocks sharing a corner get bitwise the same coordinates whichever three
// of the planes through it they know it by.
#pragma once

#include "dda/core/Types.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace dda::rockmass {

// A plane n . x = offset [m]; the coefficients are exact as given (a normal
// need not be a unit vector).
struct CutPlane {
	Vector3 normal;
	double offset = 0;
};

// Three plane indices, ascending.
using PlaneTriple = std::array<int, 3>;

// Certain bounds of a vertex's exact coordinates [m]: lo <= x <= hi, or
// bounded = false when the filter could not bound them (det N within its
// round-off of zero).
struct PointBounds {
	Vector3 lo = Vector3::Zero();
	Vector3 hi = Vector3::Zero();
	bool bounded = false;
};

// How often each stage settled a sign (for statistics and tests).
struct PredicateCounters {
	std::uint64_t boundsDecided = 0;    // from the vertex's coordinate bounds
	std::uint64_t intervalDecided = 0;  // from the determinants in intervals
	std::uint64_t exactDecided = 0;     // from the exact determinants
};

// Exact sign of det [n_i; n_j; n_k] (0: the three planes do not meet in one point).
int tripleSign(const std::vector<CutPlane>& planes, const PlaneTriple& t);

// Certain bounds of the exact intersection of the triple's planes.
PointBounds vertexBounds(const std::vector<CutPlane>& planes, const PlaneTriple& t);

// Exact sign of n_l . x - d_l at the exact intersection x of the triple's
// planes (which must meet in one point); 0 when l is one of them. `bounds`
// are vertexBounds(planes, t) (passed in so a caller computes them once).
int vertexSide(const std::vector<CutPlane>& planes, const PlaneTriple& t, const PointBounds& bounds, int l,
               PredicateCounters* counters = nullptr);

// The exact sign of n_l . x - d_l from the determinants alone (no bounds
// filter): the reference the filtered vertexSide must agree with.
int vertexSideExact(const std::vector<CutPlane>& planes, const PlaneTriple& t, int l);

// The exact intersection of the triple's planes, each coordinate rounded
// toward zero [m]. Throws InputError when the planes do not meet in one point.
Vector3 vertexPoint(const std::vector<CutPlane>& planes, const PlaneTriple& t);

// Certain range [lo, hi] of n . x - offset over the box lo <= x <= hi.
std::array<double, 2> boxRange(const CutPlane& plane, const Vector3& lo, const Vector3& hi);

}  // namespace dda::rockmass
