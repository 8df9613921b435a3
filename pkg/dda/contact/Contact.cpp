#include "Contact.hpp"

#include "dda/core/CapacityBytes.hpp"

#include <algorithm>

namespace dda {

namespace {

std::uint64_t pairKey(int a, int b) {
	return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

// Faces f and g of a shape share an edge.
bool facesAdjacent(const PolyhedronTopology& shape, int f, int g) {
	for (const auto& faces : shape.edgeFaces)
		if ((faces[0] == f && faces[1] == g) || (faces[0] == g && faces[1] == f)) return true;
	return false;
}

// Same blocks, kind and first feature (the second is not compared).
bool sameFeature1(const ContactKey& a, const ContactKey& b) {
	return a.blockI == b.blockI && a.blockJ == b.blockJ && a.kind == b.kind && a.feature1 == b.feature1;
}

// Edges e and g of a shape share a corner.
bool edgesAdjacent(const PolyhedronTopology& shape, int e, int g) {
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

void ContactStore::FlatIndex::reset(std::size_t entries) {
	std::size_t size = 16;
	while (size < 2 * entries) size *= 2;
	slots.assign(size, -1);
	mask = size - 1;
}

void ContactStore::beginStep() {
	previousEdgePoints_.clear();
	for (const Contact& contact : current_)
		if (contact.key.kind == ContactKind::EdgeEdge && contact.geometry.stencil.kind == ContactKind::VertexFace)
			previousEdgePoints_.push_back({pairKey(std::min(contact.key.blockI, contact.key.blockJ),
			                                       std::max(contact.key.blockI, contact.key.blockJ)),
			                               contact.key.blockI,
			                               contact.key.feature1, contact.key.feature2, contact.point});
	std::stable_sort(previousEdgePoints_.begin(), previousEdgePoints_.end(),
	                 [](const EdgePoint& x, const EdgePoint& y) { return x.pair < y.pair; });
	previous_.clear();
	previous_.reserve(current_.size());
	for (const Contact& contact : current_) previous_.push_back({contact.key, contact.history});
	current_.clear();
	const int n = static_cast<int>(previous_.size());
	previousIndex_.reset(previous_.size());
	byFeature1_.reset(previous_.size());
	sameFeature1_.assign(previous_.size(), -1);
	// Exact keys in ascending order (the first of equal keys is kept); partial
	// keys in descending order, each becoming its chain's head, so chains
	// ascend.
	for (int k = 0; k < n; ++k) {
		int& slot = previousIndex_.slots[slotOf(previousIndex_, previous_[k].key, false)];
		if (slot < 0) slot = k;
	}
	for (int k = n - 1; k >= 0; --k) {
		int& slot = byFeature1_.slots[slotOf(byFeature1_, previous_[k].key, true)];
		sameFeature1_[k] = slot;
		slot = k;
	}
	claimed_.assign(previous_.size(), 0);
	if (!entrancesSorted_) normalize(entrances_);
	previousEntrances_.swap(entrances_);
	entrances_.clear();
	entrancesSorted_ = true;
}

std::size_t ContactStore::slotOf(const FlatIndex& index, ContactKey key, bool byFeature1) const {
	if (byFeature1) key.feature2 = -1;
	for (std::size_t h = ContactKeyHash{}(key) & index.mask;; h = (h + 1) & index.mask) {
		const int k = index.slots[h];
		if (k < 0 || (byFeature1 ? sameFeature1(previous_[k].key, key) : previous_[k].key == key)) return h;
	}
}

int ContactStore::previousIndex(const ContactKey& key) const {
	return previousIndex_.slots[slotOf(previousIndex_, key, false)];
}

int ContactStore::firstWithFeature1(const ContactKey& key) const {
	return byFeature1_.slots[slotOf(byFeature1_, key, true)];
}

Contact& ContactStore::add(const ContactKey& key, ContactType pairType, const SubContact& geometry,
                           const PolyhedronTopology& shapeI, const PolyhedronTopology& shapeJ) {
	(void)shapeI;
	Contact& contact = current_.emplace_back();
	fill(contact, key, pairType, geometry, shapeJ);
	return contact;
}

int ContactStore::extend(int count) {
	const int first = static_cast<int>(current_.size());
	current_.resize(current_.size() + static_cast<std::size_t>(std::max(count, 0)));
	return first;
}

void ContactStore::fill(Contact& contact, const ContactKey& key, ContactType pairType, const SubContact& geometry,
                        const PolyhedronTopology& shapeJ) {
	contact.key = key;
	contact.bodyI = key.blockI;  // ContactDetection::storePair sets the bodies of concave blocks' parts
	contact.bodyJ = key.blockJ;
	contact.pairType = pairType;
	contact.geometry = geometry;
	if (previous_.empty()) return;

	int predecessor = -1;
	const int exact = previousIndex(key);
	if (exact >= 0 && !claimed_[exact]) {
		predecessor = exact;
	} else {
		// The same vertex (or first edge) of block i against a neighbour of the
		// old face (or second edge) of block j.
		for (int k = firstWithFeature1(key); k >= 0; k = sameFeature1_[k]) {
			if (claimed_[k]) continue;
			const int oldFeature = previous_[k].key.feature2;
			const bool neighbour = key.kind == ContactKind::VertexFace ? facesAdjacent(shapeJ, oldFeature, key.feature2)
			                                                           : edgesAdjacent(shapeJ, oldFeature, key.feature2);
			if (neighbour) {
				predecessor = k;
				break;
			}
		}
	}
	bool swapped = false;
	if (predecessor < 0 && key.kind == ContactKind::EdgeEdge) {
		// The same two edges with the roles of i and j exchanged (the pair's
		// entrance moved from a face of one block to the crossing edges, or back).
		const int reversed = previousIndex(ContactKey{key.blockJ, key.blockI, key.kind, key.feature2, key.feature1});
		if (reversed >= 0 && !claimed_[reversed]) {
			predecessor = reversed;
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
}

const EntranceFeature& ContactStore::previousEntrance(int a, int b) const {
	static const EntranceFeature none;
	const std::uint64_t key = pairKey(a, b);
	const auto it = std::lower_bound(previousEntrances_.begin(), previousEntrances_.end(), key,
	                                 [](const auto& entry, std::uint64_t k) { return entry.first < k; });
	return it == previousEntrances_.end() || it->first != key ? none : it->second;
}

KeptEdgePoint ContactStore::previousEdgePoint(int a, int b) const {
	const std::uint64_t key = pairKey(std::min(a, b), std::max(a, b));
	const auto it = std::lower_bound(previousEdgePoints_.begin(), previousEdgePoints_.end(), key,
	                                 [](const EdgePoint& entry, std::uint64_t k) { return entry.pair < k; });
	KeptEdgePoint kept;
	if (it == previousEdgePoints_.end() || it->pair != key) return kept;
	kept.onA = it->block == a;
	kept.edge = it->edge;
	kept.otherEdge = it->otherEdge;
	kept.point = it->point;
	return kept;
}

void ContactStore::setEntrance(int a, int b, const EntranceFeature& entrance) {
	const std::uint64_t key = pairKey(a, b);
	if (!entrances_.empty() && key <= entrances_.back().first) entrancesSorted_ = false;
	entrances_.emplace_back(key, entrance);
}

void ContactStore::normalize(std::vector<std::pair<std::uint64_t, EntranceFeature>>& entrances) {
	std::stable_sort(entrances.begin(), entrances.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
	std::size_t kept = 0;
	for (const auto& entry : entrances) {
		if (kept > 0 && entrances[kept - 1].first == entry.first)
			entrances[kept - 1] = entry;  // set again: the last one counts
		else
			entrances[kept++] = entry;
	}
	entrances.resize(kept);
}

const std::vector<std::pair<std::uint64_t, EntranceFeature>>& ContactStore::entrances() const {
	if (!entrancesSorted_) {
		normalize(entrances_);
		entrancesSorted_ = true;
	}
	return entrances_;
}

void ContactStore::restore(std::vector<Contact> contacts,
                           const std::unordered_map<std::uint64_t, EntranceFeature>& entrances) {
	clear();
	current_ = std::move(contacts);
	entrances_.assign(entrances.begin(), entrances.end());
	entrancesSorted_ = false;
}

void ContactStore::clear() {
	current_.clear();
	previous_.clear();
	previousIndex_.reset(0);
	byFeature1_.reset(0);
	sameFeature1_.clear();
	entrances_.clear();
	entrancesSorted_ = true;
	previousEntrances_.clear();
	claimed_.clear();
	previousEdgePoints_.clear();
}

std::size_t ContactStore::memoryBytes() const {
	return capacityBytes(current_) + capacityBytes(previous_) + capacityBytes(claimed_) + capacityBytes(previousEdgePoints_) +
	       capacityBytes(previousIndex_.slots) + capacityBytes(byFeature1_.slots) + capacityBytes(sameFeature1_) +
	       capacityBytes(entrances_) + capacityBytes(previousEntrances_);
}

}  // namespace dda
