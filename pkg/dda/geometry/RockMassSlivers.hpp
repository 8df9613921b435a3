// Slivers of a cut rock mass (RockMassCutter.hpp, step 4): blocks below the
// smallest volume, or whose corners buildConvexPolyhedron (hence ddaBlock)
// refuses, are merged into a neighbour or reported, never dropped.
//
// A problem block S is tried against the blocks of its part with which it
// shares a face (the same plane, opposite sides, overlapping with positive
// area), the largest shared area first. The union of S and a neighbour N
// across plane p is convex exactly when every corner of S lies inside every
// face plane of N other than p and every corner of N inside those of S
// (then the union is the intersection of those half-spaces; decided with
// the exact side predicate). The merged block is that intersection, made by
// clipping the part's own cell by its planes, so its corners are exact
// plane triples like every other's. A merged block that is still a problem
// is tried again; a block no merge can take is reported with the reason.
// The faces of the merged block may meet its neighbours' faces in part
// (T-junctions), as a non-persistent joint's do.
#pragma once

#include "dda/geometry/ConvexCell.hpp"

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace dda::rockmass {

struct SliverOutcome {
	std::vector<Cell> kept;
	std::vector<std::pair<Cell, std::string>> reported;  // with the reason
	long merged = 0;
};

// `problemOf` says why a cell cannot stay as it is ("" when it can).
SliverOutcome mergeSlivers(std::vector<Cell> cells, const std::vector<Cell>& partCells,
                           const std::function<std::string(const Cell&)>& problemOf, VertexTable& table);

}  // namespace dda::rockmass
