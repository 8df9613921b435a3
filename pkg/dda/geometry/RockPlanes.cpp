// The planes of a rock mass (RockPlanes.hpp): domain faces, joint sets with
// their keyed random choices, single joints and excavations.
#include "RockPlanes.hpp"

#include "dda/core/Errors.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

namespace dda::rockmass {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string number(double x) {
	char buffer[64];
	const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
	return std::string(buffer, result.ptr);
}

// sin and cos of an angle in degrees, exact (0, 1, -1) at multiples of 90:
// the angle is reduced exactly to r in [-45, 45] and a quadrant.
std::pair<double, double> sinCosDegrees(double degrees) {
	double reduced = std::fmod(degrees, 360.0);  // exact
	const double quadrant = std::nearbyint(reduced / 90.0);
	const double r = (reduced - 90.0 * quadrant) * (kPi / 180.0);  // reduced - 90 q is exact
	const double s = std::sin(r), c = std::cos(r);
	std::pair<double, double> out;
	switch ((static_cast<int>(quadrant) % 4 + 4) % 4) {
		case 0: out = {s, c}; break;
		case 1: out = {c, -s}; break;
		case 2: out = {-s, -c}; break;
		default: out = {-c, s}; break;
	}
	return {out.first + 0.0, out.second + 0.0};  // + 0.0: -0 becomes 0
}

[[noreturn]] void badJoint(int index, const std::string& what) {
	throw InputError("jointSets[" + std::to_string(index) + "]: " + what);
}

void requireFinite(int index, const Vector3& v, const char* name) {
	if (!v.allFinite()) badJoint(index, std::string(name) + " must be finite");
}

void requireRange(int index, double value, double lo, double hi, bool loOpen, const char* name, const char* range) {
	const bool ok = std::isfinite(value) && (loOpen ? value > lo : value >= lo) && value <= hi;
	if (!ok) badJoint(index, std::string(name) + " must be in " + range + ", got " + number(value));
}

void validateSet(const JointSpec& spec, int index) {
	requireRange(index, spec.dip, 0, 90, false, "dip", "[0, 90] degrees");
	requireRange(index, spec.dipDirection, 0, 360, false, "dipDirection", "[0, 360] degrees");
	requireRange(index, spec.spacing, 0, std::numeric_limits<double>::max(), true, "spacing", "(0, inf) m");
	requireFinite(index, spec.origin, "origin");
	requireRange(index, spec.persistence, 0, 1, true, "persistence", "(0, 1]");
	requireRange(index, spec.fisherK, 0, std::numeric_limits<double>::max(), false, "fisherK", "[0, inf) (0: none)");
	if (spec.distribution == SpacingDistribution::Lognormal)
		requireRange(index, spec.spacingStd, 0, std::numeric_limits<double>::max(), true, "spacingStd",
		             "(0, inf) m for lognormal spacings");
}

// One random spacing [m] of the set: gap number `gap` (>= 1) upward or downward from plane 0.
double randomSpacing(const JointSpec& spec, int index, long gap, bool upward, std::uint64_t seed) {
	const RandomPurpose purpose = upward ? RandomPurpose::SpacingUp : RandomPurpose::SpacingDown;
	const auto key = static_cast<std::uint64_t>(gap);
	const double u = keyedUniform(seed, purpose, {static_cast<std::uint64_t>(index), key, 0});
	if (spec.distribution == SpacingDistribution::Exponential) return -spec.spacing * std::log(u);
	const double v = keyedUniform(seed, purpose, {static_cast<std::uint64_t>(index), key, 1});
	const double z = std::sqrt(-2 * std::log(u)) * std::cos(2 * kPi * v);  // Box-Muller
	const double cv = spec.spacingStd / spec.spacing;
	const double s2 = std::log1p(cv * cv);
	return std::exp(std::log(spec.spacing) - s2 / 2 + std::sqrt(s2) * z);
}

// (k, offset along the pole from the origin [m]) of the set's planes over [lo, hi].
std::vector<std::pair<long, double>> setOffsets(const JointSpec& spec, int index, double lo, double hi,
                                                std::uint64_t seed) {
	const double expected = (hi - lo) / spec.spacing;
	if (!(expected <= kMaxPlanesPerSet)) {
		badJoint(index, "spacing " + number(spec.spacing) + " m puts about " + number(std::ceil(expected)) +
		                    " planes across the domain, more than " + std::to_string(kMaxPlanesPerSet));
	}
	std::vector<std::pair<long, double>> offsets;
	if (spec.distribution == SpacingDistribution::Fixed) {
		const long first = static_cast<long>(std::floor(lo / spec.spacing)) - 1;
		const long last = static_cast<long>(std::ceil(hi / spec.spacing)) + 1;
		for (long k = first; k <= last; ++k) offsets.emplace_back(k, static_cast<double>(k) * spec.spacing);
		return offsets;
	}
	const long limit = 4 * kMaxPlanesPerSet;
	std::vector<std::pair<long, double>> below;
	for (double o = 0; o >= lo && static_cast<long>(below.size()) < limit;) {
		const long k = -static_cast<long>(below.size()) - 1;
		o -= randomSpacing(spec, index, -k, false, seed);
		below.emplace_back(k, o);
	}
	offsets.assign(below.rbegin(), below.rend());
	offsets.emplace_back(0, 0.0);
	for (double o = 0; o <= hi && static_cast<long>(offsets.size()) < 2 * limit;) {
		const long k = offsets.back().first + 1;
		o += randomSpacing(spec, index, k, true, seed);
		offsets.emplace_back(k, o);
	}
	if (static_cast<long>(offsets.size()) >= 2 * limit) badJoint(index, "random spacings put too many planes across the domain");
	return offsets;
}

void appendSet(const JointSpec& spec, int index, const DomainExtent& domain, std::uint64_t seed,
               std::vector<PlaneRecord>& out, int& nextFamily) {
	validateSet(spec, index);
	const Vector3 pole = poleOf(spec.dip, spec.dipDirection);
	const double atOrigin = pole.dot(spec.origin);
	double tmin = std::numeric_limits<double>::infinity(), tmax = -tmin;
	for (const Vector3& p : domain.corners) {
		tmin = std::min(tmin, pole.dot(p));
		tmax = std::max(tmax, pole.dot(p));
	}
	// A scattered plane is anchored on the pole's line through the origin; one
	// anchored up to a domain diameter outside can still cross the domain.
	const double margin = spec.fisherK > 0 ? domain.diameter : 0;
	const auto offsets = setOffsets(spec, index, tmin - margin - atOrigin, tmax + margin - atOrigin, seed);
	const int family = spec.fisherK > 0 ? -1 : nextFamily++;
	for (const auto& [k, offset] : offsets) {
		PlaneRecord record;
		record.kind = PlaneKind::JointSet;
		record.source = index;
		record.number = static_cast<int>(k);
		record.persistence = spec.persistence;
		record.family = family;
		if (spec.fisherK > 0) {
			const auto key = {static_cast<std::uint64_t>(index), static_cast<std::uint64_t>(k)};
			const Vector3 normal = fisherSample(pole, spec.fisherK, keyedUniform(seed, RandomPurpose::FisherTheta, key),
			                                    keyedUniform(seed, RandomPurpose::FisherPhi, key));
			record.plane = CutPlane{normal, normal.dot(spec.origin + offset * pole)};
		} else {
			record.plane = CutPlane{pole, atOrigin + offset};
		}
		out.push_back(record);
	}
}

CutPlane planeThrough(const JointSpec& spec, int index) {
	requireFinite(index, spec.point, "the plane's point");
	requireFinite(index, spec.normal, "the plane's normal");
	if (spec.normal.isZero(0)) badJoint(index, "the plane's normal must not be zero");
	return CutPlane{spec.normal, spec.normal.dot(spec.point)};
}

}  // namespace

