// Filtered exact signs of plane-triple vertices (PlanePredicates.hpp). The
// interval stages run under CGAL::Protect_FPU_rounding (rounding toward +inf,
// which CGAL::Interval_nt<false> needs); the exact stage is integer
// arithmetic (CGAL::Gmpzf), whatever the rounding mode.
#include "PlanePredicates.hpp"

#include "dda/core/Errors.hpp"

#include <CGAL/Gmpzf.h>
#include <CGAL/Interval_nt.h>
#include <CGAL/determinant.h>
#include <gmp.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace dda::rockmass {
namespace {

using Interval = CGAL::Interval_nt<false>;
using Exact = CGAL::Gmpzf;

int signOf(const Interval& x) {
	if (x.inf() > 0) return 1;
	if (x.sup() < 0) return -1;
	return 2;  // not certain
}

int signOf(const Exact& x) { return static_cast<int>(CGAL::sign(x)); }

// Row r of the 4 x 4 matrix [n d] of a plane, in number type T.
template <class T>
std::array<T, 4> row(const CutPlane& p) {
	return {T(p.normal.x()), T(p.normal.y()), T(p.normal.z()), T(p.offset)};
}

template <class T>
T det3(const std::array<T, 4>& a, const std::array<T, 4>& b, const std::array<T, 4>& c) {
	return CGAL::determinant(a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]);
}

// det N with column `column` (0..2) replaced by the offsets (Cramer's rule).
template <class T>
T det3Column(const std::array<T, 4>& a, const std::array<T, 4>& b, const std::array<T, 4>& c, int column) {
	std::array<T, 4> ra = a, rb = b, rc = c;
	ra[column] = a[3], rb[column] = b[3], rc[column] = c[3];
	return det3(ra, rb, rc);
}

template <class T>
T det4(const std::array<T, 4>& a, const std::array<T, 4>& b, const std::array<T, 4>& c, const std::array<T, 4>& d) {
	return CGAL::determinant(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3], c[0], c[1], c[2], c[3], d[0], d[1], d[2],
	                         d[3]);
}

template <class T>
int sideFromDeterminants(const std::vector<CutPlane>& planes, const PlaneTriple& t, int l) {
	const auto a = row<T>(planes[t[0]]), b = row<T>(planes[t[1]]), c = row<T>(planes[t[2]]), d = row<T>(planes[l]);
	const int sm = signOf(det4(a, b, c, d));
	const int sn = signOf(det3(a, b, c));
	if (sm == 2 || sn == 2) return 2;
	return -sm * sn;
}

// The exact quotient of two Gmpzf (m 2^e each) rounded toward zero to a
// double: the integer quotient Q of the mantissas, shifted to at least 64
// significant bits, truncated toward zero (mpz_tdiv_q), then to 53 bits
// (mpz_get_d truncates), then scaled by a power of two (exact). Truncating
// to an integer first loses nothing the 53-bit truncation keeps. No gcd, as
// mpq would need.
double quotientTowardZero(const Exact& numerator, const Exact& denominator) {
	if (signOf(numerator) == 0) return 0;
	mpz_t a, b, q;
	mpz_init(a), mpz_init(b), mpz_init(q);
	mpz_abs(a, numerator.man());
	mpz_abs(b, denominator.man());
	const long bitsA = static_cast<long>(mpz_sizeinbase(a, 2)), bitsB = static_cast<long>(mpz_sizeinbase(b, 2));
	const long shift = std::max(0L, 66 + bitsB - bitsA);
	mpz_mul_2exp(a, a, static_cast<mp_bitcnt_t>(shift));
	mpz_tdiv_q(q, a, b);
	const double truncated = mpz_get_d(q);
	mpz_clear(a), mpz_clear(b), mpz_clear(q);
	const double value = std::ldexp(truncated, static_cast<int>(numerator.exp() - denominator.exp() - shift));
	return signOf(numerator) * signOf(denominator) < 0 ? -value : value;
}

