#include "LinkedSets.hpp"

#include "dda/core/CapacityBytes.hpp"

#include <algorithm>

namespace dda::msc {

namespace {

std::uint64_t hashList(const std::vector<int>& list) {
	std::uint64_t h = list.size();
	for (int i : list) {
		h = (h ^ static_cast<std::uint32_t>(i)) * 0x9E3779B97F4A7C15ULL;
		h ^= h >> 29;
	}
	return h;
}

}  // namespace

int LinkedSets::find(int& chain, int& setCount, const ShellRange* linkedShells, const std::array<int, 3>& counts,
                     std::uint64_t shells) {
	// The chain is searched from the set used last (a block's pairs often
	// link the same shells), which is moved to its front when found.
	for (int k = chain, previous = -1; k >= 0; previous = k, k = sets_[k].next)
		if (sets_[k].shells == shells) {
			if (previous >= 0) {
				sets_[previous].next = sets_[k].next;
				sets_[k].next = chain;
				chain = k;
			}
			return k;
		}
	LinkedSet set{shells, chain, {}};
	for (int kind = 0; kind < 3; ++kind) {
		scratch_.clear();
		for (int i = 0; i < counts[kind]; ++i)
			if (linkedShells[i].mask() & shells) scratch_.push_back(i);
		linkedShells += counts[kind];
		set.lists[kind] = intern(scratch_);
	}
	chain = static_cast<int>(sets_.size());
	pushWithHeadroom(sets_, set);
	if (static_cast<std::size_t>(++setCount) > kMaxLinkedSetsPerBlock) overflowed_ = true;
	return chain;
}

int LinkedSets::intern(const std::vector<int>& list) {
	const auto place = [this](int k) {
		const std::size_t mask = table_.size() - 1;
		std::size_t slot = hashList(lists_[k]) & mask;
		while (table_[slot] >= 0) slot = (slot + 1) & mask;
		table_[slot] = k;
	};
	// The table is kept at most half full (a power of two).
	if (2 * (lists_.size() + 1) > table_.size()) {
		table_.assign(std::max<std::size_t>(64, 2 * table_.size()), -1);
		for (int k = 0; k < static_cast<int>(lists_.size()); ++k) place(k);
	}
	const std::size_t mask = table_.size() - 1;
	std::size_t slot = hashList(list) & mask;
	for (; table_[slot] >= 0; slot = (slot + 1) & mask)
		if (lists_[table_[slot]] == list) return table_[slot];
	table_[slot] = static_cast<int>(lists_.size());
	lists_.push_back(list);
	return table_[slot];
}

void LinkedSets::clear() {
	sets_.clear();
	lists_.clear();
	std::fill(table_.begin(), table_.end(), -1);
	overflowed_ = false;
}

std::size_t LinkedSets::memoryBytes() const {
	std::size_t bytes = capacityBytes(sets_) + capacityBytes(lists_) + capacityBytes(table_) + capacityBytes(scratch_);
	for (const std::vector<int>& list : lists_) bytes += capacityBytes(list);
	return bytes;
}

}  // namespace dda::msc
