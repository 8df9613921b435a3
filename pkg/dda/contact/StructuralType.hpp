// Step 4 of the narrow phase (PairDetection.hpp): the pair's structural
// contact type (Wu et al. 2014, Table 1) from the features its contact points
// lie on. Units: m.
#pragma once

#include "PreparedBlock.hpp"

namespace dda::narrow {

// Step 4: on each block, the points of the pair's sub-contacts (pointI or
// pointJ) lie within `featureTolerance` [m] (d0 + lengthTolerance) of one
// corner (vertex), else of one edge (edge), else span a face; without
// sub-contacts, the corners within it of the block's extreme along the pair's
// normal are used instead. Two edges are parallel within sinTolerance.
ContactType classifyPair(const Prepared& a, const Prepared& b, const PairContacts& pair, double featureTolerance,
                         double sinTolerance, Scratch& s);

}  // namespace dda::narrow