std::string tripleText(const PlaneTriple& t) {
	return "(" + std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) + ")";
}

}  // namespace

int tripleSign(const std::vector<CutPlane>& planes, const PlaneTriple& t) {
	{
		CGAL::Protect_FPU_rounding<true> guard;
		const int s = signOf(det3(row<Interval>(planes[t[0]]), row<Interval>(planes[t[1]]), row<Interval>(planes[t[2]])));
		if (s != 2) return s;
	}
	return signOf(det3(row<Exact>(planes[t[0]]), row<Exact>(planes[t[1]]), row<Exact>(planes[t[2]])));
}

PointBounds vertexBounds(const std::vector<CutPlane>& planes, const PlaneTriple& t) {
	CGAL::Protect_FPU_rounding<true> guard;
	const auto a = row<Interval>(planes[t[0]]), b = row<Interval>(planes[t[1]]), c = row<Interval>(planes[t[2]]);
	const Interval n = det3(a, b, c);
	PointBounds bounds;
	if (signOf(n) == 2) return bounds;
	for (int k = 0; k < 3; ++k) {
		const Interval x = det3Column(a, b, c, k) / n;
		bounds.lo[k] = x.inf();
		bounds.hi[k] = x.sup();
	}
	bounds.bounded = true;
	return bounds;
}

int vertexSide(const std::vector<CutPlane>& planes, const PlaneTriple& t, const PointBounds& bounds, int l,
               PredicateCounters* counters) {
	if (l == t[0] || l == t[1] || l == t[2]) return 0;
	{
		CGAL::Protect_FPU_rounding<true> guard;
		if (bounds.bounded) {
			const CutPlane& p = planes[l];
			Interval s = Interval(p.normal.x()) * Interval(bounds.lo.x(), bounds.hi.x()) +
			             Interval(p.normal.y()) * Interval(bounds.lo.y(), bounds.hi.y()) +
			             Interval(p.normal.z()) * Interval(bounds.lo.z(), bounds.hi.z()) - Interval(p.offset);
			const int sign = signOf(s);
			if (sign != 2) {
				if (counters) ++counters->boundsDecided;
				return sign;
			}
		}
		const int sign = sideFromDeterminants<Interval>(planes, t, l);
		if (sign != 2) {
			if (counters) ++counters->intervalDecided;
			return sign;
		}
	}
	if (counters) ++counters->exactDecided;
	return sideFromDeterminants<Exact>(planes, t, l);
}

int vertexSideExact(const std::vector<CutPlane>& planes, const PlaneTriple& t, int l) {
	if (l == t[0] || l == t[1] || l == t[2]) return 0;
	return sideFromDeterminants<Exact>(planes, t, l);
}

Vector3 vertexPoint(const std::vector<CutPlane>& planes, const PlaneTriple& t) {
	const auto a = row<Exact>(planes[t[0]]), b = row<Exact>(planes[t[1]]), c = row<Exact>(planes[t[2]]);
	const Exact n = det3(a, b, c);
	if (signOf(n) == 0) throw InputError("planes " + tripleText(t) + " do not meet in one point");
	Vector3 x;
	for (int k = 0; k < 3; ++k) x[k] = quotientTowardZero(det3Column(a, b, c, k), n);
	return x;
}

std::array<double, 2> boxRange(const CutPlane& plane, const Vector3& lo, const Vector3& hi) {
	CGAL::Protect_FPU_rounding<true> guard;
	Interval s = Interval(plane.normal.x()) * Interval(lo.x(), hi.x()) +
	             Interval(plane.normal.y()) * Interval(lo.y(), hi.y()) +
	             Interval(plane.normal.z()) * Interval(lo.z(), hi.z()) - Interval(plane.offset);
	return {s.inf(), s.sup()};
}

}  // namespace dda::rockmass
