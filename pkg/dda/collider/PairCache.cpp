#include "PairCache.hpp"

namespace dda {

bool PairCache::tooManyMovers(int blocks) const {
	return static_cast<double>(movers_.size()) > kVerletPartialFactor * std::log2(std::max(2, blocks));
}

std::size_t PairCache::memoryBytes() const {
	return capacityBytes(searchBoxes_) + capacityBytes(cached_) + capacityBytes(kept_) + capacityBytes(searchedFixed_) +
	       capacityBytes(moved_) + capacityBytes(movers_);
}

}  // namespace dda
