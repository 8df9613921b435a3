// Parameters of one implicit DDA step and what the step reports back.
#pragma once

#include "dda/block/Displacement.hpp"

namespace dda {

struct IntegratorSettings {
	// Largest time step [s], > 0. The step actually taken may be smaller (see
	// the displacement bound below); the next step grows back towards it.
	double maxTimeStep = 1e-3;
	// Body acceleration [m/s^2]; zero means no body-force assembly at all.
	Vector3 gravity = Vector3::Zero();
	// Shi's dynamic coefficient in [0, 1]: the fraction of the end velocity that
	// carries into the next step. 1 = fully dynamic, 0 = static analysis.
	double velocityRatio = 1;
	// Largest vertex displacement allowed in one step [m]. When <= 0 it is
	// maxDisplacementRatio x half the largest extent of the scene's bounding box
	// (Shi's g2 x w0), measured at the first step after blocks were added.
	double maxDisplacement = 0;
	double maxDisplacementRatio = 0.01;  // [-], > 0
	// A step whose largest displacement d exceeds the allowed a is redone with
	// dt x clamp(safety x a / d, minShrink, maxShrink). Displacement is at most
	// linear in dt for the shrink factors used, so one redo usually suffices.
	double timeStepSafety = 0.9;
	double minTimeStepShrink = 0.1;
	double maxTimeStepShrink = 0.9;
	// After an accepted step the next one tries dt x timeStepGrowth (<= maxTimeStep).
	double timeStepGrowth = 1.3;
	// Redo a step at most this many times; a step still too large after that is
	// accepted and counted in StepStatistics::displacementLimitMisses.
	int maxStepCuts = 30;
	// Stiffness of a fixed point's penalty spring when the block's own is not
	// given: factor x Young's modulus x block size (cube root of volume) [N/m].
	double fixedPointPenaltyFactor = 1000;
	// Worker threads for per-block work; 0 = OpenMP's default. Results do not
	// depend on the count.
	int threads = 0;
};

// What the last step did, readable from Python as yade_dda.stats().
struct StepStatistics {
	double dt = 0;                   // time step taken [s]
	int stepCuts = 0;                // times this step was redone with a smaller dt
	long displacementLimitMisses = 0;  // steps accepted above the bound (cumulative)
	double maxDisplacement = 0;      // largest vertex displacement of the step [m]
	double allowedDisplacement = 0;  // bound used [m]
	int blocks = 0;                  // all blocks
	int movingBlocks = 0;            // blocks with unknowns
	int unknowns = 0;                // size of the system solved
	// wall time per phase [s]
	double timeAssembly = 0;
	double timeSolve = 0;
	double timeUpdate = 0;
	double timeTotal = 0;
};

}  // namespace dda
