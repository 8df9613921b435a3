// A DDA sub-contact between two blocks and the history it carries from step
// to step (open/sliding/locked state, shear-spring anchors, sliding direction).
//
// Identity. A sub-contact is known by its blocks and features: (block i,
// block j, kind, feature of i, feature of j), where i owns the vertex
// (vertex-face) or the first edge (edge-edge) and j owns the entrance face or
// the second edge. The next step's sub-contact with the same identity takes
// over its history. When a vertex slides from a face onto a neighbouring face
// of the same block (or an edge-edge contact moves to an edge sharing a corner
// with the old one) the identity changes; ContactStore::add then looks for
// that neighbour, so a sliding contact keeps sliding and a locked contact
// keeps its shear spring. An edge-edge contact whose two edges come back with
// the roles of i and j exchanged keeps its history too (anchors swapped,
// directions reversed).
#pragma once

#include "PairDetection.hpp"

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace dda {

enum class ContactState : std::uint8_t { Open, Sliding, Locked };
const char* contactStateName(ContactState state);  // "open", "sliding", "locked"

struct ContactKey {
	int blockI = -1, blockJ = -1;
	ContactKind kind = ContactKind::VertexFace;
	int feature1 = -1, feature2 = -1;
	bool operator==(const ContactKey& o) const {
		return blockI == o.blockI && blockJ == o.blockJ && kind == o.kind && feature1 == o.feature1 &&
		       feature2 == o.feature2;
	}
};
struct ContactKeyHash {
	std::size_t operator()(const ContactKey& k) const {
		std::uint64_t h = static_cast<std::uint64_t>(k.blockI) * 0x9E3779B97F4A7C15ull;
		h ^= static_cast<std::uint64_t>(k.blockJ) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
		h ^= static_cast<std::uint64_t>(k.feature1) * 31 + static_cast<std::uint64_t>(k.feature2) * 1031 +
		     static_cast<std::uint64_t>(k.kind) + (h << 6) + (h >> 2);
		return static_cast<std::size_t>(h);
	}
};

// What a sub-contact carries into the next step. Locked or sliding is the
// regime of its tangential spring (ContactEquations.hpp): within Coulomb's
// limit, or at it.
struct ContactHistory {
	ContactState state = ContactState::Open;
	// Closed: the tangential spring joins these two material points, one of
	// block i and one of block j [m], moved with their blocks every step; their
	// separation in the tangent plane is the spring's stretch.
	Vector3 anchorI = Vector3::Zero(), anchorJ = Vector3::Zero();
	// Sliding: unit direction of the spring's stretch (block i's slip relative
	// to block j), along which friction resists.
	Vector3 slidingDirection = Vector3::Zero();
	double normalForce = 0;  // [N], compressive > 0 (tension < 0 only while bonded); feeds friction
	// A bonded joint (closed when the scene started, both blocks with bond
	// strength) until tension or shear breaks it; a broken bond never heals.
	bool bonded = false;
	Vector3 shearForce = Vector3::Zero();  // force on block i in the tangent plane [N]
};

struct Contact {
	ContactKey key;
	// The blocks whose unknowns the sub-contact joins: the key's blocks, or
	// for a part of a concave block its body (Block::body). The key keeps the
	// parts: their features and the contact's history belong to them.
	int bodyI = -1, bodyJ = -1;
	ContactType pairType = ContactType::VertexFace;  // structural type of its pair
	SubContact geometry;      // at the start of the step
	ContactHistory history;   // state at the end of the last accepted step
	ContactHistory trial;     // state during this step's open-close iteration
	// Mechanics at the start of the step (ContactEquations.hpp).
	LinearizedDistance normal;   // gap d0 and its gradients e_i, e_j
	double normalStiffness = 0;  // [N/m]
	double shearStiffness = 0;   // [N/m]
	double frictionTangent = 0;  // tan(friction angle) [-], times staticFriction
	// Static friction (IntegratorSettings::staticFrictionExcess): 1 + excess
	// while a contact that ended the last step locked has not slipped in a
	// converged pass of this step, else 1.
	double staticFriction = 1;
	double area = 0;             // share of its pair's contact area [m^2]; 0 when the pair has no bond strength (only bonds use it)
	double cohesionForce = 0;    // bond's shear strength beyond friction [N]
	double tensileForce = 0;     // bond's tensile strength [N]
	bool isNew = true;           // no history was found
	// The time scheme's weights (IntegratorSettings::newmarkGamma = gamma;
	// ContactEquations.hpp): the step's equations carry the normal spring
	// times springWeight = (2 gamma - 1) / gamma, its secant (energy-
	// conserving) force times secantWeight = 2 (1 - gamma) / gamma and the
	// tangential spring times 1 / gamma; the physical force is gamma times
	// the equations'. Shi's scheme: 1, 0 and gamma = 1.
	double springWeight = 1, secantWeight = 0, gamma = 1;
	// Within a step (ContactEquations.hpp): the tangential stretch s [m] at
	// the last trial solution and whether it is past the limit (slipping);
	// the limit L [N] of the tangential spring, fixed while the step's energy
	// is minimised and updated from the normal force between such passes,
	// and its last change [N]; open <-> closed changes of the iteration.
	Vector3 stretch = Vector3::Zero();
	double trialGap = 0;  // linearised gap at the last trial solution [m]
	bool slipping = false;
	double slipLimit = 0;
	double limitChange = 0;
	int openCloseChanges = 0;
	// Block i's contact point at the end of the step [m] (for reports).
	Vector3 point = Vector3::Zero();
};

// The contacts of the current step and their predecessors.
class ContactStore {
public:
	// Moves the current contacts into the history pool, ready for the next
	// detection (call once per step before adding the new contacts).
	void beginStep();
	// Adds a detected sub-contact, taking over the history of its predecessor
	// (same identity, else a neighbour as described above). `shapeI`/`shapeJ`
	// give the topology for the neighbour search.
	Contact& add(const ContactKey& key, ContactType pairType, const SubContact& geometry,
	             const PolyhedronTopology& shapeI, const PolyhedronTopology& shapeJ);
	// The same in two parts, for adding many pairs' sub-contacts on several
	// threads: extend appends `count` default contacts (returns the index of
	// the first), fill makes one of them the detected sub-contact as add
	// would. A sub-contact's predecessor is one of its own block pair's
	// previous contacts, so fill calls for different block pairs touch
	// different entries and may run at once; those of one pair must run in
	// the order add would have been called (the first to ask claims).
	int extend(int count);
	void fill(Contact& contact, const ContactKey& key, ContactType pairType, const SubContact& geometry,
	          const PolyhedronTopology& shapeJ);
	std::vector<Contact>& contacts() { return current_; }
	const std::vector<Contact>& contacts() const { return current_; }

	// Entrance features of block pairs (a < b) from the last detection.
	const EntranceFeature& previousEntrance(int a, int b) const;
	void setEntrance(int a, int b, const EntranceFeature& entrance);
	// The near-parallel edge contact of blocks a and b of the last step (an
	// edge-edge key with a vertex-face stencil), onA when its point lies on
	// an edge of block a; edge = -1 when the pair had none. Built from the
	// contacts themselves, so a loaded state gives the same.
	KeptEdgePoint previousEdgePoint(int a, int b) const;

	void clear();
	// Heap bytes held: the capacities of the contact arrays, the indexes of
	// the previous contacts and the entrance lists [bytes].
	std::size_t memoryBytes() const;

	// Saving (solver/WorldState.cpp): the current contacts and entrance
	// features are all a store carries into the next step. Entrances come
	// sorted by pair key, one per pair.
	const std::vector<std::pair<std::uint64_t, EntranceFeature>>& entrances() const;
	void restore(std::vector<Contact> contacts, const std::unordered_map<std::uint64_t, EntranceFeature>& entrances);

private:
	// An open-addressing hash index of previous_ (linear probing, a power-of-two
	// table of indices, -1 empty): no allocation per entry, unlike a node-based
	// map, and rebuilt in place every step.
	struct FlatIndex {
		std::vector<int> slots;
		std::size_t mask = 0;
		void reset(std::size_t entries);
	};
	// The slot of `index` for key (byFeature1: for its blocks, kind and
	// feature1): the one holding a matching previous contact, else the empty
	// slot where it would go.
	std::size_t slotOf(const FlatIndex& index, ContactKey key, bool byFeature1) const;
	// Index into previous_ of the contact with this key, or -1.
	int previousIndex(const ContactKey& key) const;
	// The first previous contact with key's blocks, kind and feature1, or -1.
	int firstWithFeature1(const ContactKey& key) const;
	// Sorts entrances by key, keeping the last one set per key.
	static void normalize(std::vector<std::pair<std::uint64_t, EntranceFeature>>& entrances);

	std::vector<Contact> current_;
	// The last step's contacts as add() reads them: identity and history
	// only (144 of a Contact's 800 bytes).
	struct PreviousContact {
		ContactKey key;
		ContactHistory history;
	};
	std::vector<PreviousContact> previous_;
	// previous_ by key (the first of equal keys), and by (blocks, kind,
	// feature of i), feature2 = -1: the first such contact, the others
	// following by sameFeature1_ in ascending order (-1 ends the chain).
	FlatIndex previousIndex_, byFeature1_;
	std::vector<int> sameFeature1_;
	// Entrance features by pair key: this step's as set (normalized when
	// read), the last step's sorted.
	mutable std::vector<std::pair<std::uint64_t, EntranceFeature>> entrances_;
	mutable bool entrancesSorted_ = true;
	std::vector<std::pair<std::uint64_t, EntranceFeature>> previousEntrances_;
	std::vector<char> claimed_;  // previous contacts already inherited this step
	// The last step's near-parallel edge contacts by pair key (the first of
	// a pair's in contact order): the block owning the point's edge, the two
	// edges and the point at the end of the step.
	struct EdgePoint {
		std::uint64_t pair;
		int block, edge, otherEdge;
		Vector3 point;
	};
	std::vector<EdgePoint> previousEdgePoints_;
};

}  // namespace dda