const char* planeKindName(PlaneKind kind) {
	switch (kind) {
		case PlaneKind::Bound: return "bound";
		case PlaneKind::Domain: return "domain";
		case PlaneKind::JointSet: return "set";
		case PlaneKind::Joint: return "joint";
		case PlaneKind::Excavation: return "excavation";
	}
	return "?";
}

Vector3 poleOf(double dipDegrees, double dipDirectionDegrees) {
	const auto [sinDip, cosDip] = sinCosDegrees(dipDegrees);
	const auto [sinDir, cosDir] = sinCosDegrees(dipDirectionDegrees);
	return Vector3(sinDip * sinDir, sinDip * cosDir, cosDip);
}

std::vector<CutPlane> convexFacePlanes(const std::vector<Vector3>& corners, const std::string& what) {
	ConvexPolyhedron poly;
	try {
		poly = buildConvexPolyhedron(corners);
	} catch (const InputError& e) {
		throw InputError(what + ": " + e.what());
	}
	const auto lexLess = [&](int a, int b) {
		const Vector3 &p = poly.vertices[a], &q = poly.vertices[b];
		return std::tie(p.x(), p.y(), p.z()) < std::tie(q.x(), q.y(), q.z());
	};
	std::vector<CutPlane> planes;
	for (const std::vector<int>& face : poly.faces) {
		std::vector<int> sorted = face;
		std::sort(sorted.begin(), sorted.end(), lexLess);
		const Vector3& a = poly.vertices[sorted[0]];
		Vector3 best = Vector3::Zero();
		for (std::size_t i = 1; i < sorted.size(); ++i)
			for (std::size_t j = i + 1; j < sorted.size(); ++j) {
				const Vector3 n = (poly.vertices[sorted[i]] - a).cross(poly.vertices[sorted[j]] - a);
				if (n.squaredNorm() > best.squaredNorm()) best = n;
			}
		if (best.dot(faceNormal(poly.vertices, face)) < 0) best = -best;
		planes.push_back(CutPlane{best, best.dot(a)});
	}
	return planes;
}

