// Blocks that overlap when they enter a scene.
//
// Contacts are penalty springs: a pair that starts overlapping by delta is
// pushed apart with the energy of its springs, about n kn delta^2 / 2 for n
// closed sub-contacts. For 1 m rock cubes (E = 10 GPa, kn = 4e11 N/m) an
// overlap of 7.6 mm is some 1e7 J, a block thrown at hundreds of m/s: not
// physics but a placement error. So a block entering the scene (at the first
// step, or added mid-run) may overlap another by at most
//
//   tolerance = min(d0, max(2 W / kn, kInitialOverlapRelative x L))      [m]
//
// with W the weight of all moving blocks of the scene [N], kn the pair's
// normal contact stiffness (ContactEquations: contactPenaltyFactor x the
// smaller E x size) [N/m], L the larger block size (cube root of the volume)
// [m] and d0 the contact distance of the step. 2 W / kn is how deep one
// spring sinks holding the whole weight applied at once, so a scene rebuilt
// from the blocks of a settled run is accepted; the second term accepts
// coordinates rounded to about a micrometre of a metre block; d0 caps it,
// beyond which the narrow phase's sub-contacts are no longer reliable. These
// are the first and last terms of the penetration tolerance (doc/testing.md, "Penetration tolerance").
// Fixed-fixed pairs are never checked (they never touch each other's motion).
#pragma once

#include "IntegratorSettings.hpp"
#include "dda/block/Block.hpp"

#include <vector>

namespace dda {

// Initial overlaps accepted without gravity: this x the larger block size [-].
inline constexpr double kInitialOverlapRelative = 1e-6;

struct InitialOverlap {
	int blockA = -1, blockB = -1;  // indices into the block list, a < b
	double depth = 0;              // overlap [m]: least translation that separates them (separating axes)
	double tolerance = 0;          // largest overlap accepted for this pair [m]
};

// Pairs (a, b), at least one of them at index >= firstNew, not both fixed,
// overlapping deeper than their tolerance; deepest first. `blocks` is the
// whole scene (W and the scene size for d0 are taken over all of it, as
// World::step does at the first step after blocks were added).
std::vector<InitialOverlap> findInitialOverlaps(const std::vector<const Block*>& blocks, int firstNew,
                                                const IntegratorSettings& settings);

}  // namespace dda
