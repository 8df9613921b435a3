#include "ColliderFactory.hpp"

#include "MSCCollider.hpp"

#include <array>

namespace dda {

namespace {

template <class T>
std::unique_ptr<Collider> make() {
	return std::make_unique<T>();
}

using Maker = std::unique_ptr<Collider> (*)();
const std::array<Maker, 4> kMakers = {make<DESSCollider>, make<NBSCollider>, make<AllPairsCollider>, make<MSCCollider>};

}  // namespace

const std::vector<std::string>& colliderNames() {
	static const std::vector<std::string> names = [] {
		std::vector<std::string> out;
		for (Maker maker : kMakers) out.push_back(maker()->name());
		return out;
	}();
	return names;
}

std::string colliderList() {
	std::string out;
	for (const std::string& name : colliderNames()) out += (out.empty() ? "" : ", ") + name;
	return out;
}

std::unique_ptr<Collider> makeCollider(const std::string& name) {
	const std::vector<std::string>& names = colliderNames();
	for (std::size_t k = 0; k < names.size(); ++k)
		if (names[k] == name) return kMakers[k]();
	return nullptr;
}

}  // namespace dda