void appendJointPlanes(const JointSpec& spec, int index, const DomainExtent& domain, std::uint64_t seed,
                       std::vector<PlaneRecord>& out, int& nextFamily) {
	PlaneRecord record;
	record.source = index;
	switch (spec.kind) {
		case JointSpec::Kind::Set: appendSet(spec, index, domain, seed, out, nextFamily); return;
		case JointSpec::Kind::Plane:
			requireRange(index, spec.persistence, 0, 1, true, "persistence", "(0, 1]");
			record.kind = PlaneKind::Joint;
			record.plane = planeThrough(spec, index);
			record.persistence = spec.persistence;
			out.push_back(record);
			return;
		case JointSpec::Kind::ExcavateHalfSpace: {
			// Stored as the outward face of the removed region: n . x >= n . point inside it.
			record.kind = PlaneKind::Excavation;
			const CutPlane plane = planeThrough(spec, index);
			record.plane = CutPlane{-plane.normal, -plane.offset};
			out.push_back(record);
			return;
		}
		case JointSpec::Kind::ExcavateRegion: {
			record.kind = PlaneKind::Excavation;
			if (spec.regions.empty()) badJoint(index, "an excavation needs a region");
			for (std::size_t r = 0; r < spec.regions.size(); ++r) {
				const auto faces = convexFacePlanes(spec.regions[r], "jointSets[" + std::to_string(index) +
				                                                         "] (excavated region " + std::to_string(r) + ")");
				record.region = static_cast<int>(r);
				for (std::size_t f = 0; f < faces.size(); ++f) {
					record.plane = faces[f];
					record.number = static_cast<int>(f);
					out.push_back(record);
				}
			}
			return;
		}
	}
}

std::uint64_t mixHash(std::uint64_t h, std::uint64_t value) {
	// splitmix64's finaliser over the running hash and the value
	std::uint64_t x = h ^ (value + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
	x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
	x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
	return x ^ (x >> 31);
}

double keyedUniform(std::uint64_t seed, RandomPurpose purpose, std::initializer_list<std::uint64_t> key) {
	std::uint64_t h = mixHash(mixHash(0x5eed5eed5eed5eedULL, seed), static_cast<std::uint64_t>(purpose));
	for (std::uint64_t k : key) h = mixHash(h, k);
	return (static_cast<double>(h >> 11) + 0.5) * 0x1p-53;
}

Vector3 fisherSample(const Vector3& mean, double k, double u, double v) {
	double w = 1 + std::log(u + (1 - u) * std::exp(-2 * k)) / k;
	w = std::clamp(w, -1.0, 1.0);
	const double s = std::sqrt(std::max(0.0, 1 - w * w));
	const Vector3 helper = std::abs(mean.z()) < 0.9 ? Vector3::UnitZ() : Vector3::UnitX();
	const Vector3 e1 = mean.cross(helper).normalized();
	const Vector3 e2 = mean.cross(e1);
	const double phi = 2 * kPi * v;
	return w * mean + s * (std::cos(phi) * e1 + std::sin(phi) * e2);
}

}  // namespace dda::rockmass
