#include "Contact.hpp"

#include <algorithm>

namespace dda {

namespace {

std::uint64_t pairKey(int a, int b) {
	return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

// Faces f and g of a shape share an edge.
bool facesAdjacent(const ConvexPolyhedron& shape, int f, int g) {
	for (const auto& faces : shape.edgeFaces)
		if ((faces[0] == f && faces[1] == g) || (faces[0] == g && faces[1] == f)) return true;
	return false;
}

// Edges e and g of a shape share a corner.
bool edgesAdjacent(const ConvexPolyhedron& shape, int e, int g) {
	const auto& a = shape.edges[e];
	const auto& b = shape.edges[g];
	return a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
}

}  // namespace

const char* contactStateName(ContactState state) {
	switch (state) {
		case ContactState::Open: return "open";
		case ContactState::Sliding: return "sliding";
		case ContactState::Locked: return "locked";
	}
	return "?";
}

void ContactStore::beginStep() {
	previous_.clear();
	previous_.reserve(current_.size());
	for (const Contact& contact : current_) previous_.push_back({contact.key, contact.history});
	current_.clear();
	previousIndex_.clear();
	byFeature1_.clear();
	for (int k = 0; k < static_cast<int>(previous_.size()); ++k) {
		ContactKey partial = previous_[k].key;
		previousIndex_.emplace(partial, k);
		partial.feature2 = -1;
		byFeature1_[partial].push_back(k);
	}
	claimed_.assign(previous_.size(), 0);
	previousEntrances_.swap(entrances_);
	entrances_.clear();
}

Contact& ContactStore::add(const ContactKey& key, ContactType pairType, const SubContact& geometry,
                           const ConvexPolyhedron& shapeI, const ConvexPolyhedron& shapeJ) {
	(void)shapeI;
	Contact contact;
	contact.key = key;
	contact.pairType = pairType;
	contact.geometry = geometry;

	int predecessor = -1;
	const auto exact = previousIndex_.find(key);
	if (exact != previousIndex_.end() && !claimed_[exact->second]) {
		predecessor = exact->second;
	} else {
		// The same vertex (or first edge) of block i against a neighbour of the
		// old face (or second edge) of block j.
		ContactKey partial = key;
		partial.feature2 = -1;
		const auto candidates = byFeature1_.find(partial);
		if (candidates != byFeature1_.end()) {
			for (int k : candidates->second) {
				if (claimed_[k]) continue;
				const int oldFeature = previous_[k].key.feature2;
				const bool neighbour = key.kind == ContactKind::VertexFace
				                           ? facesAdjacent(shapeJ, oldFeature, key.feature2)
				                           : edgesAdjacent(shapeJ, oldFeature, key.feature2);
				if (neighbour) {
					predecessor = k;
					break;
				}
			}
		}
	}
	bool swapped = false;
	if (predecessor < 0 && key.kind == ContactKind::EdgeEdge) {
		// The same two edges with the roles of i and j exchanged (the pair's
		// entrance moved from a face of one block to the crossing edges, or back).
		const auto reversed = previousIndex_.find(ContactKey{key.blockJ, key.blockI, key.kind, key.feature2, key.feature1});
		if (reversed != previousIndex_.end() && !claimed_[reversed->second]) {
			predecessor = reversed->second;
			swapped = true;
		}
	}
	if (predecessor >= 0) {
		claimed_[predecessor] = 1;
		contact.history = previous_[predecessor].history;
		contact.isNew = false;
		if (swapped) {
			ContactHistory& h = contact.history;
			std::swap(h.anchorI, h.anchorJ);
			h.slidingDirection = -h.slidingDirection;
			h.shearForce = -h.shearForce;
		}
	}
	current_.push_back(contact);
	return current_.back();
}

const EntranceFeature& ContactStore::previousEntrance(int a, int b) const {
	static const EntranceFeature none;
	const auto it = previousEntrances_.find(pairKey(a, b));
	return it == previousEntrances_.end() ? none : it->second;
}

void ContactStore::setEntrance(int a, int b, const EntranceFeature& entrance) {
	entrances_[pairKey(a, b)] = entrance;
}

void ContactStore::restore(std::vector<Contact> contacts,
                           std::unordered_map<std::uint64_t, EntranceFeature> entrances) {
	clear();
	current_ = std::move(contacts);
	entrances_ = std::move(entrances);
}

void ContactStore::clear() {
	current_.clear();
	previous_.clear();
	previousIndex_.clear();
	byFeature1_.clear();
	entrances_.clear();
	previousEntrances_.clear();
	claimed_.clear();
}

namespace {
template <class Map>
std::size_t mapBytes(const Map& map) {
	return map.bucket_count() * sizeof(void*) +
	       map.size() * (sizeof(void*) + sizeof(typename Map::value_type) + sizeof(std::size_t) + 16);
}
}  // namespace

std::size_t ContactStore::memoryBytes() const {
	std::size_t bytes = current_.capacity() * sizeof(Contact) + previous_.capacity() * sizeof(PreviousContact) +
	                    claimed_.capacity() +
	                    mapBytes(previousIndex_) + mapBytes(byFeature1_) + mapBytes(entrances_) +
	                    mapBytes(previousEntrances_);
	for (const auto& entry : byFeature1_) bytes += entry.second.capacity() * sizeof(int);
	return bytes;
}

}  // namespace dda
