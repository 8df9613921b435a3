// Parameters of one implicit DDA step and what the step reports back.
#pragma once

#include "dda/block/Displacement.hpp"
#include "dda/solver/Settings.hpp"

namespace dda {

// One member per row of Settings.def, with its default; each setting's
// range, unit and meaning are there. validateSettings (Settings.hpp) checks
// a whole set.
struct IntegratorSettings {
#define DDA_SETTING(type, name, engineName, value, range, unit, doc) type name = value;
#include "dda/solver/Settings.def"

	// Shi's scheme needs no start-of-step acceleration a0.
	bool shiScheme() const { return newmarkBeta == 0.5 && newmarkGamma == 1.0; }
};

// The energy account of a scene [J] (World::energy; Python stats()['energy']).
// kinetic, gravity, strain and contact are the state's energies now; friction,
// damping and loads add up over the steps. Each term has its own formula (see
// World::accountStep and contactStepEnergy); none is the residual of the
// others. kinetic + gravity + strain + contact + friction + damping - loads
// - contactChanges is conserved by Shi's scheme to round-off and the
// second-order terms of the exact block update (rotation of J and of the
// stress, volume change), so a drift of it is a bug.
struct EnergyAccount {
	double kinetic = 0;   // 1/2 v^T M v, consistent mass: translation, rotation and strain rates
	double gravity = 0;   // -m g . c, potential of the last step's gravity
	double gravityChange = 0;  // -m g . (c - c0): the same relative to the blocks' initial centroids c0
	double strain = 0;    // V/2 sigma^T E^-1 sigma (the blocks' elastic energy, initial stress included)
	double contact = 0;   // energy in the closed contacts' springs at the end of the last step
	double friction = 0;  // dissipated by sliding (work of friction loads against the relative motion)
	double damping = 0;   // dissipated by the time scheme, the strain viscosity and velocityRatio < 1
	double loads = 0;     // work done on the blocks by point loads and fixed-point springs
	// Energy the contacts' springs gained between the end of one step and the
	// start of the next (D = 0 of the next step in its accepted states): new
	// contacts found penetrating, gaps linearised again from the moved
	// geometry, contacts that slide (their springs' energy lost), contacts
	// that vanish (a normal spring that opens within a step is damping). No formula of the scheme covers it; it is what
	// contact detection and the contact states add or remove.
	double contactChanges = 0;
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
	int unknowns = 0;                // size of the system solved: 12 per moving block, 6 per rigid one
	int rigidBlocks = 0;             // moving blocks that are rigid (6 unknowns: no strain, no stress)
	int strainUnknowns = 0;          // strain unknowns in the system (6 per deformable moving block)
	long solvedUnknowns = 0;         // unknowns the last solve factorised, all components (= unknowns)
	// contacts
	double contactDistance = 0;      // d0 used [m]
	long candidatePairs = 0;         // block pairs from the broad phase
	long shellPairs = 0;             // overlapping bounding volumes (MSC: shell pairs)
	long shellTests = 0;             // bounding-volume comparisons made
	long shells = 0;                 // bounding volumes
	long shellUpdates = 0;           // bounding volumes recomputed this step
	long subUnitPairs = 0;           // vertex-face plus edge-edge sub-unit pairs the candidates offer
	long subUnitTests = 0;           // vertex-face plane tests and edge-edge tests the narrow phase made
	long fullSearchPairs = 0;        // MSC pairs searched again with every sub-unit (deep penetration)
	int contactPairs = 0;            // block pairs within d0
	int contacts = 0;                // vertex-face and edge-edge sub-contacts
	int closedContacts = 0;          // sliding or locked at the end of the step
	int slidingContacts = 0;
	int openCloseIterations = 0;     // solves in the accepted attempt
	int openCloseIterationsTotal = 0;  // solves in all attempts of the step
	int stateChanges = 0;            // contact state changes in the accepted attempt
	int normalForceUpdates = 0;      // solves made only because tangential forces had not settled (all attempts)
	int lineSearches = 0;            // solves whose step was shortened by the line search (all attempts)
	int refinedComponents = 0;       // components solved by refinement, not factorised (all attempts)
	int refineIterations = 0;        // their conjugate-gradient iterations (all attempts)
	int refineFallbacks = 0;         // refinements that did not converge and were factorised (all attempts)
	int iterativeComponents = 0;     // components solved by the iterative path (all attempts)
	int iterativeIterations = 0;     // its conjugate-gradient iterations (all attempts)
	int iterativeFallbacks = 0;      // iterative solves that did not converge and were factorised (all attempts)
	int limitPasses = 0;             // passes made after the first because friction limits changed (all attempts)
	int limitsLowered = 0;           // groups whose limits did not settle and that went on in Coulomb-safe passes (all attempts)
	int limitsUnsettled = 0;         // groups start from rest's static steps accepted with limits unsettled (all attempts)
	// start from rest (IntegratorSettings::startFromRest): the settling before the
	// first step, in every step's report
	int settleSteps = 0;             // static steps the settling took (0: none was tried)
	int settledBlocks = 0;           // blocks brought to rest (0 when the settling did not converge)
	bool settleConverged = false;    // the settling reached equilibrium (else the scene starts as placed)
	int openCloseCuts = 0;           // dt cuts because the iteration did not converge
	long openCloseFailures = 0;      // steps accepted unconverged after maxStepCuts (cumulative)
	double maxPenetration = 0;       // deepest closed contact at the end of the step [m]
	int components = 0;              // independent systems of the last solve (moving blocks joined by closed contacts)
	int largestComponent = 0;        // blocks in the largest one
	int systemStructures = 0;        // times the system's structure was built (first solve, then after openings/closings)
	// work done or skipped ("effects on demand")
	long broadPhaseSkipped = 0;      // 1 when the broad phase reused cached pairs instead of a sort-and-sweep
	long pairsReused = 0;            // cached candidate pairs reused without a search
	long blocksResearched = 0;       // blocks searched against the others (all on a full search)
	long fixedPairsSearched = 0;     // candidate pairs of two fixed blocks given to the narrow phase (always 0)
	long frictionTerms = 0;          // shear springs and friction loads assembled, over all solves of the step
	long normalTerms = 0;            // closed-contact normal springs assembled, over all solves of the step
	long bodyForceBlocks = 0;        // block assemblies with a body force (gravity), over all attempts
	int frictionContacts = 0;        // contacts of the step with a friction coefficient > 0
	int bondedContacts = 0;          // contacts bonded at the end of the step
	int fixedBlocks = 0;             // blocks without unknowns
	bool staticAnalysis = false;     // velocityRatio == 0: velocities reset every step (Shi's static analysis)
	// CPU time of the contact detection's phases, the process's (all
	// threads) [s]: with one thread, the work without the machine's waits
	double cpuBroadPhase = 0;
	double cpuNarrowPhase = 0;
	// wall time per phase [s]
	double timeBroadPhase = 0;
	double timeNarrowPhase = 0;
	double timeAssembly = 0;
	double timeSolve = 0;
	double timeUpdate = 0;
	double timeTotal = 0;
};

}  // namespace dda
