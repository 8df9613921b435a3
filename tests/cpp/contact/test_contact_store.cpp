// Contact history across steps (contact/Contact): by identity, by a
// neighbouring face when a vertex slides across an edge, and for edge-edge
// contacts whose edges come back with the blocks' roles exchanged.
#include "dda/contact/Contact.hpp"

#include <gtest/gtest.h>

using namespace dda;

namespace {

ConvexPolyhedron unitCube() {
	std::vector<Vector3> points;
	for (int x = 0; x < 2; ++x)
		for (int y = 0; y < 2; ++y)
			for (int z = 0; z < 2; ++z) points.emplace_back(x, y, z);
	return buildConvexPolyhedron(points);
}

// Two faces of the cube that share an edge, and one that shares none with the first.
void faces(const ConvexPolyhedron& cube, int& f, int& neighbour, int& opposite) {
	f = cube.edgeFaces[0][0];
	neighbour = cube.edgeFaces[0][1];
	opposite = -1;
	for (int g = 0; g < static_cast<int>(cube.faces.size()); ++g) {
		bool adjacent = g == f;
		for (const auto& ef : cube.edgeFaces) adjacent = adjacent || (ef[0] == f && ef[1] == g) || (ef[0] == g && ef[1] == f);
		if (!adjacent) opposite = g;
	}
	ASSERT_GE(opposite, 0);
}

ContactHistory lockedHistory() {
	ContactHistory h;
	h.state = ContactState::Locked;
	h.anchorI = Vector3(1, 2, 3);
	h.anchorJ = Vector3(4, 5, 6);
	h.slidingDirection = Vector3(1, 0, 0);
	h.normalForce = 7;
	h.shearForce = Vector3(0, 8, 0);
	return h;
}

}  // namespace

TEST(ContactStore, HistoryFollowsIdentityAndNeighbouringFacesOnly) {
	const ConvexPolyhedron cube = unitCube();
	int f, neighbour, opposite;
	faces(cube, f, neighbour, opposite);
	ContactStore store;
	const SubContact geometry;

	store.beginStep();
	store.add({0, 1, ContactKind::VertexFace, 3, f}, ContactType::VertexFace, geometry, cube, cube).history = lockedHistory();
	store.add({0, 1, ContactKind::VertexFace, 4, f}, ContactType::VertexFace, geometry, cube, cube).history = lockedHistory();
	store.add({0, 1, ContactKind::VertexFace, 5, f}, ContactType::VertexFace, geometry, cube, cube).history = lockedHistory();

	store.beginStep();
	const Contact& same = store.add({0, 1, ContactKind::VertexFace, 3, f}, ContactType::VertexFace, geometry, cube, cube);
	EXPECT_FALSE(same.isNew);
	EXPECT_EQ(same.history.state, ContactState::Locked);
	EXPECT_EQ(same.history.anchorJ, Vector3(4, 5, 6));
	const Contact& slid = store.add({0, 1, ContactKind::VertexFace, 4, neighbour}, ContactType::VertexFace, geometry, cube, cube);
	EXPECT_FALSE(slid.isNew);  // the vertex slid onto the neighbouring face
	EXPECT_EQ(slid.history.state, ContactState::Locked);
	const Contact& jumped = store.add({0, 1, ContactKind::VertexFace, 5, opposite}, ContactType::VertexFace, geometry, cube, cube);
	EXPECT_TRUE(jumped.isNew);  // a face across the block is not a neighbour
	EXPECT_EQ(jumped.history.state, ContactState::Open);
	const Contact& otherBlocks = store.add({0, 2, ContactKind::VertexFace, 3, f}, ContactType::VertexFace, geometry, cube, cube);
	EXPECT_TRUE(otherBlocks.isNew);

	// A history is taken over once only.
	store.beginStep();
	store.add({0, 1, ContactKind::VertexFace, 3, f}, ContactType::VertexFace, geometry, cube, cube);
	const Contact& second = store.add({0, 1, ContactKind::VertexFace, 3, neighbour}, ContactType::VertexFace, geometry, cube, cube);
	EXPECT_TRUE(second.isNew);
}

