// Binary streams for saving and restoring a DDA scene (World::writeState,
// SceneLink::saveState). Values are written in the machine's own byte order
// and IEEE doubles bit for bit, so a restored scene continues exactly where
// it stopped. A saved state is framed (frameState) by a magic string, a format
// version, a byte-order marker, the payload length and an FNV-1a checksum;
// unframeState checks all of them and names what is wrong. Reading never
// trusts a length from the data: every read is bounds-checked, so truncated
// or corrupt input raises StateError instead of reading past the end or
// allocating without limit.
#pragma once

#include "Errors.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace dda {

// Format version of the saved state. Bump it whenever what is written, or the
// meaning of a written value, changes; older states are then refused by name.
inline constexpr std::uint32_t kStateVersion = 5;  // 2: a block's rigid flag; 3: MSC frames, no shell boxes; 4: the energy account; 5: concave blocks' parts

class StateWriter {
public:
	template <class T>
	void pod(const T& value) {
		static_assert(std::is_trivially_copyable_v<T> && !std::is_pointer_v<T>, "raw write of a non-POD");
		bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
	}
	void size(std::size_t n) { pod(static_cast<std::uint64_t>(n)); }
	template <class Derived>
	void matrix(const Eigen::DenseBase<Derived>& m) {
		for (Eigen::Index j = 0; j < m.cols(); ++j)
			for (Eigen::Index i = 0; i < m.rows(); ++i) pod(static_cast<double>(m(i, j)));
	}
	void quaternion(const Eigen::Quaterniond& q) { matrix(q.coeffs()); }
	void string(const std::string& s) {
		size(s.size());
		bytes_.append(s);
	}
	template <class T>
	void podVector(const std::vector<T>& v) {
		size(v.size());
		for (const T& x : v) pod(x);
	}
	template <class Derived>
	void matrixVector(const std::vector<Derived>& v) {
		size(v.size());
		for (const auto& x : v) matrix(x);
	}
	// A section tag: reading checks it, so a stream that lost its place says where.
	void tag(const char (&name)[5]) { bytes_.append(name, 4); }
	const std::string& bytes() const { return bytes_; }

private:
	std::string bytes_;
};

class StateReader {
public:
	explicit StateReader(const std::string& bytes) : data_(bytes.data()), size_(bytes.size()) {}
	template <class T>
	void pod(T& value) {
		static_assert(std::is_trivially_copyable_v<T> && !std::is_pointer_v<T>, "raw read of a non-POD");
		need(sizeof(T), "a value");
		std::memcpy(&value, data_ + pos_, sizeof(T));
		pos_ += sizeof(T);
	}
	template <class T>
	T pod() {
		T value;
		pod(value);
		return value;
	}
	// A count of items that need at least `itemBytes` each: never more than the bytes left.
	std::size_t size(std::size_t itemBytes, const char* what) {
		const std::uint64_t n = pod<std::uint64_t>();
		if (itemBytes > 0 && n > (size_ - pos_) / itemBytes) fail(std::string("the count of ") + what + " is corrupt");
		return static_cast<std::size_t>(n);
	}
	template <class Derived>
	void matrix(Eigen::DenseBase<Derived>& m) {
		for (Eigen::Index j = 0; j < m.cols(); ++j)
			for (Eigen::Index i = 0; i < m.rows(); ++i) m(i, j) = pod<double>();
	}
	void quaternion(Eigen::Quaterniond& q) {
		Eigen::Vector4d c;
		matrix(c);
		q.coeffs() = c;
	}
	void string(std::string& s) {
		const std::size_t n = size(1, "string bytes");
		s.assign(data_ + pos_, n);
		pos_ += n;
	}
	template <class T>
	void podVector(std::vector<T>& v, const char* what) {
		v.resize(size(sizeof(T), what));
		for (T& x : v) pod(x);
	}
	template <class Derived>
	void matrixVector(std::vector<Derived>& v, const char* what) {
		v.resize(size(sizeof(double) * Derived::SizeAtCompileTime, what));
		for (auto& x : v) matrix(x);
	}
	void tag(const char (&name)[5]) {
		need(4, name);
		if (std::memcmp(data_ + pos_, name, 4) != 0) fail(std::string("section '") + name + "' not found where expected");
		pos_ += 4;
	}
	// Whether the next section is `name` (an optional one), without reading.
	bool nextTag(const char (&name)[5]) const { return size_ - pos_ >= 4 && std::memcmp(data_ + pos_, name, 4) == 0; }
	// An index read from the state must lie in [0, count).
	int index(int count, const char* what) {
		const int i = pod<int>();
		if (i < 0 || i >= count) fail(std::string(what) + " " + std::to_string(i) + " out of range [0, " + std::to_string(count) + ")");
		return i;
	}
	bool atEnd() const { return pos_ == size_; }
	[[noreturn]] void fail(const std::string& what) const {
		throw StateError("the saved DDA state is corrupt: " + what + " (at byte " + std::to_string(pos_) + " of " +
		                 std::to_string(size_) + ")");
	}

private:
	void need(std::size_t n, const char* what) const {
		if (n > size_ - pos_)
			throw StateError(std::string("the saved DDA state is truncated: ") + what + " needs " + std::to_string(n) +
			                 " bytes at byte " + std::to_string(pos_) + ", only " + std::to_string(size_ - pos_) + " left");
	}
	const char* data_;
	std::size_t size_;
	std::size_t pos_ = 0;
};

