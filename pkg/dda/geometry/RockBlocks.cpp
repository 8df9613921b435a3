// Cut cells as blocks: snapping, faces, volume, the ddaBlock check (RockBlocks.hpp).
#include "RockBlocks.hpp"

#include "dda/core/Errors.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>

namespace dda::rockmass {
namespace {

// buildConvexPolyhedron's coincidence tolerance (ConvexPolyhedron.cpp,
// kCoincidenceRelativeTolerance): corners closer than this fraction of the
// block's bounding-box diagonal are refused as one point.
constexpr double kCoincidenceRelative = 1e-12;
// The cheap test's margin over buildConvexPolyhedron's tolerances.
constexpr double kQuickMargin = 10;

std::string number(double x) {
	char buffer[64];
	const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
	return std::string(buffer, result.ptr);
}

std::uint64_t bitsOf(double x) {
	x += 0.0;  // -0 -> +0
	std::uint64_t bits;
	std::memcpy(&bits, &x, sizeof bits);
	return bits;
}

bool lexLess(const Vector3& a, const Vector3& b) {
	return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

int findRoot(std::vector<int>& parent, int i) {
	while (parent[i] != i) i = parent[i] = parent[parent[i]];
	return i;
}

// Pairs of points closer than `tolerance`, found through a grid of that cell size.
std::vector<std::pair<int, int>> closePairs(const std::vector<Vector3>& points, double tolerance) {
	struct CellHash {
		std::size_t operator()(const std::array<long long, 3>& c) const {
			std::uint64_t h = 0x9e3779b97f4a7c15ULL;
			for (long long v : c) h = (h ^ static_cast<std::uint64_t>(v)) * 0x100000001b3ULL;
			return static_cast<std::size_t>(h ^ (h >> 29));
		}
	};
	std::unordered_map<std::array<long long, 3>, std::vector<int>, CellHash> grid;
	const auto cellOf = [tolerance](const Vector3& p) {
		std::array<long long, 3> c;
		for (int k = 0; k < 3; ++k)
			c[k] = static_cast<long long>(std::clamp(std::floor(p[k] / tolerance), -4e18, 4e18));  // far: one cell
		return c;
	};
	for (int i = 0; i < static_cast<int>(points.size()); ++i) grid[cellOf(points[i])].push_back(i);
	std::vector<std::pair<int, int>> pairs;
	for (int i = 0; i < static_cast<int>(points.size()); ++i) {
		const auto c = cellOf(points[i]);
		for (long long dx = -1; dx <= 1; ++dx)
			for (long long dy = -1; dy <= 1; ++dy)
				for (long long dz = -1; dz <= 1; ++dz) {
					const auto found = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
					if (found == grid.end()) continue;
					for (int j : found->second)
						if (j > i && (points[i] - points[j]).norm() < tolerance) pairs.emplace_back(i, j);
				}
	}
	return pairs;
}

double boundingDiagonal(const std::vector<Vector3>& points) {
	Vector3 lo = points.front(), hi = lo;
	for (const Vector3& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
	return (hi - lo).norm();
}

// True when the corners pass well clear of buildConvexPolyhedron's tolerances.
bool clearlyAccepted(const RockBlock& block) {
	const std::vector<Vector3>& p = block.corners;
	if (p.size() < 4 || block.faces.size() < 4) return false;
	const double size = boundingDiagonal(p);
	for (std::size_t i = 0; i < p.size(); ++i)
		for (std::size_t j = i + 1; j < p.size(); ++j)
			if (!((p[i] - p[j]).norm() > kQuickMargin * kCoincidenceRelative * size)) return false;
	std::vector<char> onFace(p.size());
	for (const std::vector<int>& face : block.faces) {
		Vector3 normal;
		try {
			normal = faceNormal(p, face);
		} catch (const InputError&) {
			return false;
		}
		Vector3 centre = Vector3::Zero();
		for (int v : face) centre += p[v];
		centre /= static_cast<double>(face.size());
		std::fill(onFace.begin(), onFace.end(), 0);
		for (int v : face) onFace[v] = 1;
		for (std::size_t v = 0; v < p.size(); ++v)
			if (!onFace[v] && !(std::abs(normal.dot(p[v] - centre)) > kQuickMargin * kCoplanarRelativeTolerance * size))
				return false;
	}
	return true;
}

}  // namespace

std::size_t CornerSnap::Bits::operator()(const Vector3& p) const {
	std::uint64_t h = 0x9e3779b97f4a7c15ULL;
	for (int k = 0; k < 3; ++k) h = (h ^ bitsOf(p[k])) * 0x100000001b3ULL;
	return static_cast<std::size_t>(h ^ (h >> 29));
}

CornerSnap::CornerSnap(const std::vector<Vector3>& input, double tolerance) {
	if (input.empty() || !(tolerance > 0)) return;
	std::vector<Vector3> points = input;
	std::sort(points.begin(), points.end(), lexLess);
	points.erase(std::unique(points.begin(), points.end()), points.end());
	std::vector<int> parent(points.size());
	std::iota(parent.begin(), parent.end(), 0);
	for (const auto& [i, j] : closePairs(points, tolerance)) {
		const int a = findRoot(parent, i), b = findRoot(parent, j);
		parent[std::max(a, b)] = std::min(a, b);  // points are sorted: the root is the smallest
	}
	for (std::size_t i = 0; i < points.size(); ++i) {
		const int root = findRoot(parent, static_cast<int>(i));
		if (root != static_cast<int>(i)) moved_.emplace(points[i], points[root]);
	}
}

const Vector3& CornerSnap::operator()(const Vector3& p) const {
	const auto found = moved_.find(p);
	return found == moved_.end() ? p : found->second;
}

RockBlock toBlock(const Cell& cell, VertexTable& table, const CornerSnap& snap) {
	RockBlock block;
	block.part = cell.part;
	std::vector<int> index(cell.vertices.size());
	for (std::size_t v = 0; v < cell.vertices.size(); ++v) {
		const Vector3& p = snap(table.point(cell.vertices[v]));
		const auto found = std::find(block.corners.begin(), block.corners.end(), p);
		index[v] = static_cast<int>(found - block.corners.begin());
		if (found == block.corners.end()) {
			block.corners.push_back(p);
			block.cornerPlanes.push_back(table.triple(cell.vertices[v]));
		}
	}
	for (int f = 0; f < cell.faceCount(); ++f) {
		std::vector<int> face;
		for (int i = cell.faceStart[f]; i < cell.faceStart[f + 1]; ++i) {
			const int c = index[cell.corners[i]];
			if (face.empty() || face.back() != c) face.push_back(c);
		}
		while (face.size() > 1 && face.front() == face.back()) face.pop_back();
		if (face.size() < 3) continue;
		block.faces.push_back(std::move(face));
		block.facePlanes.push_back(refPlane(cell.faceRefs[f]));
	}
	const Vector3& origin = block.corners.front();
	double six = 0;
	for (const std::vector<int>& face : block.faces)
		for (std::size_t i = 1; i + 1 < face.size(); ++i)
			six += (block.corners[face[0]] - origin).dot((block.corners[face[i]] - origin).cross(block.corners[face[i + 1]] - origin));
	block.volume = six / 6;
	return block;
}

std::string blockProblem(const RockBlock& block, double minVolume, bool checkShapes) {
	if (block.volume < minVolume)
		return "its volume " + number(block.volume) + " m^3 is below minVolume " + number(minVolume) + " m^3";
	if (!checkShapes || clearlyAccepted(block)) return "";
	try {
		buildConvexPolyhedron(block.corners);
	} catch (const InputError& e) {
		return std::string("ddaBlock would refuse its corners: ") + e.what();
	}
	return "";
}

}  // namespace dda::rockmass
