// The sub-units (vertices, edges, faces) of a pair of blocks that may meet in
// the narrow phase. A broad phase with sub-block volumes (MSC's shells) links
// each candidate pair to the sub-units of its overlapping volumes; the narrow
// phase then loops over those only (Wu et al. 2014, Sec. 4.2).
#pragma once

#include "dda/geometry/ConvexPolyhedron.hpp"

#include <array>
#include <vector>

namespace dda {

// Indices into the blocks' shapes: [0] of the pair's first block (A), [1] of
// the second (B), each sorted and unique.
struct LinkedSubUnits {
	std::array<std::vector<int>, 2> vertices, edges, faces;
	// The paper's "sub-unit loops" of the pair: Va x Fb + Vb x Fa + Ea x Eb.
	long subUnitPairs() const {
		const auto n = [](const std::vector<int>& v) { return static_cast<long>(v.size()); };
		return n(vertices[0]) * n(faces[1]) + n(vertices[1]) * n(faces[0]) + n(edges[0]) * n(edges[1]);
	}
};

// The sub-unit loops of a pair when every sub-unit takes part.
inline long allSubUnitPairs(const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
	const auto v = [](const ConvexPolyhedron& s) { return static_cast<long>(s.vertices.size()); };
	const auto e = [](const ConvexPolyhedron& s) { return static_cast<long>(s.edges.size()); };
	const auto f = [](const ConvexPolyhedron& s) { return static_cast<long>(s.faces.size()); };
	return v(a) * f(b) + v(b) * f(a) + e(a) * e(b);
}

}  // namespace dda
