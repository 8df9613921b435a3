// Heap accounting for stats()['memory'].
#pragma once

#include <cstddef>
#include <vector>

namespace dda {

// Heap bytes of a vector's storage (its capacity) [bytes].
template <class T>
std::size_t capacityBytes(const std::vector<T>& v) {
	return v.capacity() * sizeof(T);
}

}  // namespace dda
