// The sub-units (vertices, edges, faces) of a pair of blocks that may meet in
// the narrow phase. A broad phase with sub-block volumes (MSC's shells) links
// each candidate pair to the sub-units of its overlapping volumes; the narrow
// phase then loops over those only (Wu et al. 2014, Sec. 4.2).
#pragma once

#include "ConvexPolyhedron.hpp"

#include <array>
#include <cstddef>
#include <vector>

namespace dda {

// A read-only view of sorted, unique sub-unit indices owned by the broad
// phase (valid until its next findPairs): many pairs share one block's list.
class SubUnitList {
public:
	SubUnitList() = default;
	explicit SubUnitList(const std::vector<int>& indices)
	    : first_(indices.data()), count_(static_cast<int>(indices.size())) {}
	const int* begin() const { return first_; }
	const int* end() const { return first_ + count_; }
	std::size_t size() const { return static_cast<std::size_t>(count_); }
	bool empty() const { return count_ == 0; }
	int operator[](std::size_t k) const { return first_[k]; }

private:
	const int* first_ = nullptr;
	int count_ = 0;
};

// Indices into the blocks' shapes: [0] of the pair's first block (A), [1] of
// the second (B), each sorted and unique.
struct LinkedSubUnits {
	std::array<SubUnitList, 2> vertices, edges, faces;
	// The paper's "sub-unit loops" of the pair: Va x Fb + Vb x Fa + Ea x Eb.
	long subUnitPairs() const {
		const auto n = [](const SubUnitList& v) { return static_cast<long>(v.size()); };
		return n(vertices[0]) * n(faces[1]) + n(vertices[1]) * n(faces[0]) + n(edges[0]) * n(edges[1]);
	}
};

// The sub-unit loops of a pair when every sub-unit takes part.
inline long allSubUnitPairs(const PolyhedronTopology& a, const PolyhedronTopology& b) {
	const auto v = [](const PolyhedronTopology& s) { return static_cast<long>(s.vertexCount()); };
	const auto e = [](const PolyhedronTopology& s) { return static_cast<long>(s.edges.size()); };
	const auto f = [](const PolyhedronTopology& s) { return static_cast<long>(s.faces.size()); };
	return v(a) * f(b) + v(b) * f(a) + e(a) * e(b);
}

}  // namespace dda
