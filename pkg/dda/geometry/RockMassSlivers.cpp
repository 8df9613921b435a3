// Merging or reporting slivers (RockMassSlivers.hpp).
#include "RockMassSlivers.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace dda::rockmass {
namespace {

std::vector<Vector3> facePoints(const Cell& cell, int face, VertexTable& table) {
	std::vector<Vector3> points;
	for (int i = cell.faceStart[face]; i < cell.faceStart[face + 1]; ++i)
		points.push_back(table.point(cell.vertices[cell.corners[i]]));
	return points;
}

using Point2 = Eigen::Vector2d;

double cross2(const Point2& a, const Point2& b) { return a.x() * b.y() - a.y() * b.x(); }

double signedArea(const std::vector<Point2>& polygon) {
	double twice = 0;
	for (std::size_t i = 0; i < polygon.size(); ++i) twice += cross2(polygon[i], polygon[(i + 1) % polygon.size()]);
	return twice / 2;
}

// The polygon projected along the largest component of `normal`, counter-clockwise.
std::vector<Point2> projected(const std::vector<Vector3>& polygon, const Vector3& normal) {
	int drop = 0;
	normal.cwiseAbs().maxCoeff(&drop);
	std::vector<Point2> out;
	for (const Vector3& p : polygon) out.emplace_back(p[(drop + 1) % 3], p[(drop + 2) % 3]);
	if (signedArea(out) < 0) std::reverse(out.begin(), out.end());
	return out;
}

// Area [m^2] of the overlap of two convex polygons on one plane of normal n
// (Sutherland-Hodgman in the projection; doubles: it only ranks neighbours).
double overlapArea(const std::vector<Vector3>& a, const std::vector<Vector3>& b, const Vector3& normal) {
	std::vector<Point2> subject = projected(a, normal);
	const std::vector<Point2> window = projected(b, normal);
	for (std::size_t e = 0; e < window.size() && !subject.empty(); ++e) {
		const Point2 p = window[e], q = window[(e + 1) % window.size()];
		std::vector<Point2> next;
		for (std::size_t i = 0; i < subject.size(); ++i) {
			const Point2 u = subject[i], v = subject[(i + 1) % subject.size()];
			const double su = cross2(q - p, u - p), sv = cross2(q - p, v - p);
			if (su >= 0) next.push_back(u);
			if ((su >= 0) != (sv >= 0)) next.push_back(u + (v - u) * (su / (su - sv)));
		}
		subject = std::move(next);
	}
	if (subject.size() < 3) return 0;
	const Vector3 n = normal.cwiseAbs();
	return signedArea(subject) * normal.norm() / n.maxCoeff();
}

// Every corner of `a` inside every face plane of `b` but `plane`.
bool cornersInside(const Cell& a, const Cell& b, int plane, VertexTable& table) {
	for (int ref : b.faceRefs) {
		if (refPlane(ref) == plane) continue;
		for (int v : a.vertices)
			if (table.side(v, refPlane(ref)) * refOutside(ref) > 0) return false;
	}
	return true;
}

Cell mergedCell(const Cell& partCell, const Cell& a, const Cell& b, int plane, VertexTable& table) {
	std::vector<int> refs;
	for (const Cell* c : {&a, &b})
		for (int ref : c->faceRefs)
			if (refPlane(ref) != plane) refs.push_back(ref);
	std::sort(refs.begin(), refs.end());
	refs.erase(std::unique(refs.begin(), refs.end()), refs.end());
	Cell cell = partCell;
	for (int ref : refs) {
		std::optional<Cell> clipped = clip(cell, ref, table);
		if (!clipped) throw std::logic_error("rock-mass cutter internal error: a merged block has no volume");
		cell = std::move(*clipped);
	}
	return cell;
}

bool boxesTouch(const Cell& a, const Cell& b) {
	return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

struct Neighbour {
	double area;
	int cell;
	int plane;
};

// The blocks that share a face with block s, the largest shared area first.
std::vector<Neighbour> neighboursOf(int s, const std::vector<Cell>& cells, const std::vector<char>& alive,
                                    const std::unordered_map<int, std::vector<int>>& byPlane, VertexTable& table) {
	const Cell& cell = cells[s];
	std::vector<Neighbour> out;
	for (int f = 0; f < cell.faceCount(); ++f) {
		const int ref = cell.faceRefs[f];
		const auto found = byPlane.find(refPlane(ref));
		if (found == byPlane.end()) continue;
		for (int c : found->second) {
			if (c == s || !alive[c] || cells[c].part != cell.part || !boxesTouch(cell, cells[c])) continue;
			const auto& refs = cells[c].faceRefs;
			const auto g = std::find(refs.begin(), refs.end(), ref ^ 1);
			if (g == refs.end()) continue;
			const double area = overlapArea(facePoints(cell, f, table),
			                                facePoints(cells[c], static_cast<int>(g - refs.begin()), table),
			                                table.planes()[refPlane(ref)].normal);
			if (area > 0) out.push_back({area, c, refPlane(ref)});
		}
	}
	std::sort(out.begin(), out.end(), [](const Neighbour& x, const Neighbour& y) {
		return x.area != y.area ? x.area > y.area : x.cell < y.cell;
	});
	out.erase(std::unique(out.begin(), out.end(), [](const Neighbour& x, const Neighbour& y) { return x.cell == y.cell; }),
	          out.end());
	return out;
}

}  // namespace

SliverOutcome mergeSlivers(std::vector<Cell> cells, const std::vector<Cell>& partCells,
                           const std::function<std::string(const Cell&)>& problemOf, VertexTable& table) {
	SliverOutcome outcome;
	std::vector<char> alive(cells.size(), 1);
	std::vector<std::pair<double, int>> queue;
	for (std::size_t c = 0; c < cells.size(); ++c)
		if (!problemOf(cells[c]).empty())
			queue.emplace_back(cellVolume(cells[c], table), static_cast<int>(c));
	if (queue.empty()) {
		outcome.kept = std::move(cells);
		return outcome;
	}
	std::sort(queue.begin(), queue.end());
	std::unordered_map<int, std::vector<int>> byPlane;
	for (std::size_t c = 0; c < cells.size(); ++c)
		for (int ref : cells[c].faceRefs) byPlane[refPlane(ref)].push_back(static_cast<int>(c));
	for (std::size_t head = 0; head < queue.size(); ++head) {
		const int s = queue[head].second;
		if (!alive[s]) continue;
		const std::string problem = problemOf(cells[s]);
		if (problem.empty()) continue;
		const std::vector<Neighbour> neighbours = neighboursOf(s, cells, alive, byPlane, table);
		bool merged = false;
		for (const Neighbour& n : neighbours) {
			if (!cornersInside(cells[s], cells[n.cell], n.plane, table) ||
			    !cornersInside(cells[n.cell], cells[s], n.plane, table))
				continue;
			cells[n.cell] = mergedCell(partCells[cells[s].part], cells[s], cells[n.cell], n.plane, table);
			alive[s] = 0;
			for (int ref : cells[n.cell].faceRefs) byPlane[refPlane(ref)].push_back(n.cell);
			queue.emplace_back(cellVolume(cells[n.cell], table), n.cell);
			++outcome.merged;
			merged = true;
			break;
		}
		if (merged) continue;
		alive[s] = 0;
		outcome.reported.emplace_back(
		    cells[s], problem + (neighbours.empty() ? "; it shares no face with another block of its part"
		                                            : "; its union with each block it shares a face with is not convex"));
	}
	for (std::size_t c = 0; c < cells.size(); ++c)
		if (alive[c]) outcome.kept.push_back(std::move(cells[c]));
	return outcome;
}

}  // namespace dda::rockmass
