// MSCCollider's linked sets: per block and set of its shells, the sub-units
// (vertices, edges, faces) linked to those shells, built when first met and
// shared by every pair that links that set. Each distinct list of sub-units
// is kept once, found by hashing its contents (interning), so blocks of one
// topology share their lists.
#pragma once

#include "MultiShellCover.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace dda::msc {

// Linked sets kept per block (one per shell set met); when a block has
// more, every block's are dropped at the next call.
constexpr std::size_t kMaxLinkedSetsPerBlock = 64;

class LinkedSets {
public:
	// The index of the block's set for `shells` (built when new). chain: the
	// block's sets, most recently used first (moved to the front when found);
	// setCount: how many it has; linkedShells: the linked shells of its
	// vertices, then edges, then faces, whose counts are `counts`.
	int find(int& chain, int& setCount, const ShellRange* linkedShells, const std::array<int, 3>& counts,
	         std::uint64_t shells);
	// The block's set for `shells` if it has one, else -1; changes nothing
	// (the chain's order neither), so calls may run at once.
	int lookup(int chain, std::uint64_t shells) const {
		for (int k = chain; k >= 0; k = sets_[k].next)
			if (sets_[k].shells == shells) return k;
		return -1;
	}
	// The set's lists of vertices, edges and faces (sorted, unique).
	const std::vector<int>& vertices(int set) const { return lists_[sets_[set].lists[0]]; }
	const std::vector<int>& edges(int set) const { return lists_[sets_[set].lists[1]]; }
	const std::vector<int>& faces(int set) const { return lists_[sets_[set].lists[2]]; }
	void prefetch(int set) const { __builtin_prefetch(&sets_[set]); }
	// Whether a block has more than kMaxLinkedSetsPerBlock sets.
	bool overflowed() const { return overflowed_; }
	// Drops every set and list (the blocks' chains and counts are the caller's).
	void clear();
	std::size_t memoryBytes() const;

private:
	// The sub-units linked to a set of a block's shells: indices into lists_
	// of its vertices, edges and faces.
	struct LinkedSet {
		std::uint64_t shells;
		int next;  // the block's next set in its chain, -1: none
		std::array<int, 3> lists;
	};
	// Index into lists_ of a list equal to `list` (added when new).
	int intern(const std::vector<int>& list);

	std::vector<LinkedSet> sets_;
	std::vector<std::vector<int>> lists_;
	// lists_ by hash of their contents (open addressing, -1 = free), and work space.
	std::vector<int> table_, scratch_;
	bool overflowed_ = false;
};

}  // namespace dda::msc
