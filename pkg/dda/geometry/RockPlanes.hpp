// Where the planes of a rock mass come from: a convex domain's faces, joint
// sets (dip, dip direction, spacing, origin; Fisher-scattered orientations and
// random spacings on request), single joints and excavations. Geometry only;
// RockMassCutter.hpp cuts with them. SI units: m, degrees where named.
//
// Conventions (geology, z up, y north, x east): a plane's dip d in [0, 90] is
// its angle below the horizontal; its dip direction a in [0, 360] is the
// azimuth, clockwise from north (+y), of its steepest downward line. Its pole
// (upward unit normal) is (sin d sin a, sin d cos a, cos d): a plane with dip
// 30 and dip direction 90 descends towards +x.
//
// Random choices are drawn from a keyed generator: each number is a hash
// (splitmix64) of the seed, a purpose tag and the indices it belongs to (set,
// plane number, ...), never the next number of a stream, so no result
// depends on the order in which anything is visited.
#pragma once

#include "dda/geometry/PlanePredicates.hpp"

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

namespace dda::rockmass {

enum class SpacingDistribution { Fixed, Exponential, Lognormal };

// One entry of the joint list.
struct JointSpec {
	enum class Kind {
		Set,                // a family of planes (dip, dipDirection, spacing, origin, ...)
		Plane,              // one joint through `point` with normal `normal`
		ExcavateHalfSpace,  // removes n . (x - point) > 0
		ExcavateRegion,     // removes the convex hull of each corner list of `regions`
	};
	Kind kind = Kind::Set;
	double dip = 0;           // [deg], 0..90
	double dipDirection = 0;  // [deg], 0..360
	double spacing = 1;       // [m], mean spacing along the pole, > 0
	Vector3 origin = Vector3::Zero();  // [m], a point of plane 0 of the set
	double persistence = 1;   // (0, 1]: chance that a plane cuts a block it crosses
	double fisherK = 0;       // Fisher concentration of the poles (0: all planes parallel)
	SpacingDistribution distribution = SpacingDistribution::Fixed;
	double spacingStd = 0;    // [m], standard deviation of lognormal spacings
	Vector3 point = Vector3::Zero();   // Plane, ExcavateHalfSpace [m]
	Vector3 normal = Vector3::UnitZ(); // Plane, ExcavateHalfSpace
	std::vector<std::vector<Vector3>> regions;  // ExcavateRegion: convex corner lists [m]
};

// What a plane of the cut is.
enum class PlaneKind { Bound, Domain, JointSet, Joint, Excavation };
const char* planeKindName(PlaneKind kind);

struct PlaneRecord {
	CutPlane plane;
	PlaneKind kind = PlaneKind::Bound;
	int source = -1;  // Domain: part; JointSet, Joint, Excavation: index in the joint list
	int number = 0;   // JointSet: plane number k along the pole (0 through origin); Domain, region: face
	int region = 0;   // Excavation: which region of the entry
	double persistence = 1;
	// Planes of one family share their normal bit for bit and come in
	// ascending offset (a joint set without Fisher scatter); -1: none.
	int family = -1;
};

// The pole of a plane of dip and dip direction [deg] (header comment).
Vector3 poleOf(double dipDegrees, double dipDirectionDegrees);

// The face planes of the convex hull of `corners`, outward (n . x <= offset
// inside). Each face's plane is exact through three of its corners: the
// lexicographically smallest and the two that span the largest triangle with
// it, n = (b - a) x (c - a), offset = n . a; so two parts sharing a face with
// the same corners get exactly opposite planes. Throws InputError (prefixed
// by `what`) for corners that are not a convex block's.
std::vector<CutPlane> convexFacePlanes(const std::vector<Vector3>& corners, const std::string& what);

// The range of the domain the sets must cover: its corners [m].
struct DomainExtent {
	std::vector<Vector3> corners;
	double diameter = 0;  // bounding-box diagonal [m]
};

// The planes of joint `index` of the list (a Set, Plane or excavation) over
// the domain, appended to `out`; `nextFamily` numbers the families. Throws
// InputError naming the entry for bad values.
void appendJointPlanes(const JointSpec& spec, int index, const DomainExtent& domain, std::uint64_t seed,
                       std::vector<PlaneRecord>& out, int& nextFamily);

// The keyed generator: a uniform number in (0, 1) from the seed and a key.
enum class RandomPurpose : std::uint64_t { FisherTheta = 1, FisherPhi, SpacingUp, SpacingDown, Persistence, Normal };
double keyedUniform(std::uint64_t seed, RandomPurpose purpose, std::initializer_list<std::uint64_t> key);
std::uint64_t mixHash(std::uint64_t h, std::uint64_t value);

// A unit vector drawn from the Fisher distribution of concentration k > 0
// about the unit vector `mean` (u, v uniform in (0, 1)): cos(theta) =
// 1 + ln(u + (1 - u) exp(-2k)) / k, azimuth 2 pi v.
Vector3 fisherSample(const Vector3& mean, double k, double u, double v);

// The largest number of planes one set may put across the domain.
inline constexpr long kMaxPlanesPerSet = 200000;

}  // namespace dda::rockmass
