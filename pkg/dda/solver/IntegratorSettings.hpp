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
	double boundaryWork = 0;  // work done on the moving blocks by prescribed motions of fixed blocks (BaseMotion.hpp)
	// Energy the contacts' springs gained between the end of one step and the
	// start of the next (D = 0 of the next step in its accepted states): new
	// contacts found penetrating, gaps linearised again from the moved
	// geometry, contacts that slide (their springs' energy lost), contacts
	// that vanish (a normal spring that opens within a step is damping). No formula of the scheme covers it; it is what
	// contact detection and the contact states add or remove.
	double contactChanges = 0;
};

// What the last step did, readable from Python as yade_dda.stats(): one
// member per row of Statistics.def, zero until the step sets it; each
// statistic's unit and meaning are there.
struct StepStatistics {
#define DDA_STAT(type, name, group, key, unit, doc) type name = type();
#include "dda/solver/Statistics.def"
};

}  // namespace dda
