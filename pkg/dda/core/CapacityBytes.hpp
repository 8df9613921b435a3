// Heap accounting for stats()['memory'], and the growth of arrays kept from
// call to call at their largest size.
#pragma once

#include <cstddef>
#include <vector>

namespace dda {

// Heap bytes of a vector's storage (its capacity) [bytes].
template <class T>
std::size_t capacityBytes(const std::vector<T>& v) {
	return v.capacity() * sizeof(T);
}

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

}  // namespace dda