// Frame: "YADE-DDA-STATE\0\0" (16 bytes), version (u32), byte-order marker
// 0x01020304 (u32), payload length (u64), FNV-1a 64 checksum of the payload (u64).
inline constexpr std::array<char, 16> kStateMagic = {'Y', 'A', 'D', 'E', '-', 'D', 'D', 'A',
                                                     '-', 'S', 'T', 'A', 'T', 'E', 0, 0};
inline constexpr std::size_t kStateHeaderBytes = 16 + 4 + 4 + 8 + 8;

inline std::uint64_t stateChecksum(const char* data, std::size_t n) {
	std::uint64_t h = 0xcbf29ce484222325ull;
	for (std::size_t i = 0; i < n; ++i) {
		h ^= static_cast<unsigned char>(data[i]);
		h *= 0x100000001b3ull;
	}
	return h;
}

inline std::string frameState(const std::string& payload) {
	std::string out(kStateMagic.data(), kStateMagic.size());
	const std::uint32_t version = kStateVersion, order = 0x01020304u;
	const std::uint64_t length = payload.size(), checksum = stateChecksum(payload.data(), payload.size());
	out.append(reinterpret_cast<const char*>(&version), 4);
	out.append(reinterpret_cast<const char*>(&order), 4);
	out.append(reinterpret_cast<const char*>(&length), 8);
	out.append(reinterpret_cast<const char*>(&checksum), 8);
	out.append(payload);
	return out;
}

// The payload of a framed state; StateError naming the problem otherwise.
inline std::string unframeState(const std::string& blob) {
	if (blob.size() < kStateHeaderBytes || std::memcmp(blob.data(), kStateMagic.data(), kStateMagic.size()) != 0)
		throw StateError("not a saved DDA state (" + std::to_string(blob.size()) +
		                 " bytes without the YADE-DDA-STATE header)");
	std::uint32_t version, order;
	std::uint64_t length, checksum;
	std::memcpy(&version, blob.data() + 16, 4);
	std::memcpy(&order, blob.data() + 20, 4);
	std::memcpy(&length, blob.data() + 24, 8);
	std::memcpy(&checksum, blob.data() + 32, 8);
	if (order != 0x01020304u) throw StateError("the saved DDA state was written on a machine of the other byte order");
	if (version != kStateVersion)
		throw StateError("the saved DDA state has format version " + std::to_string(version) +
		                 "; this build of yade_dda reads version " + std::to_string(kStateVersion));
	const std::size_t have = blob.size() - kStateHeaderBytes;
	if (length != have)
		throw StateError("the saved DDA state is truncated or padded: its header announces " + std::to_string(length) +
		                 " bytes of state, " + std::to_string(have) + " are present");
	if (stateChecksum(blob.data() + kStateHeaderBytes, have) != checksum)
		throw StateError("the saved DDA state is corrupt: its checksum does not match its " + std::to_string(have) + " bytes");
	return blob.substr(kStateHeaderBytes);
}

}  // namespace dda
