#include "MSCCollider.hpp"

#include "FrameTest.hpp"

#include "dda/core/CapacityBytes.hpp"
#include "dda/core/Errors.hpp"
#include "dda/core/StateStream.hpp"

#include <algorithm>
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
// The frame test (FrameTest.hpp) uses nothing else.

namespace dda {

namespace {

// Shell pairs ahead whose second shell's box is prefetched in the cache's
// final test, and whose second block's frame is prefetched in the frame test.
constexpr std::size_t kPrefetchHits = 16;
// The frame tests of block pairs, per group of shell pairs: prefetch
// distance, and the fewest groups worth a thread team (a group's test takes
// about 0.2 us).
constexpr int kPrefetchGroups = 8;
constexpr int kMinGroupsForThreads = 1024;
// The ordered selections (orderedSelect): segments of this many items, and
// the fewest items worth a thread team (an item's test is a few nanoseconds,
// waking a team tens of microseconds).
constexpr std::size_t kSelectSegment = 4096;
constexpr std::size_t kMinItemsForThreads = 16384;

}  // namespace

// What the pair cache sees: the flat shells, each shell's d0-box (widened_),
// its D-box, and the grid search.
struct MSCCollider::Volumes {
	MSCCollider& msc;
	int blocks;
	double searchMargin;  // [m]: D
	int count() const { return msc.cover_.shellTotal(); }
	int first(int block) const { return msc.cover_.cover(block).firstShell; }
	int end(int block) const { return first(block) + msc.cover_.cover(block).shellCount; }
	int blockOf(int shell) const { return msc.cover_.shellBlock()[shell]; }
	const Eigen::AlignedBox3d& box(int shell) const { return msc.widened_[shell]; }
	Eigen::AlignedBox3d searchBox(int shell) const {
		const Eigen::AlignedBox3d& box = msc.cover_.boxes()[shell];
		const Vector3 w = Vector3::Constant(searchMargin + msc.cover_.cover(blockOf(shell)).widening);
		return Eigen::AlignedBox3d(box.min() - w, box.max() + w);
	}
	long search(const std::vector<Eigen::AlignedBox3d>& boxes, std::vector<ItemPair>& out,
	            std::vector<ItemPair>& scratch) {
		const long tests = msc.grid_.search(boxes, msc.cover_.shellBlock(), msc.cover_.shellFixed(), out);
		msc.sortShellPairs(out, blocks, scratch);
		return tests;
	}
	void sort(std::vector<ItemPair>& pairs, std::vector<ItemPair>& scratch) const {
		msc.sortShellPairs(pairs, blocks, scratch);
	}
};

const LinkedSubUnits* MSCCollider::linked(int pairIndex) const {
	return pairIndex >= 0 && pairIndex < linkedCount_ ? &linked_[pairIndex] : nullptr;
}

const Eigen::AlignedBox3d& MSCCollider::shellBox(int block, int shell) const {
	const msc::BlockCover& cover = cover_.coverAt(block);
	if (shell < 0 || shell >= cover.shellCount)
		throw InputError("MSCCollider: block " + std::to_string(block) + " has " + std::to_string(cover.shellCount) +
		                 " shells, asked for shell " + std::to_string(shell));
	return cover_.boxes()[cover.firstShell + shell];
}

int MSCCollider::linkedSet(int block, std::uint64_t shells) {
	const msc::BlockCover& cover = cover_.cover(block);
	return linkedSets_.find(cover_.linkedSetChain(block), cover_.linkedSetCount(block), cover_.subUnitShells(block),
	                        {cover.vertexCount, cover.edgeCount, cover.faceCount}, shells);
}

void MSCCollider::clearLinkedSets() {
	linkedSets_.clear();
	cover_.forgetLinkedSets();
}

void MSCCollider::sortShellPairs(std::vector<ItemPair>& pairs, int blocks, std::vector<ItemPair>& scratch) {
	// By counting on the first block: each pair, read in order, is written
	// to its block's bucket in `scratch`, which is then swapped with `pairs`
	// (the reads of the pairs' blocks are independent, where swapping pairs
	// in place waited for one cache miss after another). pairStart_[b] is
	// where bucket b starts, then where it ends. Then each block's few pairs
	// by (t, s): flat shells go block after block, so the pairs of each
	// second block follow one another, in ascending order (the order within
	// a block pair changes nothing downstream).
	const std::vector<int>& shellBlock = cover_.shellBlock();
	pairStart_.assign(static_cast<std::size_t>(blocks) + 1, 0);
	for (const ItemPair& p : pairs) ++pairStart_[shellBlock[p.first] + 1];
	for (int b = 0; b < blocks; ++b) pairStart_[b + 1] += pairStart_[b];
	resizeWithHeadroom(scratch, pairs.size());
	for (const ItemPair& p : pairs) scratch[pairStart_[shellBlock[p.first]]++] = p;
	pairs.swap(scratch);
	const auto before = [](const ItemPair& x, const ItemPair& y) {
		return x.second < y.second || (x.second == y.second && x.first < y.first);
	};
	for (int b = 0; b < blocks; ++b) {
		const std::size_t first = b > 0 ? pairStart_[b - 1] : 0;
		if (pairStart_[b] - first > 1) std::sort(pairs.begin() + first, pairs.begin() + pairStart_[b], before);
	}
}

// The items k in [0, count) for which keep(k) holds, in ascending order, as
// out[i] = make(k) (out resized to their number). Each segment of
// kSelectSegment items is tested on any thread and counted; the segments'
// offsets are then summed in order and each segment writes its own items from
// its offset: the serial loop's result, however the segments were shared.
template <class T, class Keep, class Make>
void MSCCollider::orderedSelect(std::size_t count, std::vector<T>& out, const Keep& keep, const Make& make) {
	const std::size_t segments = (count + kSelectSegment - 1) / kSelectSegment;
	resizeWithHeadroom(selectKept_, count);
	resizeWithHeadroom(segmentStart_, segments + 1);
	segmentStart_[0] = 0;
	const long segmentCount = static_cast<long>(segments);
#pragma omp parallel if (count >= kMinItemsForThreads)
	{
#pragma omp for schedule(dynamic, 1)
		for (long g = 0; g < segmentCount; ++g) {
			const std::size_t first = static_cast<std::size_t>(g) * kSelectSegment;
			const std::size_t end = std::min(count, first + kSelectSegment);
			std::size_t kept = 0;
			for (std::size_t k = first; k < end; ++k) {
				selectKept_[k] = keep(k);
				kept += selectKept_[k];
			}
			segmentStart_[g + 1] = kept;
		}
#pragma omp single
		{
			for (std::size_t g = 0; g < segments; ++g) segmentStart_[g + 1] += segmentStart_[g];
			resizeWithHeadroom(out, segmentStart_[segments]);
		}
#pragma omp for schedule(dynamic, 1)
		for (long g = 0; g < segmentCount; ++g) {
			const std::size_t first = static_cast<std::size_t>(g) * kSelectSegment;
			const std::size_t end = std::min(count, first + kSelectSegment);
			std::size_t at = segmentStart_[g];
			for (std::size_t k = first; k < end; ++k)
				if (selectKept_[k]) out[at++] = make(k);
		}
	}
}

void MSCCollider::findPairs(const std::vector<Block>& blocks, double contactDistance,
                            std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) {
	pairs.clear();
	stats = BroadPhaseStatistics{};
	linkedCount_ = 0;
	if (linkedSets_.overflowed()) clearLinkedSets();
	if (cover_.update(blocks)) {
		clearLinkedSets();
		cache_.invalidate();
	}
	stats.shells = cover_.shellTotal();
	stats.shellUpdates = cover_.updateShells(blocks);
	if (blocks.size() < 2) return;
	const double margin = kBroadPhaseMarginFactor * contactDistance;
	findShellHits(blocks, margin, stats);
	testBlockPairs(margin, pairs, stats);
	fillLinked(pairs.size(), stats);
	stats.candidatePairs = static_cast<long>(pairs.size());
}

void MSCCollider::findShellHits(const std::vector<Block>& blocks, double margin, BroadPhaseStatistics& stats) {
	const int n = static_cast<int>(blocks.size());
	const int shellTotal = cover_.shellTotal();
	const std::vector<Eigen::AlignedBox3d>& boxes = cover_.boxes();
	resizeWithHeadroom(widened_, shellTotal);
#pragma omp parallel for schedule(static) if (static_cast<std::size_t>(shellTotal) >= kMinItemsForThreads)
	for (int s = 0; s < shellTotal; ++s) {
		const Vector3 w = Vector3::Constant(margin + cover_.cover(cover_.shellBlock()[s]).widening);
		widened_[s] = Eigen::AlignedBox3d(boxes[s].min() - w, boxes[s].max() + w);
	}
	hits_.clear();
	if (!cache_.reuse()) {
		stats.shellTests = grid_.search(widened_, cover_.shellBlock(), cover_.shellFixed(), hits_);
		stats.blocksResearched = n;
		sortShellPairs(hits_, n, cache_.scratch());
		return;
	}
	Volumes volumes{*this, n, margin * (1 + PairCache::kVerletSkinFactor)};
	cache_.update(volumes, blocks, stats);
	// The pairs a search without cache finds: the cached ones whose d0-boxes
	// meet. (The second shells lie anywhere: the box of the one
	// kPrefetchHits pairs ahead is fetched meanwhile.)
	const std::vector<ItemPair>& cached = cache_.pairs();
	const std::size_t cachedCount = cached.size();
	orderedSelect(
	    cachedCount, hits_,
	    [&](std::size_t k) {
		    if (k + kPrefetchHits < cachedCount) {
			    const Eigen::AlignedBox3d* ahead = &widened_[cached[k + kPrefetchHits].second];
			    __builtin_prefetch(ahead);
			    __builtin_prefetch(reinterpret_cast<const char*>(ahead + 1) - 1);
		    }
		    return widened_[cached[k].first].intersects(widened_[cached[k].second]);
	    },
	    [&](std::size_t k) { return cached[k]; });
	stats.shellTests += static_cast<long>(cachedCount);
}

// The frame test of each block pair's shell pairs (a run of hits_ with the
// same two blocks: a group) is pure and runs on the step's threads, which
// also look up the linked sets the pair's shells already have (a lookup
// changes nothing). The candidates and the sets still to build are then
// taken in group order, as by one thread: sets are numbered as they are
// built, and a set built for one group is found by the later ones.
void MSCCollider::testBlockPairs(double margin, std::vector<std::pair<int, int>>& pairs, BroadPhaseStatistics& stats) {
	const std::vector<int>& shellBlock = cover_.shellBlock();
	const std::vector<msc::Frame>& frames = cover_.frames();
	candidateSets_.clear();
	const std::size_t hitCount = hits_.size();
	orderedSelect(
	    hitCount, groupStart_,
	    [&](std::size_t h) {
		    return h == 0 || shellBlock[hits_[h].first] != shellBlock[hits_[h - 1].first] ||
		           shellBlock[hits_[h].second] != shellBlock[hits_[h - 1].second];
	    },
	    [](std::size_t h) { return h; });
	const int groups = static_cast<int>(groupStart_.size());
	groupStart_.push_back(hitCount);
	groupShells_.resize(groups);
	groupSets_.resize(groups);
	stats.shellTests += static_cast<long>(hitCount);
	long shellPairs = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : shellPairs) if (groups >= kMinGroupsForThreads)
	for (int g = 0; g < groups; ++g) {
		// The second block's frame and extents are far apart in memory: those
		// of the group kPrefetchGroups ahead are fetched meanwhile.
		if (g + kPrefetchGroups < groups) {
			const int t = hits_[groupStart_[g + kPrefetchGroups]].second;
			const char* frame = reinterpret_cast<const char*>(&frames[shellBlock[t]]);
			for (std::size_t byte = 0; byte < sizeof(msc::Frame); byte += 64) __builtin_prefetch(frame + byte);
			__builtin_prefetch(&cover_.extentLow()[t]);
			__builtin_prefetch(&cover_.extentHigh()[t]);
		}
		const std::size_t first = groupStart_[g], end = groupStart_[g + 1];
		const msc::Frame& fa = frames[shellBlock[hits_[first].first]];
		const msc::Frame& fb = frames[shellBlock[hits_[first].second]];
		msc::FrameTest frameTest(fa, fb, margin, cover_.extentLow(), cover_.extentHigh());
		std::uint64_t shellsA = 0, shellsB = 0;
		for (std::size_t h = first; h < end; ++h) {
			const int s = hits_[h].first, t = hits_[h].second;
			if (!frameTest.near(s, t)) continue;
			++shellPairs;
			shellsA |= std::uint64_t{1} << (s - fa.firstShell);
			shellsB |= std::uint64_t{1} << (t - fb.firstShell);
		}
		groupShells_[g] = {shellsA, shellsB};
		if (shellsA) groupSets_[g] = {linkedSets_.lookup(fa.linkedSets, shellsA), linkedSets_.lookup(fb.linkedSets, shellsB)};
	}
	stats.shellPairs += shellPairs;
	for (int g = 0; g < groups; ++g) {
		const auto [shellsA, shellsB] = groupShells_[g];
		if (!shellsA) continue;
		const int a = shellBlock[hits_[groupStart_[g]].first], b = shellBlock[hits_[groupStart_[g]].second];
		pairs.emplace_back(a, b);
		const auto [setA, setB] = groupSets_[g];
		pushWithHeadroom(candidateSets_, {setA >= 0 ? setA : linkedSet(a, shellsA), setB >= 0 ? setB : linkedSet(b, shellsB)});
	}
}

