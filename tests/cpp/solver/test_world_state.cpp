// World::writeState / readState: a restored world continues bitwise like the
// original, and bad input changes nothing.
#include "TestScenes.hpp"
#include "dda/collider/MSCCollider.hpp"
#include "dda/core/StateStream.hpp"

#include <gtest/gtest.h>

namespace dda::testing {
namespace {

// A floor and three blocks (one long enough for several MSC shells) settling
// under gravity, with friction, so contacts open, slide and lock.
World settlingStack() {
	World world;
	Material rock;
	rock.young = 1e8;
	rock.frictionAngle = 0.5;
	const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
	world.addBlock(orientedBox(Vector3(0, 0, -0.5), Vector3(10, 10, 0.5), I), rock, true);
	world.addBlock(orientedBox(Vector3(0, 0, 0.5005), Vector3(4, 0.5, 0.5), I), rock, false);
	const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Vector3::UnitZ()).toRotationMatrix();
	world.addBlock(orientedBox(Vector3(1, 0.1, 1.5008), Vector3(0.5, 0.5, 0.5), turn), rock, false);
	world.addBlock(orientedBox(Vector3(-2, 0, 1.502), Vector3(0.4, 0.4, 0.5), I), rock, false);
	world.setVelocity(3, Vector3(0.5, 0, 0), Vector3::Zero());
	world.setCollider(std::make_unique<MSCCollider>());
	return world;
}

IntegratorSettings settings() {
	IntegratorSettings s;
	s.gravity = Vector3(1, 0, -9.81);
	s.maxDisplacement = 0.002;
	s.threads = 1;
	return s;
}

std::string stateOf(const World& world) {
	StateWriter out;
	world.writeState(out);
	return out.bytes();
}

// The state without the last step's statistics, which hold wall times: the
// counters, time and next dt (the first 60 bytes) and everything from the blocks on.
std::string physicsOf(const World& world) {
	const std::string state = stateOf(world);
	return state.substr(0, 60) + state.substr(state.find("BLKS"));
}

TEST(WorldState, RestoredWorldContinuesBitwise) {
	World original = settlingStack();
	for (int k = 0; k < 20; ++k) original.step(settings());
	ASSERT_GT(original.contacts().size(), 0u);
	const std::string saved = stateOf(original);
	World restored;
	StateReader in(saved);
	restored.readState(in);
	EXPECT_TRUE(in.atEnd());
	EXPECT_TRUE(stateOf(restored) == saved);
	for (int k = 0; k < 20; ++k) {
		original.step(settings());
		restored.step(settings());
	}
	EXPECT_EQ(restored.time(), original.time());
	EXPECT_TRUE(physicsOf(restored) == physicsOf(original)) << "the restored world diverged";
	bool closed = false;
	for (const Contact& c : original.contacts()) closed = closed || c.history.state != ContactState::Open;
	EXPECT_TRUE(closed);
}

// Blocks of equal faces and edges share one topology (TopologyPool), in a
// world built block by block and in one restored from its state; a block of
// another topology has its own.
TEST(WorldState, BlocksOfOneTopologyShareIt) {
	World world = settlingStack();
	world.addBlock({{5, 5, 0}, {6, 5, 0}, {5, 6, 0}, {5, 5, 1}}, Material{}, true);
	for (int b = 1; b < 4; ++b) EXPECT_EQ(world.block(b).shape, world.block(0).shape) << "block " << b;
	EXPECT_NE(world.block(4).shape, world.block(0).shape);
	EXPECT_EQ(world.block(0).shape->vertexCount(), 8);
	EXPECT_EQ(world.block(4).shape->vertexCount(), 4);
	const std::string saved = stateOf(world);
	World restored;
	StateReader in(saved);
	restored.readState(in);
	for (int b = 1; b < 4; ++b) EXPECT_EQ(restored.block(b).shape, restored.block(0).shape) << "block " << b;
	EXPECT_NE(restored.block(4).shape, restored.block(0).shape);
	EXPECT_TRUE(*restored.block(4).shape == *world.block(4).shape);
	EXPECT_TRUE(stateOf(restored) == saved);
}

TEST(WorldState, BadStateThrowsAndChangesNothing) {
	World world = settlingStack();
	for (int k = 0; k < 5; ++k) world.step(settings());
	const std::string good = stateOf(world);
	World target = settlingStack();
	const std::string before = stateOf(target);
	for (std::size_t cut : {std::size_t{0}, std::size_t{3}, good.size() / 2, good.size() - 1}) {
		const std::string truncated = good.substr(0, cut);
		StateReader in(truncated);
		EXPECT_THROW(target.readState(in), StateError);
		EXPECT_TRUE(stateOf(target) == before);
	}
	EXPECT_THROW(unframeState(good), StateError);  // not framed
	std::string framed = frameState(good);
	framed[framed.size() / 2] ^= 0x10;
	try {
		unframeState(framed);
		FAIL() << "a corrupt state was accepted";
	} catch (const StateError& error) {
		EXPECT_NE(std::string(error.what()).find("checksum"), std::string::npos) << error.what();
	}
	framed = frameState(good);
	framed[16] = 7;  // version
	try {
		unframeState(framed);
		FAIL() << "another version was accepted";
	} catch (const StateError& error) {
		EXPECT_NE(std::string(error.what()).find("format version 7"), std::string::npos) << error.what();
	}
}

}  // namespace
}  // namespace dda::testing
