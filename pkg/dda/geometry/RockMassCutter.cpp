// The rock-mass cutter's driver (RockMassCutter.hpp): planes, the parts'
// cells, the joint families, excavations, slivers, output.
#include "RockMassCutter.hpp"

#include "dda/core/Errors.hpp"
#include "dda/geometry/ConvexCell.hpp"
#include "dda/geometry/RockMassSlivers.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace dda::rockmass {
namespace {

using Clock = std::chrono::steady_clock;

// Corners closer than this fraction of the domain's diagonal are one (RockBlocks.hpp).
constexpr double kSnapRelative = 1e-12;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

struct Setup {
	std::vector<PlaneRecord> records;
	std::vector<CutPlane> planes;
	std::array<int, 6> bounds{};
	double diameter = 0;  // the domain's bounding-box diagonal [m]
	std::vector<std::vector<int>> partFaces;  // plane indices, outward normals
};

void addRecord(Setup& setup, const PlaneRecord& record) {
	setup.records.push_back(record);
	setup.planes.push_back(record.plane);
}

// Bounds (a box twice the domain's size), the parts' faces, then the joints' planes.
Setup makePlanes(const std::vector<std::vector<Vector3>>& parts, const std::vector<JointSpec>& joints,
                 std::uint64_t seed) {
	if (parts.empty()) throw InputError("the domain has no part");
	Setup setup;
	std::vector<std::vector<CutPlane>> faces;
	DomainExtent extent;
	for (std::size_t i = 0; i < parts.size(); ++i) {
		faces.push_back(convexFacePlanes(parts[i], "domain part " + std::to_string(i)));
		extent.corners.insert(extent.corners.end(), parts[i].begin(), parts[i].end());
	}
	Vector3 lo = extent.corners.front(), hi = lo;
	for (const Vector3& p : extent.corners) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
	extent.diameter = (hi - lo).norm();
	setup.diameter = extent.diameter;
	const double pad = std::max(1.0, (hi - lo).maxCoeff());
	for (int axis = 0; axis < 3; ++axis)
		for (int side = 0; side < 2; ++side) {
			PlaneRecord record;
			record.plane = CutPlane{Vector3::Unit(axis), side ? hi[axis] + pad : lo[axis] - pad};
			record.number = 2 * axis + side;
			setup.bounds[2 * axis + side] = static_cast<int>(setup.records.size());
			addRecord(setup, record);
		}
	for (std::size_t i = 0; i < faces.size(); ++i) {
		setup.partFaces.emplace_back();
		for (std::size_t f = 0; f < faces[i].size(); ++f) {
			PlaneRecord record;
			record.plane = faces[i][f];
			record.kind = PlaneKind::Domain;
			record.source = static_cast<int>(i);
			record.number = static_cast<int>(f);
			setup.partFaces.back().push_back(static_cast<int>(setup.records.size()));
			addRecord(setup, record);
		}
	}
	int nextFamily = 0;
	std::vector<PlaneRecord> jointPlanes;
	for (std::size_t j = 0; j < joints.size(); ++j)
		appendJointPlanes(joints[j], static_cast<int>(j), extent, seed, jointPlanes, nextFamily);
	if (setup.records.size() + jointPlanes.size() >= (1u << 21))
		throw InputError("the cut has " + std::to_string(setup.records.size() + jointPlanes.size()) +
		                 " planes, more than 2097151");
	for (const PlaneRecord& record : jointPlanes) addRecord(setup, record);
	return setup;
}

std::vector<Cell> makePartCells(const Setup& setup, VertexTable& table) {
	std::vector<Cell> cells;
	for (std::size_t i = 0; i < setup.partFaces.size(); ++i) {
		Cell cell = boxCell(static_cast<int>(i), setup.bounds, table);
		for (int plane : setup.partFaces[i]) {
			std::optional<Cell> clipped = clip(cell, faceRef(plane, false), table);
			if (!clipped) throw InputError("domain part " + std::to_string(i) + " has no volume between its face planes");
			cell = std::move(*clipped);
		}
		cells.push_back(std::move(cell));
	}
	return cells;
}

bool boxesOverlap(const Cell& a, const Cell& b) {
	return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

// Parts that share volume (not just a face) are refused: each part would be cut on its own.
void requireDisjointParts(const std::vector<Cell>& cells, const Setup& setup, VertexTable& table) {
	for (std::size_t i = 0; i < cells.size(); ++i)
		for (std::size_t j = i + 1; j < cells.size(); ++j) {
			if (!boxesOverlap(cells[i], cells[j])) continue;
			std::optional<Cell> common = cells[i];
			for (int plane : setup.partFaces[j]) {
				common = clip(*common, faceRef(plane, false), table);
				if (!common) break;
			}
			if (common)
				throw InputError("domain parts " + std::to_string(i) + " and " + std::to_string(j) +
				                 " overlap: the parts of a domain must meet face to face at most");
		}
}

struct Family {
	std::vector<int> planes;  // ascending offset; one normal when more than one plane
	double persistence = 1;
};

// Joint families in cutting order: fully persistent ones first, then the others, each in list order.
std::vector<Family> jointFamilies(const Setup& setup) {
	std::vector<Family> families;
	int lastFamily = -1;
	for (std::size_t p = 0; p < setup.records.size(); ++p) {
		const PlaneRecord& r = setup.records[p];
		if (r.kind != PlaneKind::JointSet && r.kind != PlaneKind::Joint) continue;
		if (r.family < 0 || r.family != lastFamily) families.push_back(Family{{}, r.persistence});
		families.back().planes.push_back(static_cast<int>(p));
		lastFamily = r.family;
	}
	std::stable_partition(families.begin(), families.end(), [](const Family& f) { return f.persistence >= 1; });
	return families;
}

// The indices into family.planes of the planes that may cross the cell.
std::pair<std::size_t, std::size_t> candidates(const Family& family, const std::vector<double>& offsets,
                                               const Setup& setup, const Cell& cell) {
	if (family.planes.size() == 1 || !cell.bounded) return {0, family.planes.size()};
	const auto range = boxRange(CutPlane{setup.planes[family.planes.front()].normal, 0}, cell.lo, cell.hi);
	return {static_cast<std::size_t>(std::lower_bound(offsets.begin(), offsets.end(), range[0]) - offsets.begin()),
	        static_cast<std::size_t>(std::upper_bound(offsets.begin(), offsets.end(), range[1]) - offsets.begin())};
}

// Cuts every cell by the family's planes in ascending offset: the part below
// a plane is above none of the later ones, so only the part above goes on.
std::vector<Cell> cutFamily(std::vector<Cell> cells, const Family& family, const Setup& setup, VertexTable& table,
                            std::uint64_t seed, CutStatistics& stats) {
	std::vector<double> offsets;
	for (int p : family.planes) offsets.push_back(setup.planes[p].offset);
	std::vector<Cell> out;
	out.reserve(cells.size());
	std::vector<signed char> signs;
	for (Cell& cell : cells) {
		Cell current = std::move(cell);
		const auto [first, last] = candidates(family, offsets, setup, current);
		for (std::size_t i = first; i < last; ++i) {
			const int plane = family.planes[i];
			const auto range = boxRange(setup.planes[plane], current.lo, current.hi);
			if (range[0] >= 0 || range[1] <= 0) continue;
			++stats.classified;
			if (classify(current, plane, table, signs) != 3) continue;
			if (family.persistence < 1 &&
			    keyedUniform(seed, RandomPurpose::Persistence,
			                 {static_cast<std::uint64_t>(plane), cellKey(current)}) >= family.persistence) {
				++stats.skippedCuts;
				continue;
			}
			auto parts = split(current, plane, signs, table);
			out.push_back(std::move(parts.first));
			current = std::move(parts.second);
			++stats.cuts;
		}
		out.push_back(std::move(current));
	}
	return out;
}

// Whether the cell and the region of outward face planes [first, last) share
// volume: the cell clipped by every face plane keeps some (exact).
bool meetsRegion(const Cell& cell, int first, int last, const Setup& setup, VertexTable& table) {
	for (int plane = first; plane < last; ++plane)
		if (boxRange(setup.planes[plane], cell.lo, cell.hi)[0] >= 0) return false;  // wholly outside a face
	std::optional<Cell> common = cell;
	for (int plane = first; plane < last && common; ++plane) common = clip(*common, faceRef(plane, false), table);
	return common.has_value();
}

// The cells outside one excavated region, whose outward face planes are
// records [first, last) (a half-space is a region with one face). A cell
// that shares no volume with the region is kept whole; one that does is cut
// by the region's face planes in turn, each part outside a plane kept, and
// what is left inside all of them removed: the region's planes cut only the
// blocks it reaches.
std::vector<Cell> excavate(std::vector<Cell> cells, int first, int last, const Setup& setup, VertexTable& table) {
	std::vector<Cell> out;
	std::vector<signed char> signs;
	for (Cell& cell : cells) {
		if (!meetsRegion(cell, first, last, setup, table)) {
			out.push_back(std::move(cell));
			continue;
		}
		Cell rest = std::move(cell);
		for (int plane = first; plane < last; ++plane) {
			if (classify(rest, plane, table, signs) != 3) continue;  // wholly inside this face: next face
			auto parts = split(rest, plane, signs, table);
			out.push_back(std::move(parts.second));
			rest = std::move(parts.first);
		}
	}
	return out;
}

std::vector<Cell> excavateAll(std::vector<Cell> cells, const Setup& setup, VertexTable& table) {
	for (std::size_t p = 0; p < setup.records.size();) {
		const PlaneRecord& r = setup.records[p];
		if (r.kind != PlaneKind::Excavation) {
			++p;
			continue;
		}
		std::size_t end = p + 1;
		while (end < setup.records.size() && setup.records[end].kind == PlaneKind::Excavation &&
		       setup.records[end].source == r.source && setup.records[end].region == r.region)
			++end;
		cells = excavate(std::move(cells), static_cast<int>(p), static_cast<int>(end), setup, table);
		p = end;
	}
	return cells;
}

// A CornerSnap over every corner of the cells.
CornerSnap snapCorners(const std::vector<Cell>& cells, double tolerance, VertexTable& table) {
	std::vector<Vector3> points;
	for (const Cell& cell : cells)
		for (int v : cell.vertices) points.push_back(table.point(v));
	return CornerSnap(points, tolerance);
}

}  // namespace

RockMass cutRockMass(const std::vector<std::vector<Vector3>>& parts, const std::vector<JointSpec>& joints,
                     const CutOptions& options) {
	if (!std::isfinite(options.minVolume)) throw InputError("minVolume must be finite");
	RockMass mass;
	auto start = Clock::now();
	const Setup setup = makePlanes(parts, joints, options.seed);
	VertexTable table(setup.planes);
	const std::vector<Cell> partCells = makePartCells(setup, table);
	requireDisjointParts(partCells, setup, table);
	for (const Cell& cell : partCells) mass.domainVolume += cellVolume(cell, table);
	mass.minVolume = options.minVolume >= 0 ? options.minVolume : kDefaultSliverFraction * mass.domainVolume;
	mass.stats.secondsPlanes = secondsSince(start);

	start = Clock::now();
	std::vector<Cell> cells = partCells;
	for (const Family& family : jointFamilies(setup))
		cells = cutFamily(std::move(cells), family, setup, table, options.seed, mass.stats);
	mass.stats.secondsCut = secondsSince(start);

	start = Clock::now();
	cells = excavateAll(std::move(cells), setup, table);
	mass.stats.secondsExcavate = secondsSince(start);

	start = Clock::now();
	const CornerSnap snap = snapCorners(cells, kSnapRelative * setup.diameter, table);
	mass.stats.snappedCorners = snap.moved();
	const auto problemOf = [&](const Cell& cell) {
		return blockProblem(toBlock(cell, table, snap), mass.minVolume, options.checkShapes);
	};
	SliverOutcome slivers = mergeSlivers(std::move(cells), partCells, problemOf, table);
	mass.stats.mergedSlivers = slivers.merged;
	mass.stats.secondsSlivers = secondsSince(start);

	start = Clock::now();
	for (const Cell& cell : slivers.kept) mass.blocks.push_back(toBlock(cell, table, snap));
	for (const auto& [cell, reason] : slivers.reported) {
		mass.slivers.push_back(toBlock(cell, table, snap));
		mass.slivers.back().problem = reason;
	}
	mass.planes = setup.records;
	mass.stats.planes = static_cast<int>(setup.records.size());
	mass.stats.vertices = static_cast<long>(table.size());
	mass.stats.predicates = table.counters();
	mass.stats.secondsOutput = secondsSince(start);
	return mass;
}

}  // namespace dda::rockmass
