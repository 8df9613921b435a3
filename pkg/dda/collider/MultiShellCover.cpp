#include "MultiShellCover.hpp"

#include "dda/core/CapacityBytes.hpp"
#include "dda/core/Errors.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace dda::msc {

namespace {

// Blocks ahead whose corners are prefetched while boxes are updated.
constexpr int kPrefetchBlocks = 4;
// Scenes with fewer blocks update their shells on one thread: below about a
// thousand blocks the update (0.1 us a block) is shorter than a thread
// team's start. The solver's loops use the same threshold (StepClock.hpp).
constexpr int kMinBlocksForThreads = 1024;

void checkCover(double criticalLength, int segments, const std::string& what) {
	if (!(criticalLength > 0) || !std::isfinite(criticalLength))
		throw InputError(what + ": critical length must be positive and finite, got " + std::to_string(criticalLength));
	if (segments < 1 || segments > kMaxCoverSegments)
		throw InputError(what + ": segments must be in [1, " + std::to_string(kMaxCoverSegments) + "], got " +
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

// Main axis: the principal direction of largest spread of the corners, and
// their mean.
Vector3 mainAxis(const std::vector<Vector3>& x, Vector3& mean) {
	mean = Vector3::Zero();
	for (const Vector3& p : x) mean += p;
	mean /= static_cast<int>(x.size());
	Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
	for (const Vector3& p : x) spread += (p - mean) * (p - mean).transpose();
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(spread);
	return eigen.eigenvectors().col(2);  // eigenvalues ascending
}

// The frame: the face most across the main axis, the face most across
// that one, and the face that spans most volume with both; -1s when those
// span less than kMinFrameDeterminant.
std::array<int, 3> frameFacesOf(const PolyhedronTopology& shape, const std::vector<Vector3>& x, const Vector3& axis) {
	const int nf = static_cast<int>(shape.faces.size());
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
		if (f3 >= 0 && std::abs(normals[f3].dot(across)) >= kMinFrameDeterminant) return {f1, f2, f3};
	}
	return {-1, -1, -1};
}

// Per vertex, edge and face its linked slabs, appended to shellRanges: the
// slabs its interval of s (the corners' positions along the main axis)
// touches. Slab j is [bound[j], bound[j + 1]], closed: a sub-unit on a plane
// is in both.
void linkSubUnits(const PolyhedronTopology& shape, const std::vector<double>& s, const std::vector<double>& bound,
                  std::vector<ShellRange>& shellRanges) {
	const int k = static_cast<int>(bound.size()) - 1;
	// The slabs an interval [lo, hi] touches: consecutive ones (the bounds
	// ascend, except that bound[k - 1] may pass bound[k] by round-off, which
	// only drops slab k - 1), so a range.
	const auto shellsOf = [&](double lo, double hi) {
		std::uint64_t mask = 0;
		for (int j = 0; j < k; ++j)
			if (lo <= bound[j + 1] && hi >= bound[j]) mask |= std::uint64_t{1} << j;
		return ShellRange::of(mask);
	};
	for (const double v : s) shellRanges.push_back(shellsOf(v, v));
	for (const auto& e : shape.edges) {
		const double s0 = s[e[0]], s1 = s[e[1]];
		shellRanges.push_back(shellsOf(std::min(s0, s1), std::max(s0, s1)));
	}
	for (const auto& face : shape.faces) {
		double lo = s[face[0]], hi = lo;
		for (int v : face) {
			lo = std::min(lo, s[v]);
			hi = std::max(hi, s[v]);
		}
		shellRanges.push_back(shellsOf(lo, hi));
	}
}

// Division points on the slabs' inner planes (the outer ends hold corners),
// each plane's listed with the slab above it; divisionStart: one entry per slab.
void addDivisionPoints(const PolyhedronTopology& shape, const std::vector<double>& s, const std::vector<double>& bound,
                       std::vector<DivisionPoint>& divisions, std::vector<int>& divisionStart) {
	const int k = static_cast<int>(bound.size()) - 1;
	for (int j = 0; j < k; ++j) {
		divisionStart.push_back(static_cast<int>(divisions.size()));
		if (j == 0) continue;
		const double plane = bound[j];
		for (const auto& e : shape.edges) {
			const double s0 = s[e[0]], s1 = s[e[1]];
			if (std::min(s0, s1) < plane && plane < std::max(s0, s1))
				divisions.push_back({e[0], e[1], std::clamp((plane - s0) / (s1 - s0), 0.0, 1.0)});
		}
	}
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

}  // namespace

MultiShellCover::MultiShellCover(double criticalLengthFactor, int segments)
    : criticalLengthFactor_(criticalLengthFactor), segments_(segments) {
	checkCover(criticalLengthFactor, segments, "MSCCollider");
}

void MultiShellCover::setCover(double criticalLength, int segments) {
	if (!(criticalLength >= 0) || !std::isfinite(criticalLength))
		throw InputError("MSCCollider: critical length must be >= 0 (0: by block size) and finite, got " +
		                 std::to_string(criticalLength));
	checkCover(criticalLength == 0 ? 1.0 : criticalLength, segments, "MSCCollider");
	criticalLength_ = criticalLength;
	segments_ = segments;
	coverChanged_ = true;
}

void MultiShellCover::setBlockCover(int block, double criticalLength, int segments) {
	if (block < 0) throw InputError("MSCCollider: block index must be >= 0, got " + std::to_string(block));
	checkCover(criticalLength, segments, "MSCCollider block " + std::to_string(block));
	overrides_[block] = CoverParameters{criticalLength, segments};
	coverChanged_ = true;
}

std::vector<std::pair<int, CoverParameters>> MultiShellCover::coversToBuild(const std::vector<Block>& blocks) const {
	std::vector<std::pair<int, CoverParameters>> builds;
	for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
		const BlockCover& cover = covers_[b];
		const bool fresh = cover.shape != blocks[b].shape;
		if (!fresh && !coverChanged_) continue;
		const auto own = overrides_.find(b);
		const double criticalLength = own != overrides_.end() ? own->second.criticalLength
		                              : criticalLength_ > 0  ? criticalLength_
		                                                     : criticalLengthFactor_ * blockSize(blocks[b]);
		const int segments = own != overrides_.end() ? own->second.segments : segments_;
		if (!fresh && criticalLength == cover.criticalLength && segments == cover.segments) continue;
		builds.push_back({b, CoverParameters{criticalLength, segments}});
	}
	return builds;
}

bool MultiShellCover::update(const std::vector<Block>& blocks) {
	// Topology: the block count changed (all), a block's shape changed, or the
	// cover's parameters changed (blocks whose parameters differ).
	const int n = static_cast<int>(blocks.size());
	if (static_cast<int>(covers_.size()) != n) covers_.assign(n, BlockCover{});
	const std::vector<std::pair<int, CoverParameters>> builds = coversToBuild(blocks);
	coverChanged_ = false;
	if (builds.empty()) return false;
	// New covers' parts, with the others' copied, block after block.
	std::vector<ShellRange> shellRanges;
	std::vector<DivisionPoint> divisions;
	std::vector<int> divisionStart;
	auto build = builds.begin();
	for (int b = 0; b < n; ++b) {
		if (build != builds.end() && build->first == b) {
			buildCover(blocks[b], build->second, covers_[b], shellRanges, divisions, divisionStart);
			++build;
			++coverBuilds_;
		} else {
			copyCover(covers_[b], shellRanges, divisions, divisionStart);
		}
	}
	adopt(shellRanges, divisions, divisionStart);
	return true;
}

void MultiShellCover::copyCover(BlockCover& cover, std::vector<ShellRange>& shellRanges,
                                std::vector<DivisionPoint>& divisions, std::vector<int>& divisionStart) const {
	const auto ranges = shellRanges_.begin() + cover.firstSubUnit;
	cover.firstSubUnit = static_cast<int>(shellRanges.size());
	shellRanges.insert(shellRanges.end(), ranges, ranges + cover.vertexCount + cover.edgeCount + cover.faceCount);
	for (int s = cover.firstShell; s < cover.firstShell + cover.shellCount; ++s) {
		divisionStart.push_back(static_cast<int>(divisions.size()));
		divisions.insert(divisions.end(), divisions_.begin() + divisionStart_[s], divisions_.begin() + divisionStart_[s + 1]);
	}
}

void MultiShellCover::adopt(std::vector<ShellRange>& shellRanges, std::vector<DivisionPoint>& divisions,
                            std::vector<int>& divisionStart) {
	divisionStart.resize(divisionStart.size() + 2, static_cast<int>(divisions.size()));
	shellRanges.shrink_to_fit();  // (they grew by doubling)
	divisions.shrink_to_fit();
	divisionStart.shrink_to_fit();
	shellRanges_ = std::move(shellRanges);
	divisions_ = std::move(divisions);
	divisionStart_ = std::move(divisionStart);
	layoutShells();
}

void MultiShellCover::buildCover(const Block& block, const CoverParameters& parameters, BlockCover& cover,
                                 std::vector<ShellRange>& shellRanges, std::vector<DivisionPoint>& divisions,
                                 std::vector<int>& divisionStart) const {
	const PolyhedronTopology& shape = *block.shape;
	const std::vector<Vector3>& x = block.vertices;
	const int nv = static_cast<int>(x.size());
	const int ne = static_cast<int>(shape.edges.size());
	const int nf = static_cast<int>(shape.faces.size());
	cover.shape = block.shape;
	cover.criticalLength = parameters.criticalLength;
	cover.segments = parameters.segments;
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
	const int k = longest > parameters.criticalLength ? parameters.segments : 1;
	cover.shellCount = k;
	Vector3 mean;
	const Vector3 axis = mainAxis(x, mean);
	cover.frameFaces = frameFacesOf(shape, x, axis);
	copyFrameCorners(shape, cover);
	if (k == 1) {
		shellRanges.insert(shellRanges.end(), nv + ne + nf, ShellRange::of(1));
		divisionStart.push_back(static_cast<int>(divisions.size()));
		return;
	}
	std::vector<double> s(nv);
	for (int v = 0; v < nv; ++v) s[v] = axis.dot(x[v] - mean);
	const double low = *std::min_element(s.begin(), s.end()), high = *std::max_element(s.begin(), s.end());
	std::vector<double> bound(k + 1);
	for (int j = 0; j <= k; ++j) bound[j] = low + (high - low) * j / k;
	bound[k] = high;
	linkSubUnits(shape, s, bound, shellRanges);
	addDivisionPoints(shape, s, bound, divisions, divisionStart);
}

void MultiShellCover::copyFrameCorners(const PolyhedronTopology& shape, BlockCover& cover) {
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

void MultiShellCover::layoutShells() {
	int total = 0;
	for (BlockCover& cover : covers_) {
		cover.firstShell = total;
		cover.boxesBuilt = false;
		total += cover.shellCount;
	}
	// A grid entry keeps a shell index in 29 bits (ShellGrid).
	if (total >= 1 << 29) throw InputError("MSCCollider: more than 2^29 shells (" + std::to_string(total) + ")");
	resizeWithHeadroom(boxes_, total);
	resizeWithHeadroom(extentLow_, total);
	resizeWithHeadroom(extentHigh_, total);
	resizeWithHeadroom(shellBlock_, total);
	resizeWithHeadroom(frames_, covers_.size());
	for (int b = 0; b < static_cast<int>(covers_.size()); ++b)
		std::fill_n(shellBlock_.begin() + covers_[b].firstShell, covers_[b].shellCount, b);
}

void MultiShellCover::forgetLinkedSets() {
	for (BlockCover& cover : covers_) cover.linkedSetCount = 0;
	for (Frame& frame : frames_) frame.linkedSets = -1;
}

long MultiShellCover::updateShells(const std::vector<Block>& blocks) {
	// The corners of the block kPrefetchBlocks ahead are fetched meanwhile
	// (each block's are a separate allocation, usually out of cache). Each
	// block writes only its own cover, frame and shells: the blocks are
	// shared among the step's threads (static chunks keep each thread's
	// blocks consecutive, so the prefetch still runs ahead of it).
	const int n = static_cast<int>(blocks.size());
	const auto needsUpdate = [&](int b) { return !blocks[b].fixed || blocks[b].shaken || !covers_[b].boxesBuilt; };
	resizeWithHeadroom(shellFixed_, shellBlock_.size());
	long updates = 0;
#pragma omp parallel for schedule(static, 256) reduction(+ : updates) if (n >= kMinBlocksForThreads)
	for (int b = 0; b < n; ++b) {
		std::fill_n(shellFixed_.begin() + covers_[b].firstShell, covers_[b].shellCount, blocks[b].fixed);
		if (b + kPrefetchBlocks < n && needsUpdate(b + kPrefetchBlocks)) {
			const std::vector<Vector3>& ahead = blocks[b + kPrefetchBlocks].vertices;
			const char* first = reinterpret_cast<const char*>(ahead.data());
			for (std::size_t byte = 0; byte < ahead.size() * sizeof(Vector3); byte += 64) __builtin_prefetch(first + byte);
		}
		if (needsUpdate(b)) updates += updateBoxes(blocks[b], covers_[b], frames_[b]);
	}
	totalShellUpdates_ += updates;
	return updates;
}

void MultiShellCover::updateFrame(const Block& block, const BlockCover& cover, Frame& frame) const {
	const PolyhedronTopology& shape = *block.shape;
	const std::vector<Vector3>& x = block.vertices;
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
}

int MultiShellCover::updateBoxes(const Block& block, BlockCover& cover, Frame& frame) {
	const std::vector<Vector3>& x = block.vertices;
	updateFrame(block, cover, frame);
	// Each point is computed once and added to the shells it lies in: a
	// vertex to its linked shells, a division point to the two slabs of its
	// plane. A shell gets its corners, then the points on its lower plane,
	// then those on its upper one (the order of the saved per-shell lists).
	std::array<ShellBounds, kMaxCoverSegments> bounds;
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
	cover.boxesBuilt = block.fixed && !block.shaken;  // a shaken block's boxes move with it
	return cover.shellCount;
}

std::size_t MultiShellCover::memoryBytes() const {
	return capacityBytes(covers_) + capacityBytes(shellRanges_) + capacityBytes(divisions_) +
	       capacityBytes(divisionStart_) + capacityBytes(frames_) + capacityBytes(boxes_) + capacityBytes(extentLow_) +
	       capacityBytes(extentHigh_) + capacityBytes(shellBlock_) + capacityBytes(shellFixed_) +
	       overrides_.size() * (sizeof(CoverParameters) + 48);
}

}  // namespace dda::msc
