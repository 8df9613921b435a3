#include "TimeStepControl.hpp"

#include "dda/core/StateStream.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace dda {

namespace {
// The smallest volume ratio det(I + S) one step may give a deformable block
// [-]. The strain increment is a linearisation (ln(1 + e) against e is 20% off
// at e = -0.3 per axis), and at det(I + S) = 0 the block would turn inside
// out, its volume and mass matrix negative. Such a step is cut like a
// too-large one (the strain increment shrinks with dt); if the cuts run out,
// the step is refused with a named error and the scene stays as it was.
constexpr double kMinStepJacobian = 0.5;
}  // namespace

double TimeStepControl::firstTry(const IntegratorSettings& settings) const {
	return nextTimeStep_ > 0 ? std::min(nextTimeStep_, settings.maxTimeStep) : settings.maxTimeStep;
}

bool TimeStepControl::accept(int attempt, bool converged, double largest, const StepShrink& volume,
                             const IntegratorSettings& settings, double& dt, StepStatistics& stats) {
	if (converged && volume.jacobian < kMinStepJacobian) {
		if (attempt == settings.maxStepCuts) {
			std::ostringstream message;
			message << "the DDA step would shrink block " << volume.block << " to " << volume.jacobian
			        << " of its volume (at most to " << kMinStepJacobian << " in one step) even at dt = " << dt
			        << " s: its material is too soft for its loads at this step (raise young, lower dt, or "
			        << "check the loads)";
			throw std::runtime_error(message.str());
		}
		dt *= 0.5;
		++stats.stepCuts;
		return false;
	}
	if (!converged) {
		if (attempt == settings.maxStepCuts) {
			++openCloseFailures_;
			return true;
		}
		dt *= settings.openCloseShrink;
		++stats.openCloseCuts;
		++stats.stepCuts;
		return false;
	}
	if (largest <= stats.allowedDisplacement || stats.allowedDisplacement <= 0) return true;
	if (attempt == settings.maxStepCuts) {
		++displacementLimitMisses_;
		return true;
	}
	const double shrink = std::clamp(settings.timeStepSafety * stats.allowedDisplacement / largest,
	                                 settings.minTimeStepShrink, settings.maxTimeStepShrink);
	dt *= shrink;
	++stats.stepCuts;
	return false;
}

void TimeStepControl::stepTaken(const IntegratorSettings& settings, double dt, double largest, double allowed) {
	// Grown by timeStepGrowth, but not past the dt at which the accepted
	// step's motion would reach timeStepSafety x the bound (as a cut would
	// set it; displacement grows at least linearly with dt). Growing by 1.3
	// regardless made a block falling at the bound redo every step: each
	// step tried 1.3 x the dt its cut had found, overshot and was cut again
	// (the 70-block drop, blocks falling off the trough: every step from
	// 2.6 s on, each a second factorisation). Only the first dt tried
	// changes: every accepted step is still one within the bound.
	double factor = settings.timeStepGrowth;
	if (largest > 0 && allowed > 0)
		factor = std::min(factor, std::max(settings.minTimeStepShrink, settings.timeStepSafety * allowed / largest));
	nextTimeStep_ = std::min(settings.maxTimeStep, dt * factor);
}

void TimeStepControl::writeState(StateWriter& out) const {
	out.pod(nextTimeStep_);
	out.pod(openCloseFailures_);
	out.pod(displacementLimitMisses_);
}

void TimeStepControl::readState(StateReader& in) {
	in.pod(nextTimeStep_);
	in.pod(openCloseFailures_);
	in.pod(displacementLimitMisses_);
}

}  // namespace dda
