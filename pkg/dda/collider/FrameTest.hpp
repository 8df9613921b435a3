// MSCCollider's frame test (MSCCollider.hpp): two shells whose boxes overlap
// are dropped when their extents are apart along an axis of either block's
// frame by more than 2 d0 + wA + wB plus the test's own round-off.
//
// Why that is safe: the linked sub-units' argument (MSCCollider.cpp) bounds
// |P - q| <= 2 d0 + wA + wB for the points P, q of a contact; for any unit
// direction u, |(P - q) . u| <= |P - q|, so two slices apart by more than
// that along u hold no such P and q. A slice lies in its extent (the
// parallelepiped of its ranges along the frame's axes), so a shell is
// projected on the other frame's axes through that parallelepiped, and the
// test adds its own round-off (kFrameRoundoffRelative x the lengths
// involved, far below w).
#pragma once

#include "MultiShellCover.hpp"

#include <Eigen/Core>

#include <vector>

namespace dda::msc {

// The frame test's own round-off: this x the lengths it is computed from
// [-] is added to the widening (~1e-14 is the bound with the frames above).
constexpr double kFrameRoundoffRelative = 1e-12;

// The test of one block pair (a, b): set up once, asked per shell pair. The
// test in b's frame is set up when first needed: in about half of the block
// pairs every shell pair is apart in a's frame already.
class FrameTest {
public:
	// margin: the boxes' widening by d0 [m]; low, high: the shells' extents
	// in their blocks' frames [m] (MultiShellCover::extentLow, extentHigh).
	FrameTest(const Frame& a, const Frame& b, double margin, const std::vector<Vector3>& low,
	          const std::vector<Vector3>& high)
	    : a_(a), b_(b), low_(low), high_(high), between_(b.origin - a.origin) {
		inA_ = a.axes * b.dual;
		sizeInA_ = inA_.cwiseAbs();
		offsetInA_ = a.axes * between_;
		const double roundoff = kFrameRoundoffRelative * (between_.cwiseAbs().sum() + 10 * (a.reach + b.reach));
		limit_ = 2 * margin + a.widening + b.widening + roundoff;
	}

	// Whether shell s of a and shell t of b are within the limit along every
	// axis of both frames.
	bool near(int s, int t) {
		if (apart(s, t, inA_, sizeInA_, offsetInA_)) return false;
		if (!frameB_) {
			inB_ = b_.axes * a_.dual;
			sizeInB_ = inB_.cwiseAbs();
			offsetInB_ = b_.axes * (-between_);
			frameB_ = true;
		}
		return !apart(t, s, inB_, sizeInB_, offsetInB_);
	}

private:
	// Whether shell s is apart from shell t by more than the limit along an
	// axis of s's frame (m = that frame's axes x t's dual, size = |m|
	// elementwise, offset = those axes x (t's origin - s's origin)).
	bool apart(int s, int t, const Eigen::Matrix3d& m, const Eigen::Matrix3d& size, const Vector3& offset) const {
		const Vector3 middle = offset + m * (0.5 * (low_[t] + high_[t]));
		const Vector3 half = size * (0.5 * (high_[t] - low_[t]));
		return ((low_[s] - middle - half).array() > limit_).any() || ((middle - half - high_[s]).array() > limit_).any();
	}

	const Frame& a_;
	const Frame& b_;
	const std::vector<Vector3>& low_;
	const std::vector<Vector3>& high_;
	const Vector3 between_;
	Eigen::Matrix3d inA_, sizeInA_, inB_, sizeInB_;
	Vector3 offsetInA_, offsetInB_;
	double limit_;
	bool frameB_ = false;
};

}  // namespace dda::msc
