// Time-step control of World::step: the dt each step tries first (the last
// accepted one x timeStepGrowth, less when that step moved near the bound,
// at most maxTimeStep), the largest vertex
// displacement a step may make, and the cuts of an attempt that did not
// converge (dt x openCloseShrink) or moved too far (dt x clamp(safety x
// allowed / largest, minTimeStepShrink, maxTimeStepShrink)), up to
// maxStepCuts (IntegratorSettings.hpp has the rules' parameters). Counts the
// steps accepted unconverged or beyond the bound.
#pragma once

#include "IntegratorSettings.hpp"

#include <Eigen/Geometry>

namespace dda {

// The smallest volume ratio det(I + S) an attempt gives a deformable block [-],
// and that block's index (-1 when no block moves).
struct StepShrink {
	double jacobian = 1.0;
	int block = -1;
};

class StateWriter;
class StateReader;

class TimeStepControl {
public:
	// Largest vertex displacement allowed in one step [m]: maxDisplacement, or
	// without it maxDisplacementRatio x motionHalfSize() (Shi's g2 x w0) [m].
	// motionHalfSize is called only then (World measures w0 when first asked).
	template <class MotionHalfSize>
	static double allowedDisplacement(const IntegratorSettings& settings, MotionHalfSize&& motionHalfSize) {
		return settings.maxDisplacement > 0 ? settings.maxDisplacement
		                                    : settings.maxDisplacementRatio * motionHalfSize();
	}
	// Shi's w0 [m]: half the largest side of the bounding box of the blocks
	// that move (of all blocks when none moves). Fixed blocks are left out: a
	// 46 m floor under 1 m blocks made w0 23 m, so the default step could move
	// a block 0.23 m and d0 reached 0.575 m, half the blocks' size, where
	// from the moving blocks' own extent both follow the blocks. No energy
	// comes from the rule: the allowed displacement only decides when an
	// attempt is redone with a smaller dt, and every accepted step, at any
	// dt, is a Newmark step on beta = gamma/2, which creates none; d0 only
	// decides which pairs are candidates, and an open contact within d0
	// couples nothing. `corners(k)` gives block k's vertices, `fixed(k)`
	// whether it is fixed.
	template <class Corners, class Fixed>
	static double motionHalfSize(int blockCount, Corners&& corners, Fixed&& fixed) {
		for (const bool movingOnly : {true, false}) {
			Eigen::AlignedBox3d box;
			for (int k = 0; k < blockCount; ++k)
				if (!movingOnly || !fixed(k))
					for (const Vector3& x : corners(k)) box.extend(x);
			if (!box.isEmpty()) return 0.5 * box.sizes().maxCoeff();
		}
		return 0.0;
	}
	// The dt a step tries first [s].
	double firstTry(const IntegratorSettings& settings) const;
	// After attempt number `attempt` (0 first) at dt: whether it is accepted;
	// else dt is cut for the next attempt. `largest` is its largest vertex
	// displacement [m], `volume` its smallest volume ratio (accept's rule:
	// below kMinStepJacobian the step is cut, and refused with a named error
	// when the cuts run out); the cuts are counted in stats.
	bool accept(int attempt, bool converged, double largest, const StepShrink& volume,
	            const IntegratorSettings& settings, double& dt, StepStatistics& stats);
	// The step was taken at dt, moving at most `largest` [m] with `allowed`
	// [m] the bound: the next tries dt x timeStepGrowth, or less if the
	// step's motion was near the bound (dt x timeStepSafety x allowed /
	// largest, not below minTimeStepShrink), at most maxTimeStep.
	void stepTaken(const IntegratorSettings& settings, double dt, double largest, double allowed);
	// The next step tries dt [s] first (settling's static steps).
	void setNextTry(double dt) { nextTimeStep_ = dt; }
	long displacementLimitMisses() const { return displacementLimitMisses_; }
	long openCloseFailures() const { return openCloseFailures_; }
	// Saving (World::writeState / readState): next dt, failures, misses.
	void writeState(StateWriter& out) const;
	void readState(StateReader& in);

private:
	double nextTimeStep_ = 0;  // dt to try first in the next step; 0 = maxTimeStep
	long openCloseFailures_ = 0;
	long displacementLimitMisses_ = 0;
};

}  // namespace dda
