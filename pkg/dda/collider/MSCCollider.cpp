#include "MSCCollider.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

// Why the linked sub-units hold every feature of a pair's contacts. A
// vertex-face contact P -> F has P within reach = d0 + lengthTolerance of F's
// plane (or penetrating by at most delta, the pair's depth) and P's projection
// within reach of F (a distance to the polygon, also near its acute corners),
// so P is within sqrt(2) max(reach, delta) of a point q of F.
// P lies in a slice of its block, q in a slice of the other; those slices'
// shells link P and F (a feature is linked to every slab it touches), and
// their boxes, widened by d0 + w each, overlap whenever every coordinate of
// P - q is at most 2 d0 + wA + wB: true for delta <= d0 / 2 (w covers the
// length tolerance). An edge-edge contact's closest points are |gap| apart,
// gap in [min(separation, 0) - reach, reach]: the same bound. (The corner
// contacts an edge entrance adds when its edges do not cross strictly inside
// are vertex-face contacts as above.) So the union
// over the overlapping shells links them. Deeper overlaps are not covered by
// this argument (a corner far inside may pick a face beyond its shells).
// The frame test uses nothing else: for any unit direction u, |(P - q) . u| <=
// |P - q| <= 2 d0 + wA + wB, so two slices apart by more than that along u
// hold no such P and q. A slice lies in its extent (the parallelepiped of its
// ranges along the frame's axes), so a shell is projected on the other
// frame's axes through that parallelepiped, and the test adds its own
// round-off (kFrameRoundoffRelative x the lengths involved, far below w).

