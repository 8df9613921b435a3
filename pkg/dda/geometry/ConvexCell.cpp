// Cutting convex cells exactly (ConvexCell.hpp).
#include "ConvexCell.hpp"

#include "RockPlanes.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

namespace dda::rockmass {
namespace {

[[noreturn]] void internalError(const std::string& what) {
	throw std::logic_error("rock-mass cutter internal error: " + what);
}

// Plane indices fit in 21 bits each of a 64-bit key.
constexpr int kPlaneBits = 21;
constexpr int kMaxPlanes = 1 << kPlaneBits;

void updateBounds(Cell& cell, VertexTable& table) {
	cell.bounded = true;
	const double inf = std::numeric_limits<double>::infinity();
	cell.lo = Vector3::Constant(inf);
	cell.hi = Vector3::Constant(-inf);
	for (int v : cell.vertices) {
		const PointBounds& b = table.bounds(v);
		if (!b.bounded) {
			cell.bounded = false;
			cell.lo = Vector3::Constant(-inf);
			cell.hi = Vector3::Constant(inf);
			return;
		}
		cell.lo = cell.lo.cwiseMin(b.lo);
		cell.hi = cell.hi.cwiseMax(b.hi);
	}
}

// A crossing edge: local vertices a < b with strictly opposite signs, and
// the vertex where the plane meets it.
struct Crossing {
	int a, b, vertex;
};

// The vertex on each crossing edge, sorted by (a, b). The edge's planes are
// those of its two faces: the face that traverses it a -> b and the one
// that traverses it b -> a.
std::vector<Crossing> crossings(const Cell& cell, int plane, const std::vector<signed char>& signs,
                                VertexTable& table) {
	std::vector<std::array<int, 3>> directed;  // (from, to, face)
	directed.reserve(cell.corners.size());
	for (int f = 0; f < cell.faceCount(); ++f) {
		const int begin = cell.faceStart[f], end = cell.faceStart[f + 1];
		for (int i = begin; i < end; ++i)
			directed.push_back({cell.corners[i], cell.corners[i + 1 < end ? i + 1 : begin], f});
	}
	std::sort(directed.begin(), directed.end());
	std::vector<Crossing> out;
	for (const auto& [u, v, f] : directed) {
		if (u > v || signs[u] * signs[v] >= 0) continue;
		const auto other = std::lower_bound(directed.begin(), directed.end(), std::array<int, 3>{v, u, -1});
		if (other == directed.end() || (*other)[0] != v || (*other)[1] != u) internalError("edge with one face");
		const int vertex = table.intern(refPlane(cell.faceRefs[f]), refPlane(cell.faceRefs[(*other)[2]]), plane);
		out.push_back({u, v, vertex});
	}
	return out;  // sorted by (a, b): directed was
}

// The part of the cell on side `sigma` (-1 below, +1 above) of the plane.
Cell keepSide(const Cell& cell, int plane, int sigma, const std::vector<signed char>& signs,
              const std::vector<Crossing>& crossing, VertexTable& table) {
	Cell out;
	out.part = cell.part;
	std::vector<int> local(cell.vertices.size(), -1);
	std::vector<char> onPlane;
	for (std::size_t v = 0; v < cell.vertices.size(); ++v) {
		if (signs[v] != 0 && signs[v] != sigma) continue;
		local[v] = static_cast<int>(out.vertices.size());
		out.vertices.push_back(cell.vertices[v]);
		onPlane.push_back(signs[v] == 0);
	}
	std::vector<int> crossingLocal(crossing.size(), -1);
	const auto crossingVertex = [&](int u, int v) {
		const Crossing key{std::min(u, v), std::max(u, v), 0};
		const auto it = std::lower_bound(crossing.begin(), crossing.end(), key, [](const Crossing& x, const Crossing& y) {
			return std::tie(x.a, x.b) < std::tie(y.a, y.b);
		});
		if (it == crossing.end() || it->a != key.a || it->b != key.b) internalError("crossing edge not found");
		int& index = crossingLocal[it - crossing.begin()];
		if (index < 0) {
			index = static_cast<int>(out.vertices.size());
			out.vertices.push_back(it->vertex);
			onPlane.push_back(1);
		}
		return index;
	};
	std::vector<std::pair<int, int>> cap;  // edges of the cap face, in its order
	out.faceStart.push_back(0);
	for (int f = 0; f < cell.faceCount(); ++f) {
		const int begin = cell.faceStart[f], end = cell.faceStart[f + 1];
		if (std::none_of(cell.corners.begin() + begin, cell.corners.begin() + end, [&](int v) { return signs[v] == sigma; }))
			continue;  // nothing of this face is strictly on this side
		const std::size_t first = out.corners.size();
		for (int i = begin; i < end; ++i) {
			const int u = cell.corners[i], v = cell.corners[i + 1 < end ? i + 1 : begin];
			if (signs[u] == 0 || signs[u] == sigma) out.corners.push_back(local[u]);
			if (signs[u] * signs[v] < 0) out.corners.push_back(crossingVertex(u, v));
		}
		const std::size_t m = out.corners.size() - first;
		for (std::size_t i = 0; i < m; ++i) {
			const int a = out.corners[first + i], b = out.corners[first + (i + 1) % m];
			if (onPlane[a] && onPlane[b]) {
				cap.emplace_back(b, a);
				break;
			}
		}
		out.faceRefs.push_back(cell.faceRefs[f]);
		out.faceStart.push_back(static_cast<int>(out.corners.size()));
	}
	if (cap.size() < 3) internalError("cap face with " + std::to_string(cap.size()) + " edges");
	int at = cap.front().first;
	for (std::size_t n = 0; n < cap.size(); ++n) {
		out.corners.push_back(at);
		const auto next = std::find_if(cap.begin(), cap.end(), [at](const auto& e) { return e.first == at; });
		if (next == cap.end()) internalError("open cap face");
		at = next->second;
	}
	if (at != cap.front().first) internalError("cap face is not one cycle");
	out.faceRefs.push_back(faceRef(plane, sigma > 0));
	out.faceStart.push_back(static_cast<int>(out.corners.size()));
	updateBounds(out, table);
	return out;
}

}  // namespace

int VertexTable::intern(int a, int b, int c) {
	PlaneTriple t{a, b, c};
	std::sort(t.begin(), t.end());
	if (t[0] < 0 || t[2] >= kMaxPlanes || t[0] == t[1] || t[1] == t[2]) internalError("bad plane triple");
	const std::uint64_t key = (static_cast<std::uint64_t>(t[0]) << (2 * kPlaneBits)) |
	                          (static_cast<std::uint64_t>(t[1]) << kPlaneBits) | static_cast<std::uint64_t>(t[2]);
	const auto [it, inserted] = ids_.try_emplace(key, static_cast<int>(triples_.size()));
	if (inserted) {
		triples_.push_back(t);
		bounds_.push_back(vertexBounds(planes_, t));
		points_.emplace_back(Vector3::Zero());
		pointKnown_.push_back(0);
	}
	return it->second;
}

const Vector3& VertexTable::point(int v) {
	if (!pointKnown_[v]) {
		points_[v] = vertexPoint(planes_, triples_[v]);
		pointKnown_[v] = 1;
	}
	return points_[v];
}

Cell boxCell(int part, const std::array<int, 6>& planes, VertexTable& table) {
	Cell cell;
	cell.part = part;
	for (int v = 0; v < 8; ++v) cell.vertices.push_back(table.intern(planes[v & 1], planes[2 + ((v >> 1) & 1)], planes[4 + (v >> 2)]));
	// corner v = i + 2 j + 4 k is (x_i, y_j, z_k); each face counter-clockwise seen from outside
	const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
	cell.faceStart.push_back(0);
	for (int f = 0; f < 6; ++f) {
		cell.faceRefs.push_back(faceRef(planes[f], f % 2 == 0));
		cell.corners.insert(cell.corners.end(), faces[f], faces[f] + 4);
		cell.faceStart.push_back(static_cast<int>(cell.corners.size()));
	}
	updateBounds(cell, table);
	return cell;
}

int classify(const Cell& cell, int plane, VertexTable& table, std::vector<signed char>& signs) {
	signs.resize(cell.vertices.size());
	int mask = 0;
	for (std::size_t v = 0; v < cell.vertices.size(); ++v) {
		const int s = table.side(cell.vertices[v], plane);
		signs[v] = static_cast<signed char>(s);
		mask |= s < 0 ? 1 : s > 0 ? 2 : 0;
	}
	return mask;
}

std::pair<Cell, Cell> split(const Cell& cell, int plane, const std::vector<signed char>& signs, VertexTable& table) {
	const std::vector<Crossing> crossing = crossings(cell, plane, signs, table);
	return {keepSide(cell, plane, -1, signs, crossing, table), keepSide(cell, plane, 1, signs, crossing, table)};
}

std::optional<Cell> clip(const Cell& cell, int ref, VertexTable& table) {
	std::vector<signed char> signs;
	const int plane = refPlane(ref);
	const int mask = classify(cell, plane, table, signs);
	const int outside = refOutside(ref);
	const int insideBit = outside > 0 ? 1 : 2;
	if (!(mask & insideBit)) return std::nullopt;
	if (mask != 3) return cell;
	const std::vector<Crossing> crossing = crossings(cell, plane, signs, table);
	return keepSide(cell, plane, -outside, signs, crossing, table);
}

std::uint64_t cellKey(const Cell& cell) {
	std::vector<int> refs = cell.faceRefs;
	std::sort(refs.begin(), refs.end());
	std::uint64_t h = mixHash(0xce11ULL, static_cast<std::uint64_t>(cell.part));
	for (int r : refs) h = mixHash(h, static_cast<std::uint64_t>(r));
	return h;
}

double cellVolume(const Cell& cell, VertexTable& table) {
	const Vector3 origin = table.point(cell.vertices[0]);
	double six = 0;
	for (int f = 0; f < cell.faceCount(); ++f) {
		const int begin = cell.faceStart[f], end = cell.faceStart[f + 1];
		const Vector3 a = table.point(cell.vertices[cell.corners[begin]]) - origin;
		for (int i = begin + 1; i + 1 < end; ++i) {
			const Vector3 b = table.point(cell.vertices[cell.corners[i]]) - origin;
			const Vector3 c = table.point(cell.vertices[cell.corners[i + 1]]) - origin;
			six += a.dot(b.cross(c));
		}
	}
	return six / 6;
}

}  // namespace dda::rockmass
