// Step 3 of the narrow phase (PairDetection.hpp): the vertex-face and
// edge-edge sub-contacts that represent a pair, from its entrance feature:
// the other block's corners on an entrance face, the face's own corners near
// the other block, edges crossing the face's edges, an edge entrance's
// crossing and what the best face finds away from it. No sub-contact is
// deeper than the pair's penetration (SubContactRules.hpp gives the rule).
// Units: m.
#pragma once

#include "Entrance.hpp"

#include <vector>

namespace dda::narrow {

// Step 3: the pair's sub-contacts into out.contacts (cleared, capacity kept)
// and its normal into out.normal, for `entrance` as step 2 chose it. An edge
// entrance whose edges do not cross strictly inside falls back to the best
// face, and a face entrance that finds nothing gives way to the next tied face
// that finds some: both change `entrance`.
void findSubContacts(const Prepared& a, const Prepared& b, const std::vector<FaceCandidate>& faces,
                     const AxisSearch& axes, const EntranceFeature& previous, const DetectionSettings& settings,
                     double sinTolerance, Scratch& s, Entrance& entrance, PairContacts& out);

}  // namespace dda::narrow
