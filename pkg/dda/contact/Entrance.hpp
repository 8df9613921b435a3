// Step 2 of the narrow phase (PairDetection.hpp): which axis is the pair's
// entrance feature, the face the other block's corners enter or the crossing
// edges, with Shi's hysteresis (a contact keeps its entrance face while it
// stays within the hysteresis of the best axis). Units: m.
#pragma once

#include "SeparatingAxes.hpp"

#include <vector>

namespace dda::narrow {

// An entrance feature and the separation of its axis [m].
struct Entrance {
	EntranceFeature feature;
	double separation = 0;
	bool keptPrevious = false;  // the previous step's entrance, kept by hysteresis
};

// Step 2, in order: the previous step's entrance while its separation stays
// within `hysteresis` [m] of the best axis; an edge axis only when it beats
// the best face by more than lengthTolerance [m]; else chooseFace.
Entrance chooseEntrance(const std::vector<FaceCandidate>& faces, const AxisSearch& axes, const Prepared& a,
                        const Prepared& b, double lengthTolerance, double hysteresis, const EntranceFeature& previous);

// The entrance face among the face axes: largest separation; within
// lengthTolerance of it, the previous entrance face if it is one of them, else
// the larger area, then A before B, then the lower face index (the order of
// `faces`).
const FaceCandidate& chooseFace(const std::vector<FaceCandidate>& faces, const Prepared& a, const Prepared& b,
                                double lengthTolerance, const EntranceFeature& previous);

// Whether the pair's previous entrance feature (if any) is among the sub-units
// the pair may use.
bool previousLinked(const Prepared& a, const Prepared& b, const EntranceFeature& previous);

}  // namespace dda::narrow