TEST(ContactStore, EdgeEdgeHistorySurvivesExchangedRoles) {
	const ConvexPolyhedron cube = unitCube();
	ContactStore store;
	const SubContact geometry;
	store.beginStep();
	store.add({2, 5, ContactKind::EdgeEdge, 7, 9}, ContactType::EdgeEdgeCrossing, geometry, cube, cube).history = lockedHistory();
	store.beginStep();
	const Contact& c = store.add({5, 2, ContactKind::EdgeEdge, 9, 7}, ContactType::EdgeEdgeCrossing, geometry, cube, cube);
	ASSERT_FALSE(c.isNew);
	EXPECT_EQ(c.history.state, ContactState::Locked);
	EXPECT_EQ(c.history.anchorI, Vector3(4, 5, 6));  // block 5's anchor is now anchor i
	EXPECT_EQ(c.history.anchorJ, Vector3(1, 2, 3));
	EXPECT_EQ(c.history.slidingDirection, Vector3(-1, 0, 0));
	EXPECT_EQ(c.history.shearForce, Vector3(0, -8, 0));
	EXPECT_EQ(c.history.normalForce, 7);
}

TEST(ContactStore, EntranceFeaturesCarryOneStep) {
	ContactStore store;
	store.beginStep();
	EntranceFeature e;
	e.kind = EntranceFeature::FaceOfB;
	e.feature = 3;
	store.setEntrance(1, 4, e);
	store.beginStep();
	EXPECT_TRUE(store.previousEntrance(1, 4) == e);
	EXPECT_EQ(store.previousEntrance(4, 1).kind, EntranceFeature::None);
	store.beginStep();  // not set again: forgotten
	EXPECT_EQ(store.previousEntrance(1, 4).kind, EntranceFeature::None);
}

// Many contacts (the hash index probes past collisions): each one, added
// again in another order, inherits its own history and no other; a vertex
// that slid onto a face next to two old ones takes the one added first.
TEST(ContactStore, ManyContactsEachInheritTheirOwn) {
	const ConvexPolyhedron cube = unitCube();
	ContactStore store;
	const SubContact geometry;
	std::vector<ContactKey> keys;
	for (int i = 0; i < 40; ++i)
		for (int j = i + 1; j < 40; j += 3)
			for (int v = 0; v < 8; v += 3) keys.push_back({i, j, ContactKind::VertexFace, v, (i + j + v) % 6});
	store.beginStep();
	for (std::size_t k = 0; k < keys.size(); ++k) store.add(keys[k], ContactType::VertexFace, geometry, cube, cube).history.normalForce = static_cast<double>(k);
	store.beginStep();
	for (std::size_t k = keys.size(); k-- > 0;) {
		const Contact& c = store.add(keys[k], ContactType::VertexFace, geometry, cube, cube);
		ASSERT_FALSE(c.isNew);
		EXPECT_EQ(c.history.normalForce, static_cast<double>(k));
	}
	EXPECT_FALSE(store.add({0, 99, ContactKind::VertexFace, 0, 0}, ContactType::VertexFace, geometry, cube, cube).history.normalForce > 0);

	// Faces f and `opposite` are both adjacent to `neighbour`: the one added
	// first is the predecessor, whichever it is.
	int f, neighbour, opposite;
	faces(cube, f, neighbour, opposite);
	for (const bool fFirst : {true, false}) {
		store.clear();
		store.beginStep();
		for (const int face : fFirst ? std::vector<int>{f, opposite} : std::vector<int>{opposite, f})
			store.add({1, 2, ContactKind::VertexFace, 3, face}, ContactType::VertexFace, geometry, cube, cube)
			    .history.normalForce = face == f ? 2 : 1;
		store.beginStep();
		EXPECT_EQ(store.add({1, 2, ContactKind::VertexFace, 3, neighbour}, ContactType::VertexFace, geometry, cube, cube)
		              .history.normalForce, fFirst ? 2 : 1);
	}
}

// Entrances set out of order or twice in a step: the last one set counts,
// and they are saved sorted by pair.
TEST(ContactStore, EntrancesSetOutOfOrderOrTwice) {
	ContactStore store;
	store.beginStep();
	EntranceFeature e1, e2, e3;
	e1.kind = EntranceFeature::FaceOfA;
	e1.feature = 1;
	e2.kind = EntranceFeature::FaceOfB;
	e2.feature = 2;
	e3.kind = EntranceFeature::EdgePair;
	e3.feature = 3;
	e3.other = 4;
	store.setEntrance(5, 9, e1);
	store.setEntrance(2, 7, e2);
	store.setEntrance(5, 9, e3);
	ASSERT_EQ(store.entrances().size(), 2u);
	EXPECT_LT(store.entrances()[0].first, store.entrances()[1].first);
	store.beginStep();
	EXPECT_TRUE(store.previousEntrance(5, 9) == e3);
	EXPECT_TRUE(store.previousEntrance(2, 7) == e2);
	EXPECT_EQ(store.previousEntrance(2, 9).kind, EntranceFeature::None);
}