namespace dda {

namespace {

// Blocks ahead whose corners are prefetched while boxes are updated, grid
// entries ahead whose shell's box is prefetched while cells are scanned, and
// shell pairs ahead whose second block's frame is prefetched in the frame test.
constexpr int kPrefetchBlocks = 4;
constexpr std::size_t kPrefetchHits = 16;
constexpr std::size_t kPrefetchEntries = 24;

void checkCover(double criticalLength, int segments, const std::string& what) {
	if (!(criticalLength > 0) || !std::isfinite(criticalLength))
		throw InputError(what + ": critical length must be positive and finite, got " + std::to_string(criticalLength));
	if (segments < 1 || segments > MSCCollider::kMaxSegments)
		throw InputError(what + ": segments must be in [1, " + std::to_string(MSCCollider::kMaxSegments) + "], got " +
		                 std::to_string(segments));
}

// The block's size [m]: its creation size, else the cube root of its volume.
double blockSize(const Block& block) { return block.size > 0 ? block.size : std::cbrt(block.volume); }

// A face's unit normal from its vector area (zero for a degenerate face):
// the face's corners are face[0, n).
template <class Index>
Vector3 faceNormal(const Index* face, std::size_t n, const std::vector<Vector3>& x) {
	Vector3 area = Vector3::Zero();
	for (std::size_t k = 1; k + 1 < n; ++k) area += (x[face[k]] - x[face[0]]).cross(x[face[k + 1]] - x[face[0]]);
	return area.normalized();
}
Vector3 faceNormal(const std::vector<int>& face, const std::vector<Vector3>& x) {
	return faceNormal(face.data(), face.size(), x);
}

// A shell's box (min, max) and extent in its block's frame (low, high) as
// its points p (c: p in the frame) are added.
struct ShellBounds {
	Vector3 min, max, low, high;
	void reset() {
		min = low = Vector3::Constant(std::numeric_limits<double>::infinity());
		max = high = -min;
	}
	[[gnu::always_inline]] void add(const Vector3& p, const Vector3& c) {
		min = min.cwiseMin(p);
		max = max.cwiseMax(p);
		low = low.cwiseMin(c);
		high = high.cwiseMax(c);
	}
};

// Resizes v to n elements: exactly the first time, with 1/8 spare capacity
// when it must grow again (counts creep up from call to call; resize would
// double the capacity).
template <class T>
void resizeWithHeadroom(std::vector<T>& v, std::size_t n) {
	if (n > v.capacity()) v.reserve(v.capacity() == 0 ? n : n + n / 8);
	v.resize(n);
}

// Appends x, the capacity growing by 1/8 when full (not doubling: the arrays
// so filled are kept from call to call at their largest size).
template <class T>
[[gnu::always_inline]] inline void pushWithHeadroom(std::vector<T>& v, const T& x) {
	if (v.size() == v.capacity()) v.reserve(v.size() + v.size() / 8 + 64);
	v.push_back(x);
}

std::uint64_t hashList(const std::vector<int>& list) {
	std::uint64_t h = list.size();
	for (int i : list) {
		h = (h ^ static_cast<std::uint32_t>(i)) * 0x9E3779B97F4A7C15ULL;
		h ^= h >> 29;
	}
	return h;
}

}  // namespace

MSCCollider::MSCCollider(double criticalLengthFactor, int segments)
    : criticalLengthFactor_(criticalLengthFactor), segments_(segments) {
	checkCover(criticalLengthFactor, segments, "MSCCollider");
}

void MSCCollider::setCover(double criticalLength, int segments) {
	if (!(criticalLength >= 0) || !std::isfinite(criticalLength))
		throw InputError("MSCCollider: critical length must be >= 0 (0: by block size) and finite, got " +
		                 std::to_string(criticalLength));
	checkCover(criticalLength == 0 ? 1.0 : criticalLength, segments, "MSCCollider");
	criticalLength_ = criticalLength;
	segments_ = segments;
	coverChanged_ = true;
}

void MSCCollider::setBlockCover(int block, double criticalLength, int segments) {
	if (block < 0) throw InputError("MSCCollider: block index must be >= 0, got " + std::to_string(block));
	checkCover(criticalLength, segments, "MSCCollider block " + std::to_string(block));
	overrides_[block] = Override{criticalLength, segments};
	coverChanged_ = true;
}

void MSCCollider::setPairReuse(bool reuse) {
	reuse_ = reuse;
	if (!reuse) cacheValid_ = false;
}

const LinkedSubUnits* MSCCollider::linked(int pairIndex) const {
	return pairIndex >= 0 && pairIndex < linkedCount_ ? &linked_[pairIndex] : nullptr;
}

const Eigen::AlignedBox3d& MSCCollider::shellBox(int block, int shell) const {
	const BlockCover& cover = covers_.at(block);
	if (shell < 0 || shell >= cover.shellCount)
		throw InputError("MSCCollider: block " + std::to_string(block) + " has " + std::to_string(cover.shellCount) +
		                 " shells, asked for shell " + std::to_string(shell));
	return boxes_[cover.firstShell + shell];
}

void MSCCollider::buildCover(const Block& block, double criticalLength, int segments, BlockCover& cover,
                             std::vector<ShellRange>& shellRanges, std::vector<DivisionPoint>& divisions,
                             std::vector<int>& divisionStart) const {
	const PolyhedronTopology& shape = *block.shape;
	const std::vector<Vector3>& x = block.vertices;
	const int nv = static_cast<int>(x.size());
	const int ne = static_cast<int>(shape.edges.size());
	const int nf = static_cast<int>(shape.faces.size());
	cover.shape = block.shape;
	cover.criticalLength = criticalLength;
	cover.segments = segments;
	cover.boxesBuilt = false;
	cover.firstSubUnit = static_cast<int>(shellRanges.size());
	cover.vertexCount = nv;
	cover.edgeCount = ne;
	cover.faceCount = nf;
	Eigen::AlignedBox3d box;
	for (const Vector3& p : x) box.extend(p);
	cover.widening = kShellWideningRelative * box.diagonal().norm();
	double longest = 0;
	for (const auto& e : shape.edges) longest = std::max(longest, (x[e[1]] - x[e[0]]).norm());
	const int k = longest > criticalLength ? segments : 1;
	cover.shellCount = k;
	// Main axis: the principal direction of largest spread of the corners.
	Vector3 mean = Vector3::Zero();
	for (const Vector3& p : x) mean += p;
	mean /= nv;
	Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
	for (const Vector3& p : x) spread += (p - mean) * (p - mean).transpose();
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(spread);
	const Vector3 axis = eigen.eigenvectors().col(2);  // eigenvalues ascending
	// The frame: the face most across the main axis, the face most across
	// that one, and the face that spans most volume with both.
	cover.frameFaces = {-1, -1, -1};
	std::vector<Vector3> normals(nf);
	for (int f = 0; f < nf; ++f) normals[f] = faceNormal(shape.faces[f], x);
	const auto best = [&](const auto& score, int skip) {
		int chosen = -1;
		double top = -1;
		for (int f = 0; f < nf; ++f)
			if (f != skip && score(normals[f]) > top) {
				top = score(normals[f]);
				chosen = f;
			}
		return chosen;
	};
	const int f1 = best([&](const Vector3& n) { return std::abs(n.dot(axis)); }, -1);
	const int f2 = best([&](const Vector3& n) { return 1 - std::abs(n.dot(normals[f1])); }, f1);
	if (f2 >= 0) {
		const Vector3 across = normals[f1].cross(normals[f2]);
		const int f3 = best([&](const Vector3& n) { return std::abs(n.dot(across)); }, f1);
		if (f3 >= 0 && std::abs(normals[f3].dot(across)) >= kMinFrameDeterminant) cover.frameFaces = {f1, f2, f3};
	}
	copyFrameCorners(shape, cover);
	if (k == 1) {
		shellRanges.insert(shellRanges.end(), nv + ne + nf, ShellRange::of(1));
		divisionStart.push_back(static_cast<int>(divisions.size()));
		return;
	}
	std::vector<double> s(nv);
	for (int v = 0; v < nv; ++v) s[v] = axis.dot(x[v] - mean);
	const double low = *std::min_element(s.begin(), s.end()), high = *std::max_element(s.begin(), s.end());
	// Slab j is [bound[j], bound[j + 1]], closed: a sub-unit on a plane is in both.
	std::vector<double> bound(k + 1);
	for (int j = 0; j <= k; ++j) bound[j] = low + (high - low) * j / k;
	bound[k] = high;
	// The slabs an interval [lo, hi] touches: consecutive ones (the bounds
	// ascend, except that bound[k - 1] may pass bound[k] by round-off, which
	// only drops slab k - 1), so a range.
	const auto shellsOf = [&](double lo, double hi) {
		std::uint64_t mask = 0;
		for (int j = 0; j < k; ++j)
			if (lo <= bound[j + 1] && hi >= bound[j]) mask |= std::uint64_t{1} << j;
		return ShellRange::of(mask);
	};
	for (int v = 0; v < nv; ++v) shellRanges.push_back(shellsOf(s[v], s[v]));
	for (int e = 0; e < ne; ++e) {
		const double s0 = s[shape.edges[e][0]], s1 = s[shape.edges[e][1]];
		shellRanges.push_back(shellsOf(std::min(s0, s1), std::max(s0, s1)));
	}
	for (int f = 0; f < nf; ++f) {
		double lo = s[shape.faces[f][0]], hi = lo;
		for (int v : shape.faces[f]) {
			lo = std::min(lo, s[v]);
			hi = std::max(hi, s[v]);
		}
		shellRanges.push_back(shellsOf(lo, hi));
	}
	// Division points on the slabs' inner planes (the outer ends hold
	// corners), each plane's listed with the slab above it.
	for (int j = 0; j < k; ++j) {
		divisionStart.push_back(static_cast<int>(divisions.size()));
		if (j == 0) continue;
		const double plane = bound[j];
		for (int e = 0; e < ne; ++e) {
			const double s0 = s[shape.edges[e][0]], s1 = s[shape.edges[e][1]];
			if (std::min(s0, s1) < plane && plane < std::max(s0, s1))
				divisions.push_back({shape.edges[e][0], shape.edges[e][1], std::clamp((plane - s0) / (s1 - s0), 0.0, 1.0)});
		}
	}
}

void MSCCollider::copyFrameCorners(const PolyhedronTopology& shape, BlockCover& cover) {
	cover.frameCorners.fill(0);
	if (cover.frameFaces[0] < 0 || shape.vertexCount() > 256) return;
	std::size_t used = 0;
	for (const int f : cover.frameFaces) used += 1 + shape.faces[f].size();
	if (used > cover.frameCorners.size()) return;
	std::uint8_t* out = cover.frameCorners.data();
	for (const int f : cover.frameFaces) {
		*out++ = static_cast<std::uint8_t>(shape.faces[f].size());
		for (const int v : shape.faces[f]) *out++ = static_cast<std::uint8_t>(v);
	}
}

void MSCCollider::updateBoxes(const Block& block, BlockCover& cover, Frame& frame) {
	const PolyhedronTopology& shape = *block.shape;
	const std::vector<Vector3>& x = block.vertices;
	// The frame.
	frame.axes.setIdentity();
	if (cover.frameFaces[0] >= 0) {
		Eigen::Matrix3d axes;
		if (cover.frameCorners[0] > 0) {
			const std::uint8_t* corners = cover.frameCorners.data();
			for (int j = 0; j < 3; corners += 1 + corners[0], ++j)
				axes.row(j) = faceNormal(corners + 1, corners[0], x).transpose();
		} else {
			for (int j = 0; j < 3; ++j) axes.row(j) = faceNormal(shape.faces[cover.frameFaces[j]], x).transpose();
		}
		if (std::abs(axes.determinant()) >= 0.5 * kMinFrameDeterminant) frame.axes = axes;
	}
	frame.dual = frame.axes.inverse();
	frame.origin = x.front();
	frame.reach = 0;
	frame.widening = cover.widening;
	frame.firstShell = cover.firstShell;
	// Each point is computed once and added to the shells it lies in: a
	// vertex to its linked shells, a division point to the two slabs of its
	// plane. A shell gets its corners, then the points on its lower plane,
	// then those on its upper one (the order of the saved per-shell lists).
	std::array<ShellBounds, kMaxSegments> bounds;
	const int k = cover.shellCount;
	for (int j = 0; j < k; ++j) bounds[j].reset();
	const ShellRange* vertexShells = shellRanges_.data() + cover.firstSubUnit;
	for (int v = 0; v < cover.vertexCount; ++v) {
		const Vector3 c = frame.axes * (x[v] - frame.origin);
		for (int j = vertexShells[v].first; j <= vertexShells[v].last; ++j) bounds[j].add(x[v], c);
	}
	for (int j = 1; j < k; ++j) {
		const int s = cover.firstShell + j;
		for (int d = divisionStart_[s]; d < divisionStart_[s + 1]; ++d) {
			const Vector3& from = x[divisions_[d].from];
			const Vector3 p = from + divisions_[d].fraction * (x[divisions_[d].to] - from);
			const Vector3 c = frame.axes * (p - frame.origin);
			bounds[j - 1].add(p, c);
			bounds[j].add(p, c);
		}
	}
	for (int j = 0; j < k; ++j) {
		const int s = cover.firstShell + j;
		boxes_[s] = Eigen::AlignedBox3d(bounds[j].min, bounds[j].max);
		extentLow_[s] = bounds[j].low;
		extentHigh_[s] = bounds[j].high;
		frame.reach = std::max({frame.reach, bounds[j].low.cwiseAbs().maxCoeff(), bounds[j].high.cwiseAbs().maxCoeff()});
	}
	cover.boxesBuilt = block.fixed;
	totalShellUpdates_ += cover.shellCount;
}

void MSCCollider::layoutShells() {
	int total = 0;
	for (BlockCover& cover : covers_) {
		cover.firstShell = total;
		cover.boxesBuilt = false;
		total += cover.shellCount;
	}
	// A grid entry keeps a shell index in 29 bits (gridSearch).
	if (total >= 1 << 29) throw InputError("MSCCollider: more than 2^29 shells (" + std::to_string(total) + ")");
	resizeWithHeadroom(boxes_, total);
	resizeWithHeadroom(extentLow_, total);
	resizeWithHeadroom(extentHigh_, total);
	resizeWithHeadroom(shellBlock_, total);
	resizeWithHeadroom(frames_, covers_.size());
	for (int b = 0; b < static_cast<int>(covers_.size()); ++b)
		std::fill_n(shellBlock_.begin() + covers_[b].firstShell, covers_[b].shellCount, b);
	clearLinkedSets();
	cacheValid_ = false;
}

int MSCCollider::linkedSet(int block, std::uint64_t shells) {
	// The chain is searched from the set used last (a block's pairs often
	// link the same shells), which is moved to its front when found.
	int& head = frames_[block].linkedSets;
	for (int k = head, previous = -1; k >= 0; previous = k, k = linkedSets_[k].next)
		if (linkedSets_[k].shells == shells) {
			if (previous >= 0) {
				linkedSets_[previous].next = linkedSets_[k].next;
				linkedSets_[k].next = head;
				head = k;
			}
			return k;
		}
	BlockCover& cover = covers_[block];
	LinkedSet set{shells, head, {}};
	const ShellRange* linkedShells = shellRanges_.data() + cover.firstSubUnit;
	const int counts[3] = {cover.vertexCount, cover.edgeCount, cover.faceCount};
	for (int kind = 0; kind < 3; ++kind) {
		listScratch_.clear();
		for (int i = 0; i < counts[kind]; ++i)
			if (linkedShells[i].mask() & shells) listScratch_.push_back(i);
		linkedShells += counts[kind];
		set.lists[kind] = internList(listScratch_);
	}
	head = static_cast<int>(linkedSets_.size());
	pushWithHeadroom(linkedSets_, set);
	if (static_cast<std::size_t>(++cover.linkedSetCount) > kMaxLinkedSetsPerBlock) linkedSetsOverflow_ = true;
	return head;
}

int MSCCollider::internList(const std::vector<int>& list) {
	const auto place = [this](int k) {
		const std::size_t mask = listTable_.size() - 1;
		std::size_t slot = hashList(lists_[k]) & mask;
		while (listTable_[slot] >= 0) slot = (slot + 1) & mask;
		listTable_[slot] = k;
	};
	// The table is kept at most half full (a power of two).
	if (2 * (lists_.size() + 1) > listTable_.size()) {
		listTable_.assign(std::max<std::size_t>(64, 2 * listTable_.size()), -1);
		for (int k = 0; k < static_cast<int>(lists_.size()); ++k) place(k);
	}
	const std::size_t mask = listTable_.size() - 1;
	std::size_t slot = hashList(list) & mask;
	for (; listTable_[slot] >= 0; slot = (slot + 1) & mask)
		if (lists_[listTable_[slot]] == list) return listTable_[slot];
	listTable_[slot] = static_cast<int>(lists_.size());
	lists_.push_back(list);
	return listTable_[slot];
}

void MSCCollider::clearLinkedSets() {
	linkedSets_.clear();
	lists_.clear();
	std::fill(listTable_.begin(), listTable_.end(), -1);
	for (BlockCover& cover : covers_) cover.linkedSetCount = 0;
	for (Frame& frame : frames_) frame.linkedSets = -1;
	linkedSetsOverflow_ = false;
}

long MSCCollider::gridSearch(const std::vector<Eigen::AlignedBox3d>& boxes, std::vector<ShellPair>& out) {
	out.clear();
	const int shellTotal = static_cast<int>(boxes.size());
	Eigen::AlignedBox3d domain;
	double sideSum = 0;
	for (const Eigen::AlignedBox3d& box : boxes) {
		domain.extend(box);
		sideSum += box.sizes().maxCoeff();
	}
	// Subspaces: cubic cells as wide as the mean shell's largest side (at
	// least 1/kMaxCellsPerAxis of the domain). A shell enters every cell it
	// overlaps; one spanning more than kMaxCellsPerShell cells (a floor, a
	// block much larger than the rest) is compared with every shell instead.
	// Two shells are compared in one cell only: the cell of the lower corner
	// of their boxes' intersection. cellOf is monotone in each coordinate, so
	// that cell is the componentwise max of the two shells' lowest cells, and
	// lies in both shells' ranges when the boxes meet (the test is on the
	// integer ranges computed once per shell).
	const Vector3 origin = domain.min();
	const double cell = std::max(sideSum / shellTotal, domain.sizes().maxCoeff() / kMaxCellsPerAxis);
	// x >= origin (the domain holds every box), so truncation is the floor.
	const auto cellOf = [&](const Vector3& x) {
		return ((x - origin) / cell).array().cast<long>().min(kMaxCellsPerAxis - 1).max(0).cast<int>().eval();
	};
	const Eigen::Array<long, 3, 1> dims = cellOf(domain.max()).cast<long>() + 1;
	resizeWithHeadroom(cellLow_, shellTotal);
	resizeWithHeadroom(cellSpan_, shellTotal);
	oversize_.clear();
	std::size_t entries = 0;
	for (int s = 0; s < shellTotal; ++s) {
		cellLow_[s] = cellOf(boxes[s].min());
		const Cell extra = cellOf(boxes[s].max()) - cellLow_[s];
		const long span = (extra + 1).cast<long>().prod();
		if (span > kMaxCellsPerShell) {
			oversize_.push_back(s);
			cellSpan_[s] = CellSpan{0, 0, 0, true};
		} else {
			cellSpan_[s] = CellSpan{static_cast<std::uint8_t>(extra.x()), static_cast<std::uint8_t>(extra.y()),
			                        static_cast<std::uint8_t>(extra.z()), false};
			entries += static_cast<std::size_t>(span);
		}
	}
	// Cell keys: the cell's index in the domain's grid when the grid has at
	// most kDenseCellsPerEntry x the entries (then sorted by counting), else
	// the three coordinates packed in 21 bits each (sorted by comparison).
	const double denseCells = static_cast<double>(dims.x()) * static_cast<double>(dims.y()) * static_cast<double>(dims.z());
	const bool dense = denseCells <= kDenseCellsPerEntry * static_cast<double>(entries) + kDenseCellsFloor &&
	                   entries < std::numeric_limits<std::uint32_t>::max();
	denseGrid_ = dense;
	// A cell's key is linear in its coordinates: stride x coordinate, summed.
	const std::array<std::uint64_t, 3> stride =
	    dense ? std::array<std::uint64_t, 3>{static_cast<std::uint64_t>(dims.y() * dims.z()), static_cast<std::uint64_t>(dims.z()), 1}
	          : std::array<std::uint64_t, 3>{std::uint64_t{1} << 42, std::uint64_t{1} << 21, 1};
	// Per shell its block's fixed flag is read from shellFixed_ (filled as
	// boxes are updated: the blocks themselves are large and far apart).
	// An oversize shell is compared with every shell: a test when their
	// blocks differ and are not both fixed, a shell pair when their boxes
	// meet too. The conditions are evaluated together, without a branch each
	// (they are unpredictable and the tests cheap); so they are in cells.
	long tests = 0;
	const auto compareShells = [&](int s, int t) {
		const int a = shellBlock_[s], b = shellBlock_[t];
		const bool pair = (a != b) & !(static_cast<bool>(shellFixed_[s]) & static_cast<bool>(shellFixed_[t]));
		const Vector3 &lowS = boxes[s].min(), &highS = boxes[s].max();
		const Vector3 &lowT = boxes[t].min(), &highT = boxes[t].max();
		const bool meet = (lowS.x() <= highT.x()) & (lowT.x() <= highS.x()) & (lowS.y() <= highT.y()) &
		                  (lowT.y() <= highS.y()) & (lowS.z() <= highT.z()) & (lowT.z() <= highS.z());
		tests += pair;
		if (pair & meet) pushWithHeadroom(out, a < b ? ShellPair{s, t} : ShellPair{t, s});
	};
	// Each entry is a shell (entry >> 3) and, in bits 0-2, the axes along
	// which the cell is the shell's lowest. A pair is compared in the cell of
	// the max of its lowest cells, which is the cell where, along every axis,
	// one of the two begins: (bits of s | bits of t) == 7. About half of the
	// pairs of a cell are not its own; in a cell of at most 64 entries each
	// entry is compared only with the later ones whose bits complete its own,
	// found as a bit mask. The entries are first copied with their boxes,
	// blocks and fixed flags into cellScratch_, each box read once per cell
	// rather than once per pair. Cells are scanned in the order of their
	// entries, whose shells lie anywhere in the flat arrays: the boxes, blocks
	// and fixed flags of the next kPrefetchEntries entries are fetched ahead
	// (`prefetched`: the entries done).
	std::size_t prefetched = 0;
	const auto scanCell = [&](std::size_t first, std::size_t last) {
		for (const std::size_t ahead = std::min(entries, last + kPrefetchEntries); prefetched < ahead; ++prefetched) {
			const std::uint32_t s = cellShells_[prefetched] >> 3;
			__builtin_prefetch(&boxes[s]);
			__builtin_prefetch(reinterpret_cast<const char*>(&boxes[s] + 1) - 1);
			__builtin_prefetch(&shellBlock_[s]);
			__builtin_prefetch(&shellFixed_[s]);
		}
		const std::size_t count = last - first;
		if (count > cellScratch_.size()) resizeWithHeadroom(cellScratch_, count);
		CellEntry* entry = cellScratch_.data();
		for (std::size_t p = 0; p < count; ++p) {
			const std::uint32_t packed = cellShells_[first + p];
			const int s = static_cast<int>(packed >> 3);
			CellEntry& e = entry[p];
			e.low = boxes[s].min();
			e.high = boxes[s].max();
			e.shell = s;
			e.block = shellBlock_[s];
			e.fixed = shellFixed_[s] != 0;
			e.bits = static_cast<std::uint8_t>(packed & 7);
		}
		// As compareShells, on the copies.
		long cellTests = 0;
		const auto compare = [&](const CellEntry& e, const CellEntry& f) __attribute__((always_inline)) {
			const bool test = (e.block != f.block) & !(e.fixed & f.fixed);
			const bool meet = (e.low.x() <= f.high.x()) & (f.low.x() <= e.high.x()) & (e.low.y() <= f.high.y()) &
			                  (f.low.y() <= e.high.y()) & (e.low.z() <= f.high.z()) & (f.low.z() <= e.high.z());
			cellTests += test;
			if (test & meet)
				pushWithHeadroom(out, e.block < f.block ? ShellPair{e.shell, f.shell} : ShellPair{f.shell, e.shell});
		};
		if (count <= 64) {
			// with[m]: the entries whose bits contain m (entries with bits m,
			// then summed over supersets, one axis at a time).
			std::uint64_t with[8] = {};
			for (std::size_t p = 0; p < count; ++p) with[entry[p].bits] |= std::uint64_t{1} << p;
			for (int m = 0; m < 8; m += 2) with[m] |= with[m + 1];
			for (int m : {0, 1, 4, 5}) with[m] |= with[m + 2];
			for (int m = 0; m < 4; ++m) with[m] |= with[m + 4];
			for (std::size_t p = 0; p + 1 < count; ++p) {
				const CellEntry e = entry[p];
				for (std::uint64_t later = with[~e.bits & 7] & ~std::uint64_t{0} << (p + 1); later; later &= later - 1)
					compare(e, entry[__builtin_ctzll(later)]);
			}
		} else {
			for (std::size_t p = 0; p < count; ++p)
				for (std::size_t q = p + 1; q < count; ++q)
					if ((entry[p].bits | entry[q].bits) == 7) compare(entry[p], entry[q]);
		}
		tests += cellTests;
	};
	// Visits the cells of shell s with its entry there.
	const auto forEachCellOf = [&](int s, const auto& visit) {
		const Cell& lo = cellLow_[s];
		const int spanX = cellSpan_[s].x, spanY = cellSpan_[s].y, spanZ = cellSpan_[s].z;
		const std::uint64_t base = lo.x() * stride[0] + lo.y() * stride[1] + lo.z();
		const std::uint32_t shell = static_cast<std::uint32_t>(s) << 3;
		for (int i = 0; i <= spanX; ++i)
			for (int j = 0; j <= spanY; ++j) {
				const std::uint64_t row = base + i * stride[0] + j * stride[1];
				const std::uint32_t bits = shell | (i == 0) | (j == 0) << 1;
				for (int k = 0; k <= spanZ; ++k) visit(row + k, bits | (k == 0) << 2);
			}
	};
	resizeWithHeadroom(cellShells_, entries);
	if (dense) {
		// Counting sort: count per cell, prefix sums (cellStart_[c + 1] = end
		// of cell c), then shells placed from the last down, so each cell's
		// shells ascend and cellStart_[c + 1] ends at the cell's first entry.
		const std::size_t cells = static_cast<std::size_t>(denseCells);
		resizeWithHeadroom(cellStart_, cells + 2);
		std::fill(cellStart_.begin(), cellStart_.end(), 0);
		for (int s = 0; s < shellTotal; ++s)
			if (!cellSpan_[s].oversize) forEachCellOf(s, [&](std::uint64_t c, std::uint32_t) { ++cellStart_[c + 1]; });
		for (std::size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
		for (int s = shellTotal - 1; s >= 0; --s)
			if (!cellSpan_[s].oversize)
				forEachCellOf(s, [&](std::uint64_t c, std::uint32_t e) { cellShells_[--cellStart_[c + 1]] = e; });
		// Now cellStart_[c + 1] is the start of cell c; cell c is [cellStart_[c + 1], cellStart_[c + 2]).
		cellStart_[cells + 1] = static_cast<std::uint32_t>(entries);
		for (std::size_t c = 0; c < cells; ++c)
			if (cellStart_[c + 2] - cellStart_[c + 1] > 1) scanCell(cellStart_[c + 1], cellStart_[c + 2]);
	} else {
		// By comparison on (cell key, entry): the entries of a cell ascend by shell.
		cellEntries_.clear();
		cellEntries_.reserve(entries);
		for (int s = 0; s < shellTotal; ++s)
			if (!cellSpan_[s].oversize)
				forEachCellOf(s, [&](std::uint64_t c, std::uint32_t e) { cellEntries_.emplace_back(c, e); });
		std::sort(cellEntries_.begin(), cellEntries_.end());
		for (std::size_t p = 0; p < entries; ++p) cellShells_[p] = cellEntries_[p].second;
		for (std::size_t first = 0; first < entries;) {
			std::size_t last = first + 1;
			while (last < entries && cellEntries_[last].first == cellEntries_[first].first) ++last;
			scanCell(first, last);
			first = last;
		}
	}
	for (int s : oversize_)
		for (int t = 0; t < shellTotal; ++t)
			if (t != s && (!cellSpan_[t].oversize || s < t)) compareShells(s, t);
	return tests;
}

void MSCCollider::sortShellPairs(std::vector<ShellPair>& pairs, int blocks, std::vector<ShellPair>& scratch) {
	// By counting on the first block: each pair, read in order, is written
	// to its block's bucket in `scratch`, which is then swapped with `pairs`
	// (the reads of the pairs' blocks are independent, where swapping pairs
	// in place waited for one cache miss after another). pairStart_[b] is
	// where bucket b starts, then where it ends. Then each block's few pairs
	// by (t, s): flat shells go block after block, so the pairs of each
	// second block follow one another, in ascending order (the order within
	// a block pair changes nothing downstream).
	pairStart_.assign(static_cast<std::size_t>(blocks) + 1, 0);
	for (const ShellPair& p : pairs) ++pairStart_[shellBlock_[p.s] + 1];
	for (int b = 0; b < blocks; ++b) pairStart_[b + 1] += pairStart_[b];
	resizeWithHeadroom(scratch, pairs.size());
	for (const ShellPair& p : pairs) scratch[pairStart_[shellBlock_[p.s]]++] = p;
	pairs.swap(scratch);
	const auto before = [](const ShellPair& x, const ShellPair& y) { return x.t < y.t || (x.t == y.t && x.s < y.s); };
	for (int b = 0; b < blocks; ++b) {
		const std::size_t first = b > 0 ? pairStart_[b - 1] : 0;
		if (pairStart_[b] - first > 1) std::sort(pairs.begin() + first, pairs.begin() + pairStart_[b], before);
	}
}

bool MSCCollider::apartInFrame(int s, int t, const Eigen::Matrix3d& m, const Eigen::Matrix3d& size,
                               const Vector3& offset, double limit) const {
	const Vector3 middle = offset + m * (0.5 * (extentLow_[t] + extentHigh_[t]));
	const Vector3 half = size * (0.5 * (extentHigh_[t] - extentLow_[t]));
	return ((extentLow_[s] - middle - half).array() > limit).any() ||
	       ((middle - half - extentHigh_[s]).array() > limit).any();
}

void MSCCollider::findPairs(const std::vector<Block>& blocks, double contactDistance,
                            std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) {
	pairs.clear();
	stats = BroadPhaseStatistics{};
	linkedCount_ = 0;
	const int n = static_cast<int>(blocks.size());

	// Topology: the block count changed (all), a block's shape changed, or the
	// cover's parameters changed (blocks whose parameters differ).
	if (linkedSetsOverflow_) clearLinkedSets();
	if (static_cast<int>(covers_.size()) != n) covers_.assign(n, BlockCover{});
	std::vector<std::pair<int, Override>> builds;  // the covers to build, with their parameters
	for (int b = 0; b < n; ++b) {
		const BlockCover& cover = covers_[b];
		const bool fresh = cover.shape != blocks[b].shape;
		if (!fresh && !coverChanged_) continue;
		const auto own = overrides_.find(b);
		const double criticalLength = own != overrides_.end() ? own->second.criticalLength
		                              : criticalLength_ > 0  ? criticalLength_
		                                                     : criticalLengthFactor_ * blockSize(blocks[b]);
		const int segments = own != overrides_.end() ? own->second.segments : segments_;
		if (!fresh && criticalLength == cover.criticalLength && segments == cover.segments) continue;
		builds.push_back({b, Override{criticalLength, segments}});
	}
	coverChanged_ = false;
	if (!builds.empty()) {
		// New covers' parts, with the others' copied, block after block.
		std::vector<ShellRange> shellRanges;
		std::vector<DivisionPoint> divisions;
		std::vector<int> divisionStart;
		auto build = builds.begin();
		for (int b = 0; b < n; ++b) {
			BlockCover& cover = covers_[b];
			if (build != builds.end() && build->first == b) {
				buildCover(blocks[b], build->second.criticalLength, build->second.segments, cover, shellRanges,
				           divisions, divisionStart);
				++build;
				++coverBuilds_;
				continue;
			}
			const auto ranges = shellRanges_.begin() + cover.firstSubUnit;
			cover.firstSubUnit = static_cast<int>(shellRanges.size());
			shellRanges.insert(shellRanges.end(), ranges, ranges + cover.vertexCount + cover.edgeCount + cover.faceCount);
			for (int s = cover.firstShell; s < cover.firstShell + cover.shellCount; ++s) {
				divisionStart.push_back(static_cast<int>(divisions.size()));
				divisions.insert(divisions.end(), divisions_.begin() + divisionStart_[s],
				                 divisions_.begin() + divisionStart_[s + 1]);
			}
		}
		divisionStart.resize(divisionStart.size() + 2, static_cast<int>(divisions.size()));
		shellRanges.shrink_to_fit();  // (they grew by doubling)
		divisions.shrink_to_fit();
		divisionStart.shrink_to_fit();
		shellRanges_ = std::move(shellRanges);
		divisions_ = std::move(divisions);
		divisionStart_ = std::move(divisionStart);
		layoutShells();
	}
	const int shellTotal = static_cast<int>(shellBlock_.size());
	stats.shells = shellTotal;

	// Boxes, frames and extents: moving blocks every call, fixed blocks once.
	// The corners of the block kPrefetchBlocks ahead are fetched meanwhile
	// (each block's are a separate allocation, usually out of cache).
	const long updatesBefore = totalShellUpdates_;
	const auto needsUpdate = [&](int b) { return !blocks[b].fixed || !covers_[b].boxesBuilt; };
	resizeWithHeadroom(shellFixed_, shellTotal);
	for (int b = 0; b < n; ++b) {
		std::fill_n(shellFixed_.begin() + covers_[b].firstShell, covers_[b].shellCount, blocks[b].fixed);
		if (b + kPrefetchBlocks < n && needsUpdate(b + kPrefetchBlocks)) {
			const std::vector<Vector3>& ahead = blocks[b + kPrefetchBlocks].vertices;
			const char* first = reinterpret_cast<const char*>(ahead.data());
			for (std::size_t byte = 0; byte < ahead.size() * sizeof(Vector3); byte += 64) __builtin_prefetch(first + byte);
		}
		if (needsUpdate(b)) updateBoxes(blocks[b], covers_[b], frames_[b]);
	}
	stats.shellUpdates = totalShellUpdates_ - updatesBefore;
	if (n < 2) return;

	const double margin = kBroadPhaseMarginFactor * contactDistance;
	const double searchMargin = margin * (1 + kVerletSkinFactor);
	resizeWithHeadroom(widened_, shellTotal);
	for (int s = 0; s < shellTotal; ++s) {
		const Vector3 w = Vector3::Constant(margin + covers_[shellBlock_[s]].widening);
		widened_[s] = Eigen::AlignedBox3d(boxes_[s].min() - w, boxes_[s].max() + w);
	}
	const auto searchBox = [&](int s) {
		const Vector3 w = Vector3::Constant(searchMargin + covers_[shellBlock_[s]].widening);
		return Eigen::AlignedBox3d(boxes_[s].min() - w, boxes_[s].max() + w);
	};

	// Shell pairs whose d0-boxes meet, sorted.
	hits_.clear();
	if (!reuse_) {
		cacheValid_ = false;
		stats.shellTests = gridSearch(widened_, hits_);
		stats.blocksResearched = n;
		sortShellPairs(hits_, n, kept_);
	} else {
		// Blocks with a d0-box outside its D-box (the same floats as the
		// final test: boxes inside D-boxes that meet imply D-boxes that meet).
		bool full = !cacheValid_ || static_cast<int>(searchedFixed_.size()) != n;
		movers_.clear();
		moved_.assign(n, 0);
		for (int b = 0; b < n && !full; ++b) {
			if (static_cast<char>(blocks[b].fixed) != searchedFixed_[b]) {
				full = true;
				break;
			}
			const BlockCover& cover = covers_[b];
			for (int s = cover.firstShell; s < cover.firstShell + cover.shellCount; ++s)
				if (!searchBoxes_[s].contains(widened_[s])) {
					movers_.push_back(b);
					moved_[b] = 1;
					break;
				}
		}
		if (!full && static_cast<double>(movers_.size()) > kVerletPartialFactor * std::log2(std::max(2, n))) full = true;
		if (full) {
			resizeWithHeadroom(searchBoxes_, shellTotal);
			for (int s = 0; s < shellTotal; ++s) searchBoxes_[s] = searchBox(s);
			searchedFixed_.resize(n);
			for (int b = 0; b < n; ++b) searchedFixed_[b] = blocks[b].fixed;
			stats.shellTests = gridSearch(searchBoxes_, cached_);
			sortShellPairs(cached_, n, kept_);
			stats.blocksResearched = n;
			cacheValid_ = true;
		} else {
			stats.broadPhaseSkipped = 1;
			stats.blocksResearched = static_cast<long>(movers_.size());
			if (!movers_.empty()) {
				// Each mover's shells get new D-boxes and are compared with every shell.
				for (int m : movers_) {
					const BlockCover& cover = covers_[m];
					for (int s = cover.firstShell; s < cover.firstShell + cover.shellCount; ++s)
						searchBoxes_[s] = searchBox(s);
				}
				kept_.clear();
				for (const ShellPair& p : cached_)
					if (!moved_[shellBlock_[p.s]] && !moved_[shellBlock_[p.t]]) pushWithHeadroom(kept_, p);
				stats.pairsReused = static_cast<long>(kept_.size());
				for (int m : movers_) {
					const BlockCover& cover = covers_[m];
					for (int s = cover.firstShell; s < cover.firstShell + cover.shellCount; ++s)
						for (int t = 0; t < shellTotal; ++t) {
							const int b = shellBlock_[t];
							if (b == m || (moved_[b] && b < m) || (blocks[b].fixed && blocks[m].fixed)) continue;
							++stats.shellTests;
							if (searchBoxes_[s].intersects(searchBoxes_[t]))
								pushWithHeadroom(kept_, m < b ? ShellPair{s, t} : ShellPair{t, s});
						}
				}
				sortShellPairs(kept_, n, cached_);  // (cached_'s pairs are in kept_ now: work space)
				cached_.swap(kept_);
			} else {
				stats.pairsReused = static_cast<long>(cached_.size());
			}
		}
		// (The second shells lie anywhere: the box of the one kPrefetchHits
		// pairs ahead is fetched meanwhile.)
		for (std::size_t k = 0; k < cached_.size(); ++k) {
			if (k + kPrefetchHits < cached_.size()) {
				const Eigen::AlignedBox3d* ahead = &widened_[cached_[k + kPrefetchHits].t];
				__builtin_prefetch(ahead);
				__builtin_prefetch(reinterpret_cast<const char*>(ahead + 1) - 1);
			}
			const ShellPair& p = cached_[k];
			if (widened_[p.s].intersects(widened_[p.t])) pushWithHeadroom(hits_, p);
		}
		stats.shellTests += static_cast<long>(cached_.size());
	}

	// Per block pair: the shell pairs that also overlap in both frames, and
	// the union of their shells; a candidate links the union's sub-units
	// (lists shared per block and shell set).
	candidateSets_.clear();
	// The second blocks' frames and shells' extents are far apart in memory:
	// those of the shell pair kPrefetchHits ahead are fetched meanwhile, and
	// the first linked set of the second block half as far ahead (its frame
	// fetched by then).
	std::size_t prefetched = 0, prefetchedSets = 0;
	const auto prefetchUpTo = [&](std::size_t ahead) {
		for (std::size_t last = std::min(ahead, hits_.size()); prefetched < last; ++prefetched) {
			const int t = hits_[prefetched].t;
			const char* frame = reinterpret_cast<const char*>(&frames_[shellBlock_[t]]);
			for (std::size_t byte = 0; byte < sizeof(Frame); byte += 64) __builtin_prefetch(frame + byte);
			__builtin_prefetch(&extentLow_[t]);
			__builtin_prefetch(&extentHigh_[t]);
		}
		for (std::size_t last = std::min(ahead - kPrefetchHits / 2, hits_.size()); prefetchedSets < last; ++prefetchedSets) {
			const int set = frames_[shellBlock_[hits_[prefetchedSets].t]].linkedSets;
			if (set >= 0) __builtin_prefetch(&linkedSets_[set]);
		}
	};
	for (std::size_t h = 0; h < hits_.size();) {
		prefetchUpTo(h + kPrefetchHits);
		const int a = shellBlock_[hits_[h].s], b = shellBlock_[hits_[h].t];
		std::size_t end = h + 1;
		while (end < hits_.size() && shellBlock_[hits_[end].s] == a && shellBlock_[hits_[end].t] == b) ++end;
		const Frame& fa = frames_[a];
		const Frame& fb = frames_[b];
		const Vector3 between = fb.origin - fa.origin;
		const Eigen::Matrix3d inA = fa.axes * fb.dual;
		const Eigen::Matrix3d sizeInA = inA.cwiseAbs();
		const Vector3 offsetInA = fa.axes * between;
		const double roundoff =
		    kFrameRoundoffRelative * (between.cwiseAbs().sum() + 10 * (fa.reach + fb.reach));
		const double limit = 2 * margin + fa.widening + fb.widening + roundoff;
		// The test in b's frame is set up when first needed: in about half of
		// the block pairs every shell pair is apart in a's frame already.
		Eigen::Matrix3d inB, sizeInB;
		Vector3 offsetInB;
		bool frameB = false;
		std::uint64_t shellsA = 0, shellsB = 0;
		stats.shellTests += static_cast<long>(end - h);
		for (; h < end; ++h) {
			const int s = hits_[h].s, t = hits_[h].t;
			if (apartInFrame(s, t, inA, sizeInA, offsetInA, limit)) continue;
			if (!frameB) {
				inB = fb.axes * fa.dual;
				sizeInB = inB.cwiseAbs();
				offsetInB = fb.axes * (-between);
				frameB = true;
			}
			if (apartInFrame(t, s, inB, sizeInB, offsetInB, limit)) continue;
			++stats.shellPairs;
			shellsA |= std::uint64_t{1} << (s - fa.firstShell);
			shellsB |= std::uint64_t{1} << (t - fb.firstShell);
		}
		if (shellsA) {
			pairs.emplace_back(a, b);
			pushWithHeadroom(candidateSets_, {linkedSet(a, shellsA), linkedSet(b, shellsB)});
		}
	}
	if (linked_.size() < pairs.size()) resizeWithHeadroom(linked_, pairs.size());
	for (const std::array<int, 2>& sets : candidateSets_) {
		LinkedSubUnits& out = linked_[linkedCount_++];
		for (int i = 0; i < 2; ++i) {
			const std::array<int, 3>& lists = linkedSets_[sets[i]].lists;
			out.vertices[i] = SubUnitList(lists_[lists[0]]);
			out.edges[i] = SubUnitList(lists_[lists[1]]);
			out.faces[i] = SubUnitList(lists_[lists[2]]);
		}
		stats.subUnitPairs += out.subUnitPairs();
	}
	stats.candidatePairs = static_cast<long>(pairs.size());
}

std::size_t MSCCollider::memoryBytes() const {
	std::size_t bytes = capacityBytes(covers_) + capacityBytes(shellRanges_) + capacityBytes(divisions_) +
	                    capacityBytes(divisionStart_) + capacityBytes(frames_) + capacityBytes(boxes_) +
	                    capacityBytes(extentLow_) + capacityBytes(extentHigh_) + capacityBytes(shellBlock_) +
	                    capacityBytes(widened_) + capacityBytes(cellLow_) + capacityBytes(cellSpan_) +
	                    capacityBytes(cellEntries_) + capacityBytes(cellShells_) + capacityBytes(cellStart_) +
	                    capacityBytes(cellScratch_) + capacityBytes(oversize_) + capacityBytes(shellFixed_) +
	                    capacityBytes(pairStart_) + capacityBytes(hits_) +
	                    capacityBytes(candidateSets_) + capacityBytes(linked_) + capacityBytes(linkedSets_) +
	                    capacityBytes(lists_) + capacityBytes(listTable_) + capacityBytes(listScratch_) +
	                    capacityBytes(searchBoxes_) + capacityBytes(cached_) + capacityBytes(kept_) +
	                    capacityBytes(searchedFixed_) + capacityBytes(moved_) + capacityBytes(movers_) +
	                    overrides_.size() * (sizeof(Override) + 48);
	for (const std::vector<int>& list : lists_) bytes += capacityBytes(list);
	return bytes;
}

}  // namespace dda
