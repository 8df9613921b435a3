// What a cut cell (ConvexCell.hpp) becomes for a user: corners, faces and
// volume (RockBlock), with near-coincident corners made one, and the check
// that ddaBlock will take it. Units: m, m^3.
//
// Corner snapping. Exact cutting keeps every feature of the planes as given,
// also those that are only there because the input was rounded: dips of 40
// and 70 degrees give set planes whose exact trace on a face meets another's
// (tan 20 = cot 70) but whose double coefficients miss it by 4e-15 m, so the
// exact cut has an edge 4e-15 m long, which ddaBlock refuses (corners closer
// than 1e-12 of the block's size coincide). CornerSnap makes every cluster of
// output corners closer than `tolerance` (linked by chains of such pairs) one
// corner, the cluster's lexicographically smallest. It is a function of the
// corners' values alone, so blocks sharing a corner still share it bit for
// bit. cutRockMass uses 1e-12 x the domain's bounding-box diagonal, at or
// above ddaBlock's coincidence tolerance for any block of the domain.
#pragma once

#include "dda/geometry/ConvexCell.hpp"

#include <string>
#include <unordered_map>
#include <vector>

namespace dda::rockmass {

struct RockBlock {
	int part = 0;
	std::vector<Vector3> corners;           // [m], exact corners rounded toward zero (then snapped)
	std::vector<PlaneTriple> cornerPlanes;  // three planes whose exact intersection each corner is (before snapping)
	std::vector<std::vector<int>> faces;    // corner indices, counter-clockwise seen from outside
	std::vector<int> facePlanes;            // the plane (index into RockMass::planes) of each face
	double volume = 0;                      // [m^3]
	std::string problem;                    // slivers: why it was neither kept nor merged
};

class CornerSnap {
public:
	CornerSnap() = default;
	// `points`: every corner value that may be asked for (repeats allowed).
	CornerSnap(const std::vector<Vector3>& points, double tolerance);
	// The corner p stands for.
	const Vector3& operator()(const Vector3& p) const;
	long moved() const { return static_cast<long>(moved_.size()); }

private:
	struct Bits {
		std::size_t operator()(const Vector3& p) const;
	};
	std::unordered_map<Vector3, Vector3, Bits> moved_;
};

// The cell as a block: snapped corners (each once), faces without repeated
// corners (a face left with fewer than 3 is dropped), volume from them.
RockBlock toBlock(const Cell& cell, VertexTable& table, const CornerSnap& snap);

// Why the block cannot be one of the result's ("" when it can): a volume
// below minVolume, or (checkShapes) corners buildConvexPolyhedron refuses. A
// cheap test passes most blocks without the full check: corners at least
// 10 x the coincidence tolerance apart and each 10 x the coplanar tolerance
// off the plane of every face it is not on.
std::string blockProblem(const RockBlock& block, double minVolume, bool checkShapes);

}  // namespace dda::rockmass
