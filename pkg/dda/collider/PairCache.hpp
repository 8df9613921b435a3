// The candidate-pair cache (a Verlet list of bounding-volume pairs) that
// DESSCollider (one box per block) and MSCCollider (its shells) share, as
// Bullet's btOverlappingPairCache serves every broad phase.
//
// A search is made with each volume's box widened by D = d0 (1 +
// kVerletSkinFactor), its D-box, and every pair whose D-boxes meet is kept,
// with the D-boxes. At a later call a block whose d0-boxes all lie inside
// their D-boxes needs no search: two d0-boxes that meet, each inside its
// D-box, make D-boxes that meet, so their pair is cached. The test "inside"
// is on the floats the final test uses, so no round-off argument is needed.
// The other blocks (movers) get new D-boxes and are compared with every
// volume; a full search is made instead when more than kVerletPartialFactor
// x log2(n) blocks moved, when a block was fixed or freed, or when the cache
// is invalid. The broad phase then tests the cached pairs' d0-boxes, exactly
// the test of a search without cache: the pairs it returns, and their order,
// never depend on the cache; only the work does.
#pragma once

#include "BroadPhaseStatistics.hpp"

#include "dda/block/Block.hpp"
#include "dda/core/CapacityBytes.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace dda {

// Two bounding volumes (flat indices, "items"): first one of the pair's lower
// block, second one of its higher block.
using ItemPair = std::pair<int, int>;

// Volumes (the broad phase's side, a template parameter of update): its
// items, each of one block, a block's items consecutive, and its search.
//   int count() const;                       items in all
//   int first(int block) const, end(int block) const;  the block's items
//   int blockOf(int item) const;
//   const Eigen::AlignedBox3d& box(int item) const;     widened by d0
//   Eigen::AlignedBox3d searchBox(int item) const;      widened by D
//   long search(const std::vector<Eigen::AlignedBox3d>& boxes, std::vector<ItemPair>& out,
//               std::vector<ItemPair>& scratch);
//       every pair (not both fixed) whose `boxes` meet, sorted; returns the
//       box comparisons made (scratch: work space, its contents lost)
//   void sort(std::vector<ItemPair>& pairs, std::vector<ItemPair>& scratch) const;
//       sorts pairs in search's order (scratch as above)
class PairCache {
public:
	// Skin of the cache, x d0 [-]: a block may move this far (per coordinate
	// of its boxes) before it is searched again.
	static constexpr double kVerletSkinFactor = 1.0;
	// Blocks re-searched one by one (O(n) each) when at most this x log2(n)
	// left their allowance; else a full search.
	static constexpr double kVerletPartialFactor = 4.0;

	// How the cache's arrays grow. The two broad phases differ here, and each
	// keeps its own: DESS's arrays double (std::vector's growth), MSC's grow
	// by 1/8 (resizeWithHeadroom, pushWithHeadroom: it keeps its arrays at
	// their largest size). Only the capacities, hence memoryBytes, differ.
	enum class Growth { Doubling, Eighths };

	explicit PairCache(Growth growth) : growth_(growth) {}

	// Whether update may reuse earlier calls' pairs (else the broad phase
	// searches on its own and the cache is dropped).
	bool reuse() const { return reuse_; }
	void setReuse(bool reuse) {
		reuse_ = reuse;
		if (!reuse) valid_ = false;
	}
	// Drops the cache (the volumes were laid out anew): the next update searches all.
	void invalidate() { valid_ = false; }

	// Brings pairs() up to date for this call (stats: shellTests, the tests
	// made, blocksResearched, broadPhaseSkipped, pairsReused). The caller
	// then tests each cached pair's d0-boxes.
	template <class Volumes>
	void update(Volumes& volumes, const std::vector<Block>& blocks, BroadPhaseStatistics& stats);

	// Every pair (not both fixed) whose D-boxes meet, sorted as Volumes::sort does.
	const std::vector<ItemPair>& pairs() const { return cached_; }
	// Work space for the broad phase's own sort (its contents lost).
	std::vector<ItemPair>& scratch() { return kept_; }
	// Heap bytes held [bytes].
	std::size_t memoryBytes() const;

private:
	// Finds the movers; false when a full search is needed instead.
	template <class Volumes>
	bool findMovers(const Volumes& volumes, const std::vector<Block>& blocks);
	template <class Volumes>
	void searchAll(Volumes& volumes, const std::vector<Block>& blocks, BroadPhaseStatistics& stats);
	template <class Volumes>
	void researchMovers(const Volumes& volumes, const std::vector<Block>& blocks, BroadPhaseStatistics& stats);
	// Whether this many movers are better re-searched by a full search.
	bool tooManyMovers(int blocks) const;
	void push(std::vector<ItemPair>& v, const ItemPair& p) const {
		if (growth_ == Growth::Eighths) pushWithHeadroom(v, p);
		else v.push_back(p);
	}

