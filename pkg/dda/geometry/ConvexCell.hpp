// A convex block of the rock-mass cutter held exactly: the planes of its
// faces and its vertices, each vertex the exact intersection of three planes
// (PlanePredicates.hpp). Cutting a cell by a plane classifies its vertices
// exactly (-, 0, +); the plane cuts the cell when some vertex lies strictly
// on each side, and then each part keeps the vertices on its side or on the
// plane, gains the points where edges with strictly opposite ends cross the
// plane (vertex: the plane and the edge's two face planes) and a cap face on
// the plane. Every vertex kept is a true corner of its part (an extreme point
// of a convex set stays extreme in a convex subset), so faces stay strictly
// convex polygons and the topology never needs a tolerance. Units: m.
#pragma once

#include "dda/geometry/PlanePredicates.hpp"

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

namespace dda::rockmass {

// The vertices of all cells, one record per distinct plane triple, so two
// cells that know a corner by the same triple share one record.
class VertexTable {
public:
	explicit VertexTable(const std::vector<CutPlane>& planes) : planes_(planes) {}
	// The vertex of three planes (any order) that meet in one point.
	int intern(int a, int b, int c);
	const PlaneTriple& triple(int v) const { return triples_[v]; }
	const PointBounds& bounds(int v) const { return bounds_[v]; }
	// Exact sign of n . x - d of plane `plane` at vertex v.
	int side(int v, int plane) { return vertexSide(planes_, triples_[v], bounds_[v], plane, &counters_); }
	// The exact vertex rounded toward zero [m], computed once.
	const Vector3& point(int v);
	std::size_t size() const { return triples_.size(); }
	const std::vector<CutPlane>& planes() const { return planes_; }
	const PredicateCounters& counters() const { return counters_; }

private:
	const std::vector<CutPlane>& planes_;
	std::unordered_map<std::uint64_t, int> ids_;
	std::vector<PlaneTriple> triples_;
	std::vector<PointBounds> bounds_;
	std::vector<Vector3> points_;
	std::vector<char> pointKnown_;
	PredicateCounters counters_;
};

// A face's plane and the side its cell lies on: ref = 2 plane + 1 when the
// outward normal is -n (the cell on n . x >= d), 2 plane when it is +n.
inline int faceRef(int plane, bool outwardIsMinusNormal) { return 2 * plane + (outwardIsMinusNormal ? 1 : 0); }
inline int refPlane(int ref) { return ref >> 1; }
// The sign of n . x - d outside the cell, across this face.
inline int refOutside(int ref) { return (ref & 1) ? -1 : 1; }

struct Cell {
	int part = 0;
	std::vector<int> vertices;   // VertexTable ids
	std::vector<int> faceRefs;   // one per face
	std::vector<int> faceStart;  // faceRefs.size() + 1 offsets into corners
	std::vector<int> corners;    // indices into vertices, counter-clockwise seen from outside
	Vector3 lo = Vector3::Zero(), hi = Vector3::Zero();  // certain bounds of the vertices
	bool bounded = false;
	int faceCount() const { return static_cast<int>(faceRefs.size()); }
};

// The box cell of the six planes x = lo, x = hi, y = lo, y = hi, z = lo,
// z = hi (indices in that order; normals +x, +y, +z).
Cell boxCell(int part, const std::array<int, 6>& planes, VertexTable& table);

// Signs of n . x - d of `plane` at the cell's vertices; returns 1 | 2 bits:
// 1 when some vertex is strictly below, 2 when some is strictly above.
int classify(const Cell& cell, int plane, VertexTable& table, std::vector<signed char>& signs);

// The parts below (n . x <= d) and above of a cell that `plane` cuts
// (classify returned 3, with these signs).
std::pair<Cell, Cell> split(const Cell& cell, int plane, const std::vector<signed char>& signs, VertexTable& table);

// The part of the cell inside the half-space of face ref `ref`: the cell
// itself when wholly inside, nullopt when nothing with volume is inside.
std::optional<Cell> clip(const Cell& cell, int ref, VertexTable& table);

// A hash of the cell's part and face refs (sorted): the same region gives
// the same key whatever order it was made in.
std::uint64_t cellKey(const Cell& cell);

// Volume [m^3] from the rounded vertices (faces fanned from their first corner).
double cellVolume(const Cell& cell, VertexTable& table);

}  // namespace dda::rockmass
