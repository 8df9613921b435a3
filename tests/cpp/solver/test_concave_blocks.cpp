// Concave blocks (World::addConcaveBlock): convex parts sharing one set of
// unknowns. Oracles: closed-form mass properties of an L and the same L cut
// another way; exact free fall (the parts never touch each other); a cube
// dropped into the L's inner corner rests on the right face with its weight;
// every collider's contacts equal AllPairs' on random scenes of concave and
// convex blocks (seed printed); the energy account; save and load bitwise;
// refusals of bad parts.
#include "TestScenes.hpp"
#include "dda/collider/MSCCollider.hpp"
#include "dda/collider/ColliderFactory.hpp"
#include "dda/core/StateStream.hpp"
#include "dda/geometry/ConvexParts.hpp"
#include "dda/geometry/MassProperties.hpp"

#include <gtest/gtest.h>

#include <set>
#include <tuple>

namespace dda::testing {
namespace {

// The L of three unit cubes at `origin`: (0,0), (1,0) and (0,1) in x, y; 1 m thick.
std::vector<std::vector<Vector3>> threeCubeL(const Vector3& origin, const Matrix3& R = Matrix3::Identity()) {
	std::vector<std::vector<Vector3>> parts;
	for (const Vector3 offset : {Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(0, 1, 0)}) {
		std::vector<Vector3> corners = boxPoints(offset, offset + Vector3(1, 1, 1));
		for (Vector3& x : corners) x = origin + R * x;
		parts.push_back(corners);
	}
	return parts;
}

// The same L as a 2 x 1 slab and a cube on its side (a partly shared face).
std::vector<std::vector<Vector3>> twoBoxL(const Vector3& origin) {
	std::vector<Vector3> slab = boxPoints(Vector3(0, 0, 0), Vector3(2, 1, 1));
	std::vector<Vector3> cube = boxPoints(Vector3(0, 1, 0), Vector3(1, 2, 1));
	for (Vector3& x : slab) x += origin;
	for (Vector3& x : cube) x += origin;
	return {slab, cube};
}

TEST(ConcaveBlocks, LShapeMassPropertiesAreExactForEitherSplit) {
	Material rock;
	World world;
	const int three = world.addConcaveBlock(threeCubeL(Vector3(0, 0, 0)), rock, false);
	const int two = world.addConcaveBlock(twoBoxL(Vector3(0, 0, 0)), rock, false);
	// Closed form: three unit cubes, centres (0.5, 0.5, 0.5), (1.5, 0.5, 0.5), (0.5, 1.5, 0.5).
	const Vector3 c(2.5 / 3, 2.5 / 3, 0.5);
	Matrix3 J = Matrix3::Zero();
	for (const Vector3 centre : {Vector3(0.5, 0.5, 0.5), Vector3(1.5, 0.5, 0.5), Vector3(0.5, 1.5, 0.5)})
		J += Matrix3::Identity() / 12 + (centre - c) * (centre - c).transpose();
	for (int b : {three, two}) {
		const Block& block = world.block(b);
		EXPECT_NEAR(block.volume, 3, 1e-14);
		EXPECT_NEAR(block.mass, 3 * rock.density, 1e-10);
		EXPECT_LT((block.centroid - c).norm(), 1e-14);
		EXPECT_LT((block.secondMoment - J).norm(), 1e-14) << block.secondMoment;
	}
	EXPECT_EQ(world.block(three).partCount, 3);
	EXPECT_EQ(world.block(two).partCount, 2);
	EXPECT_EQ(world.block(three + 1).body, three);
	EXPECT_EQ(world.block(two + 1).body, two);
	EXPECT_EQ(world.bodyOf(three + 2), three);
	EXPECT_EQ(world.block(three + 2).mass, 0);
}

TEST(ConcaveBlocks, FreeFallAndSpinAreExactAndThePartsNeverTouch) {
	for (const bool rigid : {true, false}) {
		World world;
		Material rock{2600, 1e9, 0.25};
		const Matrix3 turn = Eigen::AngleAxisd(0.4, Vector3(1, 2, 3).normalized()).toRotationMatrix();
		const int b = world.addConcaveBlock(threeCubeL(Vector3(0, 0, 10), turn), rock, false, rigid);
		const Vector3 v0(1.5, -0.5, 4.0), w0 = rigid ? Vector3(0.3, -1.2, 2.0) : Vector3::Zero(), g(0, 0, -9.81);
		world.setVelocity(b, v0, w0);
		std::vector<Block> start = blocksOf(world);
		IntegratorSettings settings;
		settings.gravity = g;
		settings.maxDisplacement = 1e9;
		settings.maxTimeStep = 0.01;
		double t = 0;
		for (int i = 0; i < 50; ++i) {
			t += world.step(settings);
			EXPECT_EQ(world.lastStep().contacts, 0) << "step " << i;
			EXPECT_EQ(world.lastStep().movingBlocks, 1);
			EXPECT_EQ(world.lastStep().unknowns, rigid ? 6 : 12);
		}
		const Block& end = world.block(b);
		const Vector3 expected = start[b].centroid + v0 * t + 0.5 * g * t * t;
		EXPECT_LT((end.centroid - expected).norm(), 1e-12 * expected.norm());
		const Matrix3 R = rigid ? Matrix3(Eigen::AngleAxisd(w0.norm() * t, w0.normalized()).toRotationMatrix())
		                        : Matrix3::Identity();
		for (int p = 0; p < 3; ++p)
			for (std::size_t k = 0; k < end.vertices.size(); ++k)
				EXPECT_LT((world.block(b + p).vertices[k] - (end.centroid + R * (start[b + p].vertices[k] -
				                                                                 start[b].centroid))).norm(), 1e-10)
				    << "part " << p << " corner " << k;
	}
}

// A fixed floor, the L standing on it (its inner corner open upwards: the
// cube of the L at (1, 0) is its foot, (0, 0) and (0, 1) make a wall two
// cubes high, turned into the x-z plane) and a 0.5 m cube dropped into the
// inner corner, 1 mm off the wall.
World cornerScene(std::unique_ptr<Collider> collider) {
	World world;
	Material rock{2600, 1e9, 0.25};
	rock.frictionAngle = 0.5;
	const Matrix3 I = Matrix3::Identity();
	world.addBlock(orientedBox(Vector3(1, 0.5, -0.5), Vector3(3, 2, 0.5), I), rock, true);
	// L in the x-z plane: parts [0,1]x[0,1]x[0,1], [1,2]x[0,1]x[0,1] (the foot), [0,1]x[0,1]x[1,2] (the wall).
	std::vector<std::vector<Vector3>> parts;
	for (const Vector3 lo : {Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(0, 0, 1)}) parts.push_back(boxPoints(lo, lo + Vector3(1, 1, 1)));
	world.addConcaveBlock(parts, rock, false);
	world.addBlock(orientedBox(Vector3(1.251, 0.5, 1.3), Vector3(0.25, 0.25, 0.25), I), rock, false);
	world.setCollider(std::move(collider));
	return world;
}

// The z force [N] on block `body` from its closed contacts with block `other` (any part of either).
double verticalForce(const World& world, int body, int other) {
	double fz = 0;
	for (const Contact& c : world.contacts()) {
		if (c.history.state == ContactState::Open) continue;
		const Vector3 onI = c.geometry.normal * c.history.normalForce + c.history.shearForce;
		if (c.bodyI == body && c.bodyJ == other) fz += onI.z();
		if (c.bodyJ == body && c.bodyI == other) fz -= onI.z();
	}
	return fz;
}

// The cube comes to rest on the foot (the L's inner horizontal face), not on
// the wall 1 mm beside it nor on the faces the parts share. The oracle is
// the momentum balance over the last second (the deformable blocks still
// ring): the impulse of the contact forces on the cube equals its weight's
// plus its change of momentum, and likewise for the floor's on L and cube.
TEST(ConcaveBlocks, ACubeDroppedIntoTheInnerCornerRestsOnTheFootWithItsWeight) {
	World world = cornerScene(std::make_unique<MSCCollider>());
	IntegratorSettings settings;
	settings.gravity = Vector3(0, 0, -9.81);
	settings.maxTimeStep = 2e-3;
	settings.threads = 1;
	for (int i = 0; i < 500; ++i) world.step(settings);
	const int L = 1, cube = 4;
	const double mL = world.block(L).mass, mc = world.block(cube).mass, g = 9.81;
	const double vL0 = world.block(L).velocity.z(), vc0 = world.block(cube).velocity.z();
	double impulseOnCube = 0, impulseOfFloor = 0, T = 0;
	for (int i = 0; i < 500; ++i) {
		const double dt = world.step(settings);
		T += dt;
		impulseOnCube += dt * verticalForce(world, cube, L);
		impulseOfFloor += dt * (verticalForce(world, L, 0) + verticalForce(world, cube, 0));
		for (const Contact& c : world.contacts()) {
			ASSERT_NE(c.bodyI, c.bodyJ);
			if (c.history.state == ContactState::Open || std::set<int>{c.bodyI, c.bodyJ} != std::set<int>{L, cube})
				continue;
			// Only the foot (part 2) carries the cube, on its top face.
			ASSERT_EQ(std::min(c.key.blockI, c.key.blockJ), 2) << "step " << i;
			ASSERT_NEAR(std::abs(c.geometry.normal.z()), 1, 1e-6);
		}
	}
	const double vL1 = world.block(L).velocity.z(), vc1 = world.block(cube).velocity.z();
	EXPECT_NEAR(impulseOnCube, mc * g * T + mc * (vc1 - vc0), 1e-3 * mc * g * T);
	EXPECT_NEAR(impulseOfFloor, (mL + mc) * g * T + mL * (vL1 - vL0) + mc * (vc1 - vc0), 1e-3 * (mL + mc) * g * T);
	const Block& c = world.block(cube);
	EXPECT_NEAR(c.centroid.z(), 1.25, 2e-4);          // on the foot's top face, z = 1
	EXPECT_GT(c.centroid.x() - 0.25, 1.0);            // off the wall, x = 1
	EXPECT_LT(std::abs(c.centroid.y() - 0.5), 1e-9);  // the scene is symmetric in y
}

using ContactKeys = std::set<std::tuple<int, int, int, int, int>>;
ContactKeys keysOf(const World& world) {
	ContactKeys keys;
	for (const Contact& c : world.contacts())
		keys.emplace(c.key.blockI, c.key.blockJ, static_cast<int>(c.key.kind), c.key.feature1, c.key.feature2);
	return keys;
}

// Random L's and T's (three or four unit cubes, turned) and cubes dropped on a
// floor (TestScenes.hpp's randomConcavePile, E = 1e8 Pa): every strategy's
// contacts equal AllPairs' at every step, no contact joins two parts of one
// block, and the account balances.
World randomConcaveScene(unsigned seed, const std::string& collider) {
	return randomConcavePile(seed, true, 1e8, false, collider);
}

TEST(ConcaveBlocks, EveryColliderFindsAllPairsContactsAndTheAccountBalances) {
	for (const unsigned seed : {3u, 17u}) {
		SCOPED_TRACE("seed " + std::to_string(seed));
		std::vector<World> worlds;
		const std::vector<std::string> names = {"AllPairs", "DESS", "NBS", "MSC"};
		for (const std::string& name : names) worlds.push_back(randomConcaveScene(seed, name));
		const IntegratorSettings settings = concavePileSettings();
		// The account's conserved sum (IntegratorSettings.hpp): its terms less
		// the loads' work and what contact detection added (contactChanges).
		auto account = [](const EnergyAccount& e) {
			return e.kinetic + e.gravity + e.strain + e.contact + e.friction + e.damping - e.loads - e.contactChanges;
		};
		EnergyAccount first;
		std::set<std::pair<int, int>> touched, touchedConcave;  // body pairs closed at some step
		for (int step = 0; step < 800; ++step) {
			for (World& w : worlds) w.step(settings);
			if (step == 0) first = worlds[0].energy();
			const ContactKeys reference = keysOf(worlds[0]);
			for (std::size_t k = 1; k < worlds.size(); ++k)
				ASSERT_TRUE(keysOf(worlds[k]) == reference) << names[k] << " differs at step " << step;
			for (const Contact& c : worlds[0].contacts()) {
				ASSERT_NE(c.bodyI, c.bodyJ);
				if (c.history.state == ContactState::Open) continue;
				const std::pair<int, int> pair(std::min(c.bodyI, c.bodyJ), std::max(c.bodyI, c.bodyJ));
				touched.insert(pair);
				if (worlds[0].block(pair.first).partCount > 1 && worlds[0].block(pair.second).partCount > 1)
					touchedConcave.insert(pair);
			}
		}
		std::cout << "seed " << seed << ": " << touched.size() << " body pairs touched, " << touchedConcave.size()
		          << " of two concave blocks\n";
		EXPECT_GE(touched.size(), 12u);  // every block landed on the floor or another
		EXPECT_GE(touchedConcave.size(), 1u);
		const EnergyAccount last = worlds[0].energy();
		const double scale = std::abs(last.gravity - first.gravity);
		EXPECT_LT(std::abs(account(last) - account(first)), 1e-3 * scale)
		    << "friction " << last.friction << " damping " << last.damping << " contact changes "
		    << last.contactChanges - first.contactChanges;
	}
}

TEST(ConcaveBlocks, RestoredWorldWithConcaveBlocksContinuesBitwise) {
	World original = randomConcaveScene(5, "MSC");
	IntegratorSettings settings;
	settings.gravity = Vector3(0, 0, -9.81);
	settings.maxTimeStep = 2e-3;
	settings.threads = 1;
	for (int k = 0; k < 150; ++k) original.step(settings);
	StateWriter out;
	original.writeState(out);
	World restored;
	StateReader in(out.bytes());
	restored.readState(in);
	for (int k = 0; k < 100; ++k) {
		original.step(settings);
		restored.step(settings);
	}
	ASSERT_EQ(original.blockCount(), restored.blockCount());
	for (int b = 0; b < original.blockCount(); ++b) {
		EXPECT_EQ(original.block(b).vertices, restored.block(b).vertices) << "block " << b;
		EXPECT_EQ(original.block(b).velocity, restored.block(b).velocity) << "block " << b;
		EXPECT_EQ(original.block(b).body, restored.block(b).body);
		EXPECT_EQ(original.block(b).partCount, restored.block(b).partCount);
	}
}

// conformParts: staggered bricks and random stacks of boxes whose faces
// overlap only in part (seeded) become parts that makeConcaveBlock accepts,
// with the union's volume, centroid and second moments unchanged.
TEST(ConcaveBlocks, ConformedPartsAreAcceptedAndKeepTheUnionsMassProperties) {
	auto wholeOf = [](const std::vector<std::vector<Vector3>>& parts) {
		std::vector<MassProperties> each;
		for (const auto& corners : parts) {
			const ConvexPolyhedron p = buildConvexPolyhedron(corners);
			each.push_back(computeMassProperties(p.vertices, p.faces));
		}
		return unionMassProperties(each);
	};
	std::vector<std::vector<std::vector<Vector3>>> cases;
	cases.push_back({boxPoints(Vector3(0, 0, 0), Vector3(2, 1, 1)), boxPoints(Vector3(1, 0, 1), Vector3(3, 1, 2))});
	cases.push_back({boxPoints(Vector3(0, 0, 0), Vector3(2, 2, 1)), boxPoints(Vector3(1, 1, 1), Vector3(3, 3, 2))});
	const unsigned seed = 41;
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> unit(0, 1);
	for (int trial = 0; trial < 6; ++trial) {  // towers of 3 boxes, each on the one below, shifted at random
		std::vector<std::vector<Vector3>> parts;
		Vector3 lo(0, 0, 0);
		Vector3 size(1 + unit(rng), 1 + unit(rng), 0.5 + unit(rng));
		for (int k = 0; k < 3; ++k) {
			parts.push_back(boxPoints(lo, lo + size));
			const Vector3 next(1 + unit(rng), 1 + unit(rng), 0.5 + unit(rng));
			lo = Vector3(lo.x() + (size.x() - 0.2) * unit(rng), lo.y() + (size.y() - 0.2) * unit(rng), lo.z() + size.z());
			size = next;
		}
		cases.push_back(parts);
	}
	for (std::size_t c = 0; c < cases.size(); ++c) {
		SCOPED_TRACE("case " + std::to_string(c) + " (seed " + std::to_string(seed) + ")");
		const std::vector<std::vector<Vector3>> conformed = conformParts(cases[c]);
		EXPECT_GT(conformed.size(), cases[c].size());
		World world;
		const int b = world.addConcaveBlock(conformed, Material{}, false);
		const MassProperties whole = wholeOf(cases[c]);
		const Block& block = world.block(b);
		EXPECT_NEAR(block.volume, whole.volume, 1e-12 * whole.volume);
		EXPECT_LT((block.centroid - whole.centroid).norm(), 1e-12 * std::cbrt(whole.volume));
		EXPECT_LT((block.secondMoment - whole.secondMoment).norm(), 1e-12 * whole.secondMoment.norm());
		EXPECT_EQ(conformParts(conformed).size(), conformed.size());  // already conforming: unchanged
	}
}

void expectRefused(const std::vector<std::vector<Vector3>>& parts, const std::string& words) {
	World world;
	try {
		world.addConcaveBlock(parts, Material{}, false);
		ADD_FAILURE() << "accepted; expected an error with '" << words << "'";
	} catch (const InputError& error) {
		EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
	}
	EXPECT_EQ(world.blockCount(), 0);
}

TEST(ConcaveBlocks, BadPartsAreRefusedNamingTheProblem) {
	const Vector3 o = Vector3::Zero();
	expectRefused({boxPoints(o, Vector3(1, 1, 1)), boxPoints(Vector3(0.5, 0, 0), Vector3(1.5, 1, 1))}, "overlap");
	expectRefused({boxPoints(o, Vector3(1, 1, 1)), boxPoints(Vector3(2, 0, 0), Vector3(3, 1, 1))}, "shares no face");
	// Touching along an edge only: not one piece.
	expectRefused({boxPoints(o, Vector3(1, 1, 1)), boxPoints(Vector3(1, 1, 0), Vector3(2, 2, 1))}, "shares no face");
	// Staggered bricks: each top face partly shared.
	expectRefused({boxPoints(o, Vector3(2, 1, 1)), boxPoints(Vector3(1, 0, 1), Vector3(3, 1, 2))}, "neither face");
	std::vector<Vector3> flat = boxPoints(o, Vector3(1, 1, 1));
	flat.push_back(Vector3(0.5, 0.5, 0.5));  // not a corner
	expectRefused({boxPoints(Vector3(0, 0, 1), Vector3(1, 1, 2)), flat}, "part 1");
	expectRefused({}, "at least one part");
}

}  // namespace
}  // namespace dda::testing