	Growth growth_;
	bool reuse_ = true;
	bool valid_ = false;
	// Each item's D-box from its block's last search, every pair whose
	// D-boxes meet then (sorted), and the blocks' fixed flags then.
	std::vector<Eigen::AlignedBox3d> searchBoxes_;
	std::vector<ItemPair> cached_, kept_;
	std::vector<char> searchedFixed_;
	std::vector<char> moved_;  // per block, this call
	std::vector<int> movers_;
};

template <class Volumes>
void PairCache::update(Volumes& volumes, const std::vector<Block>& blocks, BroadPhaseStatistics& stats) {
	if (!findMovers(volumes, blocks) || tooManyMovers(static_cast<int>(blocks.size()))) {
		searchAll(volumes, blocks, stats);
		return;
	}
	stats.broadPhaseSkipped = 1;
	stats.blocksResearched = static_cast<long>(movers_.size());
	if (movers_.empty()) {
		stats.pairsReused = static_cast<long>(cached_.size());
		return;
	}
	researchMovers(volumes, blocks, stats);
}

template <class Volumes>
bool PairCache::findMovers(const Volumes& volumes, const std::vector<Block>& blocks) {
	const int n = static_cast<int>(blocks.size());
	movers_.clear();
	moved_.assign(n, 0);
	if (!valid_ || static_cast<int>(searchedFixed_.size()) != n) return false;
	for (int b = 0; b < n; ++b) {
		if (static_cast<char>(blocks[b].fixed) != searchedFixed_[b]) return false;
		for (int s = volumes.first(b); s < volumes.end(b); ++s)
			if (!searchBoxes_[s].contains(volumes.box(s))) {
				movers_.push_back(b);
				moved_[b] = 1;
				break;
			}
	}
	return true;
}

template <class Volumes>
void PairCache::searchAll(Volumes& volumes, const std::vector<Block>& blocks, BroadPhaseStatistics& stats) {
	const int n = static_cast<int>(blocks.size());
	if (growth_ == Growth::Eighths) resizeWithHeadroom(searchBoxes_, volumes.count());
	else searchBoxes_.resize(volumes.count());
	for (int s = 0; s < volumes.count(); ++s) searchBoxes_[s] = volumes.searchBox(s);
	searchedFixed_.resize(n);
	for (int b = 0; b < n; ++b) searchedFixed_[b] = blocks[b].fixed;
	stats.shellTests = volumes.search(searchBoxes_, cached_, kept_);
	stats.blocksResearched = n;
	valid_ = true;
}

template <class Volumes>
void PairCache::researchMovers(const Volumes& volumes, const std::vector<Block>& blocks, BroadPhaseStatistics& stats) {
	// Each mover's items get new D-boxes and are compared with every item.
	for (int m : movers_)
		for (int s = volumes.first(m); s < volumes.end(m); ++s) searchBoxes_[s] = volumes.searchBox(s);
	kept_.clear();
	for (const ItemPair& p : cached_)
		if (!moved_[volumes.blockOf(p.first)] && !moved_[volumes.blockOf(p.second)]) push(kept_, p);
	stats.pairsReused = static_cast<long>(kept_.size());
	for (int m : movers_)
		for (int s = volumes.first(m); s < volumes.end(m); ++s)
			for (int t = 0; t < volumes.count(); ++t) {
				const int b = volumes.blockOf(t);
				if (b == m || (moved_[b] && b < m) || (blocks[b].fixed && blocks[m].fixed)) continue;
				++stats.shellTests;
				if (searchBoxes_[s].intersects(searchBoxes_[t])) push(kept_, m < b ? ItemPair{s, t} : ItemPair{t, s});
			}
	volumes.sort(kept_, cached_);  // (cached_'s pairs are in kept_ now: work space)
	cached_.swap(kept_);
}

}  // namespace dda
