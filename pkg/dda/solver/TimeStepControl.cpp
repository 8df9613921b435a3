#include "TimeStepControl.hpp"

#include "dda/core/StateStream.hpp"

#include <algorithm>

namespace dda {

double TimeStepControl::firstTry(const IntegratorSettings& settings) const {
	return nextTimeStep_ > 0 ? std::min(nextTimeStep_, settings.maxTimeStep) : settings.maxTimeStep;
}

bool TimeStepControl::accept(int attempt, bool converged, double largest, const IntegratorSettings& settings,
                             double& dt, StepStatistics& stats) {
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

void TimeStepControl::stepTaken(const IntegratorSettings& settings, double dt) {
	nextTimeStep_ = std::min(settings.maxTimeStep, dt * settings.timeStepGrowth);
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