void MSCCollider::fillLinked(std::size_t candidates, BroadPhaseStatistics& stats) {
	if (linked_.size() < candidates) resizeWithHeadroom(linked_, candidates);
	const int count = static_cast<int>(candidateSets_.size());
	long subUnitPairs = 0;
#pragma omp parallel for schedule(static) reduction(+ : subUnitPairs) if (count >= kMinGroupsForThreads)
	for (int k = 0; k < count; ++k) {
		const std::array<int, 2>& sets = candidateSets_[k];
		LinkedSubUnits& out = linked_[k];
		for (int i = 0; i < 2; ++i) {
			out.vertices[i] = SubUnitList(linkedSets_.vertices(sets[i]));
			out.edges[i] = SubUnitList(linkedSets_.edges(sets[i]));
			out.faces[i] = SubUnitList(linkedSets_.faces(sets[i]));
		}
		subUnitPairs += out.subUnitPairs();
	}
	linkedCount_ = count;
	stats.subUnitPairs += subUnitPairs;
}

std::size_t MSCCollider::memoryBytes() const {
	return cover_.memoryBytes() + grid_.memoryBytes() + linkedSets_.memoryBytes() + cache_.memoryBytes() +
	       capacityBytes(widened_) + capacityBytes(pairStart_) + capacityBytes(hits_) + capacityBytes(candidateSets_) + capacityBytes(groupStart_) +
	       capacityBytes(groupShells_) + capacityBytes(groupSets_) + capacityBytes(selectKept_) + capacityBytes(segmentStart_) +
	       capacityBytes(linked_);
}

void MSCCollider::writeState(StateWriter& out) const {
	out.tag("MSC.");
	cover_.write(out);
}

void MSCCollider::readState(StateReader& in, const std::vector<Block>& blocks) {
	// Into a fresh collider (parameters as read, no linked sets, no cache),
	// which then replaces this one.
	MSCCollider restored;
	in.tag("MSC.");
	restored.cover_.read(in, blocks);
	*this = std::move(restored);
}

}  // namespace dda
