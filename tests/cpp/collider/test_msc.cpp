// The multi-shell cover collider: it finds the all-pairs contact set on random
// scenes, its shells cover their blocks (also after the blocks moved), the
// sub-units it links to a pair hold every feature of the pair's contacts, it
// beats DESS on slender scenes, and fixed blocks' shells are built once.
#include "dda/collider/Collider.hpp"
#include "dda/collider/MSCCollider.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/core/StateStream.hpp"
#include "dda/solver/World.hpp"
#include "TestScenes.hpp"

#include <gtest/gtest.h>

#include <omp.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

using namespace dda;
using namespace dda::testing;

namespace {

// TestScenes.hpp's random scene, plus a long block with cubes lying along
// its edge, exactly on its slab planes.
World randomMscScene(int n, unsigned seed) {
	World world = randomScene(n, seed);
	Material material;
	const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
	// A long block lying along the edge of another, exactly: the contact sits
	// on the first one's slab planes.
	world.addBlock(orientedBox(Vector3(40, 0, 0), Vector3(10, 0.5, 0.5), I), material, false);
	world.addBlock(orientedBox(Vector3(40, 1, 1), Vector3(0.5, 0.5, 0.5), I), material, false);
	world.addBlock(orientedBox(Vector3(40 + 10 / 3.0, 0, 1), Vector3(0.5, 0.5, 0.5), I), material, false);
	return world;
}

// A log pile: layers of 10:1:1 blocks, each layer across the one below,
// slightly turned, with gaps and penetrations between -0.4 d0 and d0 (the
// states DDA keeps contacts in), some blocks fixed.
World logPile(double d0, unsigned seed) {
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> unit(0, 1);
	World world;
	Material material;
	const auto gap = [&] { return d0 * (-0.4 + 1.4 * unit(rng)); };
	double z = 0.5;
	for (int layer = 0; layer < 4; ++layer) {
		const double turn = (layer % 2 ? M_PI / 2 : 0) + 0.02 * (unit(rng) - 0.5);
		const Eigen::Matrix3d R = Eigen::AngleAxisd(turn, Vector3::UnitZ()).toRotationMatrix();
		double y = -4.5;
		for (int k = 0; k < 8; ++k) {
			const Vector3 axis = Vector3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
			const Eigen::Matrix3d tilt = Eigen::AngleAxisd(1e-4 * unit(rng), axis).toRotationMatrix();
			world.addBlock(orientedBox(R * Vector3(0, y, 0) + Vector3(0, 0, z), Vector3(5, 0.5, 0.5), R * tilt), material,
			               layer == 0 && k % 3 == 0);
			y += 1 + gap();
		}
		z += 1 + gap();
	}
	return world;
}

std::optional<PairContacts> detect(const std::vector<Block>& blocks, int a, int b, double d0) {
	return detectPairContacts(BlockGeometry{blocks[a].shape.get(), &blocks[a].vertices, blocks[a].centroid},
	                          BlockGeometry{blocks[b].shape.get(), &blocks[b].vertices, blocks[b].centroid},
	                          detectionSettings(d0));
}

bool has(const SubUnitList& sorted, int x) { return std::binary_search(sorted.begin(), sorted.end(), x); }

// Checks that every feature of every sub-contact of the MSC candidates is
// linked to the pair; returns the number of sub-contacts checked.
int checkLinkedFeatures(const std::vector<Block>& blocks, double d0, MSCCollider msc = MSCCollider()) {
	std::vector<std::pair<int, int>> pairs;
	BroadPhaseStatistics stats;
	msc.findPairs(blocks, d0, pairs, stats);
	int checked = 0;
	long loops = 0;
	for (int p = 0; p < static_cast<int>(pairs.size()); ++p) {
		const LinkedSubUnits* linked = msc.linked(p);
		if (!linked) {
			ADD_FAILURE() << "no linked sub-units for pair " << p;
			continue;
		}
		loops += linked->subUnitPairs();
		for (int i = 0; i < 2; ++i)
			for (const auto* set : {&linked->vertices[i], &linked->edges[i], &linked->faces[i]}) {
				EXPECT_TRUE(std::is_sorted(set->begin(), set->end()));
				EXPECT_TRUE(std::adjacent_find(set->begin(), set->end()) == set->end());
			}
		const auto [a, b] = pairs[p];
		const auto result = detect(blocks, a, b, d0);
		if (!result) continue;
		for (const SubContact& c : result->contacts) {
			const int i = c.firstIsA ? 0 : 1, j = 1 - i;
			if (c.kind == ContactKind::VertexFace) {
				EXPECT_TRUE(has(linked->vertices[i], c.feature1))
				    << "pair " << a << "-" << b << " vertex " << c.feature1 << " (d0 " << d0 << ")";
				EXPECT_TRUE(has(linked->faces[j], c.feature2))
				    << "pair " << a << "-" << b << " face " << c.feature2 << " (d0 " << d0 << ")";
			} else {
				EXPECT_TRUE(has(linked->edges[i], c.feature1))
				    << "pair " << a << "-" << b << " edge " << c.feature1 << " (d0 " << d0 << ")";
				EXPECT_TRUE(has(linked->edges[j], c.feature2))
				    << "pair " << a << "-" << b << " edge " << c.feature2 << " (d0 " << d0 << ")";
			}
			++checked;
		}
	}
	EXPECT_EQ(stats.subUnitPairs, loops);
	EXPECT_EQ(msc.linked(static_cast<int>(pairs.size())), nullptr);
	return checked;
}

// A point of the block: a random convex combination of its corners.
Vector3 pointInside(const Block& block, std::mt19937& rng) {
	std::exponential_distribution<double> weight(1.0);
	Vector3 sum = Vector3::Zero();
	double total = 0;
	for (const Vector3& x : block.vertices) {
		const double w = std::pow(weight(rng), 3);  // spiky: points near corners and edges too
		sum += w * x;
		total += w;
	}
	return sum / total;
}

// Whether two colliders' first `count` linked sets hold the same sub-units.
bool sameLinkedSets(const MSCCollider& x, const MSCCollider& y, int count) {
	const auto list = [](const SubUnitList& l) { return std::vector<int>(l.begin(), l.end()); };
	for (int p = 0; p < count; ++p) {
		const LinkedSubUnits &u = *x.linked(p), &v = *y.linked(p);
		for (int i = 0; i < 2; ++i)
			if (list(u.vertices[i]) != list(v.vertices[i]) || list(u.edges[i]) != list(v.edges[i]) ||
			    list(u.faces[i]) != list(v.faces[i]))
				return false;
	}
	return true;
}

std::string stateOf(const MSCCollider& msc) {
	StateWriter out;
	msc.writeState(out);
	return out.bytes();
}

bool inShells(const MSCCollider& msc, int block, const Vector3& x, double tolerance) {
	for (int s = 0; s < msc.shellCount(block); ++s) {
		const Eigen::AlignedBox3d& box = msc.shellBox(block, s);
		if (((box.min().array() - tolerance) <= x.array()).all() && (x.array() <= (box.max().array() + tolerance)).all())
			return true;
	}
	return false;
}

}  // namespace

TEST(MSCCollider, FindsTheAllPairsContactSet) {
	for (unsigned seed : {1u, 2u, 3u, 4u}) {
		const std::vector<Block> blocks = blocksOf(randomMscScene(120, seed));
		for (double d0 : {0.0, 0.05, 0.5}) {
			AllPairsCollider all;
			const ContactSet reference = contactSet(all, blocks, d0);
			ASSERT_GT(reference.size(), 10u);
			MSCCollider msc;
			const ContactSet fromMsc = contactSet(msc, blocks, d0);
			for (const auto& c : reference)
				if (!fromMsc.count(c)) ADD_FAILURE() << "MSC misses " << std::get<0>(c) << "-" << std::get<1>(c);
			EXPECT_TRUE(fromMsc == reference) << "seed " << seed << " d0 " << d0;
			// More slabs, and every block cut.
			MSCCollider fine(0.5, 7);
			EXPECT_TRUE(contactSet(fine, blocks, d0) == reference) << "seed " << seed << " d0 " << d0;
		}
	}
}

TEST(MSCCollider, SparseAndDenseGridsFindTheSameContacts) {
	// The grid's cells are keyed by index (counting sort) in a compact domain
	// and by packed coordinates when a far block makes the domain huge; both
	// give the all-pairs contact set and the same pairs among the other blocks.
	const std::vector<Block> compact = blocksOf(randomMscScene(120, 5));
	World farWorld = randomMscScene(120, 5);
	farWorld.addBlock(orientedBox(Vector3(4e4, -3e4, 5e4), Vector3(0.1, 0.1, 0.1), Eigen::Matrix3d::Identity()),
	                  Material(), false);
	const std::vector<Block> spread = blocksOf(farWorld);
	for (double d0 : {0.0, 0.05, 0.5}) {
		MSCCollider dense, sparse;
		std::vector<std::pair<int, int>> densePairs, sparsePairs;
		BroadPhaseStatistics stats;
		dense.findPairs(compact, d0, densePairs, stats);
		dense.setPairReuse(false);
		sparse.setPairReuse(false);
		dense.findPairs(compact, d0, densePairs, stats);
		EXPECT_TRUE(dense.denseGrid());
		sparse.findPairs(spread, d0, sparsePairs, stats);
		EXPECT_FALSE(sparse.denseGrid());
		EXPECT_EQ(densePairs, sparsePairs) << "d0 " << d0;  // the far block meets nothing
		AllPairsCollider all;
		EXPECT_TRUE(contactSet(sparse, spread, d0) == contactSet(all, spread, d0)) << "d0 " << d0;
		EXPECT_TRUE(contactSet(dense, compact, d0) == contactSet(all, compact, d0)) << "d0 " << d0;
	}
}

TEST(MSCCollider, LinksEveryFeatureOfTheContacts) {
	// Random scenes, deep overlaps included (the design argument covers
	// penetrations up to d0 / 2; deeper ones hold on these scenes too).
	int checked = 0;
	for (unsigned seed : {1u, 2u, 3u})
		for (double d0 : {0.0, 0.05, 0.5}) {
			const std::vector<Block> blocks = blocksOf(randomMscScene(120, seed));
			checked += checkLinkedFeatures(blocks, d0);
			checkLinkedFeatures(blocks, d0, MSCCollider(0.5, 7));  // every block cut, in 7
		}
	EXPECT_GT(checked, 500);
	// Log piles: contacts in DDA's range of penetration, across slab planes.
	int pile = 0;
	for (unsigned seed : {1u, 2u})
		for (double d0 : {0.01, 0.1}) {
			const std::vector<Block> blocks = blocksOf(logPile(d0, seed));
			pile += checkLinkedFeatures(blocks, d0);
			checkLinkedFeatures(blocks, d0, MSCCollider(3, 9));
		}
	EXPECT_GT(pile, 1000);
}

TEST(MSCCollider, FewerCandidatesAndSubUnitLoopsThanDESSOnSlenderScenes) {
	Material material;
	// 200 randomly turned 20 x 1 x 1 m blocks in a 40 m box.
	World sticks;
	std::mt19937 rng(7);
	std::uniform_real_distribution<double> unit(0, 1);
	for (int k = 0; k < 200; ++k)
		sticks.addBlock(orientedBox(Vector3(40 * unit(rng), 40 * unit(rng), 40 * unit(rng)), Vector3(10, 0.5, 0.5),
		                            randomRotation(rng)),
		                material, k % 10 == 0);
	// A row of ten 10 x 1 x 1 m blocks at 45 degrees in the x-y plane, side by
	// side, 1 cm apart.
	World row;
	const Eigen::Matrix3d slant = Eigen::AngleAxisd(M_PI / 4, Vector3::UnitZ()).toRotationMatrix();
	for (int k = 0; k < 10; ++k)
		row.addBlock(orientedBox(slant * Vector3(0, 1.01 * k, 0), Vector3(5, 0.5, 0.5), slant), material, k == 0);
	for (const World* world : {&sticks, &row}) {
		const std::vector<Block> blocks = blocksOf(*world);
		for (double d0 : {0.02, 0.2}) {
			AllPairsCollider all;
			DESSCollider dess;
			MSCCollider msc;
			BroadPhaseStatistics allStats, dessStats, mscStats;
			NarrowPhaseWork dessWork, mscWork;
			const ContactSet reference = contactSet(all, blocks, d0, &allStats);
			EXPECT_TRUE(contactSet(dess, blocks, d0, &dessStats, &dessWork) == reference);
			EXPECT_TRUE(contactSet(msc, blocks, d0, &mscStats, &mscWork) == reference);
			EXPECT_LE(mscStats.candidatePairs, dessStats.candidatePairs) << "d0 " << d0;
			EXPECT_LT(mscStats.subUnitPairs, dessStats.subUnitPairs) << "d0 " << d0;
			// The narrow phase really loops over the linked sub-units only.
			EXPECT_LT(mscWork.subUnitTests, dessWork.subUnitTests) << "d0 " << d0;
			EXPECT_EQ(dessWork.fullSearches, 0);
			EXPECT_GE(mscStats.shellPairs, mscStats.candidatePairs);
			EXPECT_EQ(mscStats.shells, 3L * world->blockCount());  // every block is long
			EXPECT_EQ(dessStats.shells, world->blockCount());
		}
	}
	// The row: DESS's 45-degree boxes reach far past each neighbour; MSC
	// proposes fewer pairs, still every pair of neighbours (9 contacts pairs).
	const std::vector<Block> blocks = blocksOf(row);
	DESSCollider dess;
	MSCCollider msc;
	std::vector<std::pair<int, int>> dessPairs, mscPairs;
	BroadPhaseStatistics stats;
	dess.findPairs(blocks, 0.02, dessPairs, stats);
	msc.findPairs(blocks, 0.02, mscPairs, stats);
	EXPECT_LT(mscPairs.size(), dessPairs.size());
	for (int k = 0; k + 1 < 10; ++k)
		EXPECT_TRUE(std::binary_search(mscPairs.begin(), mscPairs.end(), std::make_pair(k, k + 1))) << k;
	// Along the blocks' own axes (their frames) the next but one is 1 m away:
	// the neighbours only, although the 45-degree shells of blocks k and k + 2
	// overlap as boxes.
	EXPECT_EQ(mscPairs.size(), 9u);
	EXPECT_GT(stats.shellTests, stats.shellPairs);
}

TEST(MSCCollider, FramesAreThreeFacesOfTheBoxAcrossItsMainAxisFirst) {
	const std::vector<Block> blocks = blocksOf(randomMscScene(40, 3));
	MSCCollider msc;
	std::vector<std::pair<int, int>> pairs;
	BroadPhaseStatistics stats;
	msc.findPairs(blocks, 0.05, pairs, stats);
	for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
		const Block& block = blocks[b];
		const std::array<int, 3>& faces = msc.frameFaces(b);
		Vector3 normals[3];
		for (int j = 0; j < 3; ++j) {
			ASSERT_GE(faces[j], 0) << "block " << b;
			const std::vector<int>& face = block.shape->faces[faces[j]];
			normals[j] = (block.vertices[face[1]] - block.vertices[face[0]])
			                 .cross(block.vertices[face[2]] - block.vertices[face[0]])
			                 .normalized();
		}
		// A box: three mutually orthogonal faces.
		EXPECT_NEAR(std::abs(normals[0].dot(normals[1].cross(normals[2]))), 1, 1e-9) << "block " << b;
		// The first is across the longest edge (a long block's end).
		Vector3 longest = Vector3::Zero();
		for (const auto& e : block.shape->edges) {
			const Vector3 d = block.vertices[e[1]] - block.vertices[e[0]];
			if (d.norm() > longest.norm()) longest = d;
		}
		if (msc.shellCount(b) > 1) EXPECT_NEAR(std::abs(normals[0].dot(longest.normalized())), 1, 1e-9) << "block " << b;
	}
}

TEST(MSCCollider, ShellPairCacheGivesThePairsAndLinkedSetsOfAFullSearch) {
	// Blocks moved a little (inside the skin) and some far (outside): each
	// round the cached collider must return what one without cache returns,
	// pair for pair and linked set for linked set, and the contacts of AllPairs.
	std::vector<Block> blocks = blocksOf(randomMscScene(120, 8));
	const double d0 = 0.05;
	MSCCollider cached, uncached;
	uncached.setPairReuse(false);
	std::mt19937 rng(4);
	std::uniform_real_distribution<double> unit(0, 1);
	long skipped = 0, partial = 0, reused = 0, full = 0;
	for (int round = 0; round < 12; ++round) {
		std::vector<std::pair<int, int>> pairsCached, pairsUncached;
		BroadPhaseStatistics withCache, without;
		cached.findPairs(blocks, d0, pairsCached, withCache);
		uncached.findPairs(blocks, d0, pairsUncached, without);
		ASSERT_EQ(pairsCached, pairsUncached) << "round " << round;
		EXPECT_EQ(withCache.shellPairs, without.shellPairs);
		EXPECT_EQ(withCache.subUnitPairs, without.subUnitPairs);
		EXPECT_TRUE(sameLinkedSets(cached, uncached, static_cast<int>(pairsCached.size()))) << "round " << round;
		EXPECT_EQ(without.broadPhaseSkipped, 0);
		skipped += withCache.broadPhaseSkipped;
		partial += withCache.broadPhaseSkipped && withCache.blocksResearched > 0;
		reused += withCache.pairsReused;
		full += withCache.blocksResearched == static_cast<long>(blocks.size());
		if (round % 4 == 3) {
			AllPairsCollider all;
			EXPECT_TRUE(contactSet(cached, blocks, d0) == contactSet(all, blocks, d0)) << "round " << round;
		}
		// Every free block drifts by up to 0.3 d0; rounds 2, 5, 8: a few jump by
		// 2 d0 (re-searched one by one); round 10: most jump (a full search).
		for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
			Block& block = blocks[b];
			if (block.fixed) continue;
			const bool jump = (round % 3 == 2 && b % 25 == 0) || (round == 10 && b % 4 != 0);
			const double step = (jump ? 2.0 : 0.3) * d0;
			const Vector3 shift = step * Vector3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
			const Eigen::Matrix3d turn =
			    Eigen::AngleAxisd(0.002 * unit(rng), Vector3(unit(rng), unit(rng), unit(rng)).normalized()).toRotationMatrix();
			for (Vector3& x : block.vertices) x = block.centroid + shift + turn * (x - block.centroid);
			block.centroid += shift;
		}
	}
	EXPECT_GT(skipped, 6);
	EXPECT_GE(partial, 3);
	EXPECT_GT(reused, 0);
	EXPECT_GE(full, 2);  // the first call and round 10
}

TEST(MSCCollider, ShellsCoverTheirBlocksAlsoAfterAffineMotion) {
	std::vector<Block> blocks = blocksOf(randomMscScene(60, 5));
	// One block of its own cover: 9 slabs from 1 m long.
	MSCCollider msc;
	msc.setBlockCover(0, 1.0, 9);
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> unit(0, 1);
	for (int round = 0; round < 3; ++round) {
		std::vector<std::pair<int, int>> pairs;
		BroadPhaseStatistics stats;
		msc.findPairs(blocks, 0.1, pairs, stats);
		long shells = 0;
		for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
			const Block& block = blocks[b];
			shells += msc.shellCount(b);
			double longest = 0;
			for (const auto& e : block.shape->edges)
				longest = std::max(longest, (block.vertices[e[1]] - block.vertices[e[0]]).norm());
			if (b == 0)
				EXPECT_EQ(msc.shellCount(b), 9);
			else if (round == 0)  // lengths change a little once the blocks are strained
				EXPECT_EQ(msc.shellCount(b), longest > 3 * block.size ? 3 : 1) << b;
			Eigen::AlignedBox3d box;
			for (const Vector3& x : block.vertices) box.extend(x);
			const double tolerance = 1e-12 * box.diagonal().norm();
			for (const Vector3& x : block.vertices) EXPECT_TRUE(inShells(msc, b, x, tolerance)) << "block " << b;
			for (int k = 0; k < 200; ++k) {
				const Vector3 x = pointInside(block, rng);
				EXPECT_TRUE(inShells(msc, b, x, tolerance)) << "block " << b << " point " << x.transpose();
			}
			// Each shell lies within the block's box: the cover is never coarser than DESS's.
			for (int s = 0; s < msc.shellCount(b); ++s)
				EXPECT_TRUE(box.contains(msc.shellBox(b, s))) << "block " << b << " shell " << s;
		}
		EXPECT_EQ(stats.shells, shells);
		// Move every free block by an affine map: turn, stretch by up to 10 %, shift.
		for (Block& block : blocks) {
			if (block.fixed) continue;
			const Eigen::Matrix3d strain =
			    Eigen::Matrix3d::Identity() + 0.1 * Eigen::Matrix3d::NullaryExpr([&](int, int) { return unit(rng) - 0.5; });
			const Eigen::Matrix3d map = randomRotation(rng) * strain;
			const Vector3 shift(unit(rng), unit(rng), unit(rng));
			for (Vector3& x : block.vertices) x = block.centroid + shift + map * (x - block.centroid);
			block.centroid += shift;
		}
	}
	EXPECT_EQ(msc.coverBuilds(), static_cast<long>(blocks.size()));  // topology once
}

TEST(MSCCollider, FixedBlocksShellsAreBuiltOnceAndFixedPairsNeverProposed) {
	const std::vector<Block> blocks = blocksOf(randomMscScene(100, 9));
	MSCCollider msc;
	long fixedShells = 0, allShells = 0;
	std::vector<std::pair<int, int>> pairs;
	BroadPhaseStatistics stats;
	for (int call = 0; call < 3; ++call) {
		msc.findPairs(blocks, 0.05, pairs, stats);
		if (call == 0) {
			for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
				allShells += msc.shellCount(b);
				if (blocks[b].fixed) fixedShells += msc.shellCount(b);
			}
			ASSERT_GT(fixedShells, 10);
			EXPECT_EQ(stats.shellUpdates, allShells);
		} else {
			EXPECT_EQ(stats.shellUpdates, allShells - fixedShells);
		}
		for (auto [a, b] : pairs) EXPECT_FALSE(blocks[a].fixed && blocks[b].fixed) << a << "-" << b;
	}
	EXPECT_EQ(msc.totalShellUpdates(), allShells + 2 * (allShells - fixedShells));
	EXPECT_EQ(msc.coverBuilds(), static_cast<long>(blocks.size()));
	// A block more: every cover is rebuilt, every box recomputed once.
	std::vector<Block> more = blocks;
	more.push_back(blocks.back());
	msc.findPairs(more, 0.05, pairs, stats);
	EXPECT_EQ(msc.coverBuilds(), static_cast<long>(2 * blocks.size() + 1));
	EXPECT_EQ(stats.shellUpdates, allShells + msc.shellCount(static_cast<int>(blocks.size())));
}

TEST(MSCCollider, StatisticsAndLinkedSetsOfEveryStrategy) {
	const std::vector<Block> blocks = blocksOf(randomMscScene(80, 4));
	std::unique_ptr<Collider> others[] = {std::make_unique<AllPairsCollider>(), std::make_unique<DESSCollider>(),
	                                      std::make_unique<NBSCollider>()};
	for (auto& collider : others) {
		std::vector<std::pair<int, int>> pairs;
		BroadPhaseStatistics stats;
		collider->findPairs(blocks, 0.05, pairs, stats);
		long loops = 0;
		for (auto [a, b] : pairs) loops += allSubUnitPairs(*blocks[a].shape, *blocks[b].shape);
		EXPECT_EQ(stats.subUnitPairs, loops) << collider->name();
		EXPECT_EQ(stats.subUnitPairs, 240 * stats.candidatePairs) << "boxes: 8 x 6 x 2 + 12 x 12";
		EXPECT_EQ(collider->linked(0), nullptr) << collider->name();
		EXPECT_LE(stats.shellPairs, stats.shellTests + stats.candidatePairs) << collider->name();
	}
	// MSC: a block of one shell links everything.
	MSCCollider msc;
	std::vector<std::pair<int, int>> pairs;
	BroadPhaseStatistics stats;
	msc.findPairs(blocks, 0.05, pairs, stats);
	ASSERT_FALSE(pairs.empty());
	EXPECT_LE(stats.subUnitPairs, 240 * stats.candidatePairs);
	for (int p = 0; p < static_cast<int>(pairs.size()); ++p) {
		const LinkedSubUnits* linked = msc.linked(p);
		ASSERT_NE(linked, nullptr);
		const auto [a, b] = pairs[p];
		if (msc.shellCount(a) == 1) EXPECT_EQ(linked->vertices[0].size(), 8u);
		if (msc.shellCount(b) == 1) EXPECT_EQ(linked->faces[1].size(), 6u);
		// A middle slab of a box holds no corner (the paper's Table 2, shell B),
		// but always edges and faces.
		for (int i = 0; i < 2; ++i) EXPECT_FALSE(linked->edges[i].empty() || linked->faces[i].empty());
	}
}

TEST(MSCCollider, RejectsInvalidCovers) {
	EXPECT_THROW(MSCCollider(0, 3), InputError);
	EXPECT_THROW(MSCCollider(3, 0), InputError);
	EXPECT_THROW(MSCCollider(3, MSCCollider::kMaxSegments + 1), InputError);
	MSCCollider msc;
	EXPECT_THROW(msc.setBlockCover(-1, 1, 3), InputError);
	EXPECT_THROW(msc.setBlockCover(0, -1, 3), InputError);
	EXPECT_THROW(msc.setBlockCover(0, std::nan(""), 3), InputError);
	EXPECT_THROW(msc.setBlockCover(0, 1, 0), InputError);
	EXPECT_THROW(msc.shellBox(0, 0), std::out_of_range);  // before any findPairs
	EXPECT_THROW(msc.setCover(-1, 3), InputError);
	EXPECT_THROW(msc.setCover(1, 0), InputError);
	EXPECT_NO_THROW(msc.setCover(0, 2));
}

TEST(MSCCollider, SceneAndBlockCoversRebuildOnlyWhatChanged) {
	const std::vector<Block> blocks = blocksOf(randomMscScene(40, 6));
	const int n = static_cast<int>(blocks.size());
	MSCCollider msc;
	std::vector<std::pair<int, int>> pairs, first;
	BroadPhaseStatistics stats;
	msc.findPairs(blocks, 0.05, first, stats);
	EXPECT_EQ(msc.coverBuilds(), n);
	// A scene-wide critical length of 1.2 m and 5 segments: every block with a
	// longer edge gets 5 shells; the contacts stay those of AllPairs.
	msc.setCover(1.2, 5);
	msc.findPairs(blocks, 0.05, pairs, stats);
	for (int b = 0; b < n; ++b) {
		double longest = 0;
		for (const auto& e : blocks[b].shape->edges)
			longest = std::max(longest, (blocks[b].vertices[e[1]] - blocks[b].vertices[e[0]]).norm());
		EXPECT_EQ(msc.shellCount(b), longest > 1.2 ? 5 : 1) << b;
	}
	AllPairsCollider all;
	EXPECT_TRUE(contactSet(msc, blocks, 0.05) == contactSet(all, blocks, 0.05));
	// Back to the defaults: the same pairs as before; one block's own cover
	// rebuilds that block only.
	msc.setCover(0, MSCCollider::kDefaultSegments);
	msc.findPairs(blocks, 0.05, pairs, stats);
	EXPECT_EQ(pairs, first);
	const long builds = msc.coverBuilds();
	msc.setBlockCover(3, 0.1, 2);
	msc.findPairs(blocks, 0.05, pairs, stats);
	EXPECT_EQ(msc.coverBuilds(), builds + 1);
	EXPECT_EQ(msc.shellCount(3), 2);
	// The covers kept are those built afresh (they are copied around the new one).
	MSCCollider fresh;
	fresh.setBlockCover(3, 0.1, 2);
	std::vector<std::pair<int, int>> freshPairs;
	fresh.findPairs(blocks, 0.05, freshPairs, stats);
	EXPECT_EQ(pairs, freshPairs);
	EXPECT_TRUE(sameLinkedSets(msc, fresh, static_cast<int>(pairs.size())));
}

TEST(MSCCollider, SavedCoversRestoreAsBuiltAndOtherCoversAreRejected) {
	// Logs of 10:1:1 (three shells each) turned after their covers were built.
	World world = logPile(0.01, 5);
	std::vector<Block> blocks = blocksOf(world);
	MSCCollider msc;
	std::vector<std::pair<int, int>> pairs, restoredPairs;
	BroadPhaseStatistics stats;
	msc.findPairs(blocks, 0.01, pairs, stats);
	ASSERT_EQ(msc.shellCount(0), 3);
	const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.01, Vector3::UnitX()).toRotationMatrix();
	for (Block& block : blocks)
		if (!block.fixed)
			for (Vector3& x : block.vertices) x = turn * x;
	const std::string saved = stateOf(msc);
	MSCCollider restored;
	StateReader in(saved);
	restored.readState(in, blocks);
	EXPECT_TRUE(in.atEnd());
	EXPECT_TRUE(stateOf(restored) == saved);
	msc.findPairs(blocks, 0.01, pairs, stats);
	restored.findPairs(blocks, 0.01, restoredPairs, stats);
	EXPECT_EQ(restoredPairs, pairs);
	EXPECT_TRUE(sameLinkedSets(msc, restored, static_cast<int>(pairs.size())));
	// The state ends with the last block's linked shells as masks (per vertex,
	// edge, face: a count and 8 bytes each) and two 8-byte counters; before
	// them, its last shell's division points (edge, fraction).
	const std::size_t masks = 3 * 8 + (8 + 12 + 6) * 8, end = saved.size() - 16;
	const std::string before = stateOf(restored);
	const auto corrupt = [&](std::size_t at, std::uint64_t value, std::size_t bytes) {
		std::string bad = saved;
		bad.replace(at, bytes, reinterpret_cast<const char*>(&value), bytes);
		StateReader badIn(bad);
		EXPECT_THROW(restored.readState(badIn, blocks), StateError) << "at byte " << at;
	};
	corrupt(end - 8, 0b101, 8);                        // a face linked to two slabs apart
	corrupt(end - masks + 8, 0b111, 8);                // a vertex linked to every slab: not the saved corners
	corrupt(end - masks - 8, 0x3FE0000000000000, 8);  // a division point at 1/2: not the shell below's
	EXPECT_TRUE(stateOf(restored) == before);  // (unchanged by the rejected states)
}

TEST(MSCCollider, WorldStepsAsWithDESS) {
	// Crossed 10 x 1 x 1 m blocks dropped on a fixed floor: the same contacts,
	// hence the same trajectory, to the last bit.
	const auto scene = [](std::unique_ptr<Collider> collider) {
		World world;
		world.setCollider(std::move(collider));
		Material material;
		world.addBlock(orientedBox(Vector3(0, 0, -0.5), Vector3(8, 8, 0.5), Eigen::Matrix3d::Identity()), material, true);
		for (int k = 0; k < 4; ++k) {
			const Eigen::Matrix3d R = Eigen::AngleAxisd(k * 1.3 + 0.1, Vector3::UnitZ()).toRotationMatrix() *
			                          Eigen::AngleAxisd(0.02 * k, Vector3::UnitX()).toRotationMatrix();
			world.addBlock(orientedBox(Vector3(0.3 * k, -0.2 * k, 0.52 + 1.02 * k), Vector3(5, 0.5, 0.5), R), material,
			               false);
		}
		IntegratorSettings settings;
		settings.gravity = Vector3(0, 0, -9.81);
		settings.maxTimeStep = 2e-3;
		long contacts = 0;
		for (int step = 0; step < 60; ++step) {
			world.step(settings);
			contacts += world.lastStep().contacts;
		}
		return std::make_pair(blocksOf(world), contacts);
	};
	const auto [withDess, dessContacts] = scene(std::make_unique<DESSCollider>());
	const auto [withMsc, mscContacts] = scene(std::make_unique<MSCCollider>());
	EXPECT_GT(dessContacts, 0);
	EXPECT_EQ(mscContacts, dessContacts);
	for (std::size_t b = 0; b < withDess.size(); ++b)
		for (std::size_t v = 0; v < withDess[b].vertices.size(); ++v)
			EXPECT_EQ(withDess[b].vertices[v], withMsc[b].vertices[v]) << "block " << b << " corner " << v;
}

TEST(MSCCollider, LinkedNarrowPhaseEqualsTheFullSearchAndFallsBackWhenDeep) {
	// Log piles keep DDA's range of penetration (down to -0.4 d0): the linked
	// search alone decides every pair, with fewer tests than on all sub-units.
	for (unsigned seed : {1u, 2u, 3u})
		for (double d0 : {0.01, 0.1}) {
			const std::vector<Block> blocks = blocksOf(logPile(d0, seed));
			AllPairsCollider all;
			MSCCollider msc, fine(3, 9);
			NarrowPhaseWork allWork, mscWork, fineWork;
			const ContactSet reference = contactSet(all, blocks, d0, nullptr, &allWork);
			ASSERT_GT(reference.size(), 50u);
			EXPECT_TRUE(contactSet(msc, blocks, d0, nullptr, &mscWork) == reference) << seed << " " << d0;
			EXPECT_TRUE(contactSet(fine, blocks, d0, nullptr, &fineWork) == reference) << seed << " " << d0;
			EXPECT_EQ(mscWork.fullSearches, 0);
			EXPECT_EQ(fineWork.fullSearches, 0);
			EXPECT_LT(mscWork.subUnitTests, allWork.subUnitTests);
		}
	// Random scenes overlap deeply (blocks placed at random): those pairs are
	// searched again with every sub-unit, and the result is still the same.
	long fullSearches = 0;
	for (unsigned seed : {1u, 2u}) {
		const std::vector<Block> blocks = blocksOf(randomMscScene(120, seed));
		AllPairsCollider all;
		MSCCollider msc;
		NarrowPhaseWork work;
		EXPECT_TRUE(contactSet(msc, blocks, 0.05, nullptr, &work) == contactSet(all, blocks, 0.05)) << seed;
		fullSearches += work.fullSearches;
	}
	EXPECT_GT(fullSearches, 0);
}

TEST(MSCCollider, MemoryStatisticsCountTheArraysHeld) {
	// World::memoryUse's collider, contacts, narrowPhase and solver bytes hold
	// at least the arrays every strategy must keep (a box per block or shell; a
	// Contact per sub-contact; a result per candidate pair; a solution and a
	// motion per moving block) and MSC's shells cost more than DESS's single
	// boxes.
	struct Run {
		StepStatistics stats;
		World::MemoryUse memory;
	};
	const auto run = [](std::unique_ptr<Collider> collider) {
		World world = randomMscScene(120, 9);
		world.setCollider(std::move(collider));
		IntegratorSettings settings;
		settings.maxTimeStep = 1e-4;
		world.step(settings);
		return Run{world.lastStep(), world.memoryUse()};
	};
	const Run dessRun = run(std::make_unique<DESSCollider>());
	const Run mscRun = run(std::make_unique<MSCCollider>());
	const Run nbsRun = run(std::make_unique<NBSCollider>());
	const StepStatistics &dess = dessRun.stats, &msc = mscRun.stats, &nbs = nbsRun.stats;
	ASSERT_GT(dess.contacts, 10);
	for (const StepStatistics* s : {&dess, &msc, &nbs}) {
		// The phases' process CPU time: some was spent, and not more than the
		// step's wall time times the threads that may run (2 here) plus a
		// clock tick, with margin.
		EXPECT_GT(s->cpuNarrowPhase, 0);
		EXPECT_GE(s->cpuBroadPhase, 0);
		EXPECT_LE(s->cpuBroadPhase + s->cpuNarrowPhase, s->timeTotal * 4 + 0.02);
	}
	for (const Run* r : {&dessRun, &mscRun, &nbsRun}) {
		EXPECT_GE(r->memory.contacts, r->stats.contacts * sizeof(Contact));
		EXPECT_LT(r->memory.contacts, r->stats.contacts * sizeof(Contact) * 20 + (1 << 20));
		// The narrow phase keeps at least one result slot per candidate pair.
		EXPECT_GE(r->memory.narrowPhase, r->stats.candidatePairs * sizeof(std::optional<PairContacts>));
		// The solver keeps a solution and a motion per moving block.
		EXPECT_GE(r->memory.solver, r->stats.movingBlocks * (sizeof(Vector12) + sizeof(BlockMotion)));
	}
	EXPECT_GE(dessRun.memory.collider, dess.blocks * sizeof(Eigen::AlignedBox3d));
	EXPECT_GE(mscRun.memory.collider, msc.shells * 2 * sizeof(Eigen::AlignedBox3d));
	EXPECT_GT(mscRun.memory.collider, dessRun.memory.collider);
	// MSC's covers, linked lists and shell pairs are flat arrays (no vectors
	// per block or per linked set): about 1.0 kB per block here (2.2 kB when
	// they were), below 1 kB per block plus 64 kB (grid cells, headroom).
	EXPECT_LT(mscRun.memory.collider, msc.blocks * 1024 + (1 << 16));
	EXPECT_GE(nbsRun.memory.collider, nbs.blocks * (sizeof(Vector3) + sizeof(double)));
}

namespace {

// A lattice of slender blocks (6:1:1, three shells each), 5 mm apart and
// turned a little at random: every block has neighbours within d0 on all
// sides, so the cached shell pairs, the frame tests' block pairs and the
// candidates are many thousands, above the counts from which MSC's loops run
// threaded (MSCCollider.cpp).
std::vector<Block> slenderLattice(unsigned seed) {
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> tilt(-0.02, 0.02);
	World world;
	Material material;
	for (int i = 0; i < 12; ++i)
		for (int j = 0; j < 40; ++j)
			for (int k = 0; k < 5; ++k) {
				const Eigen::Matrix3d R = (Eigen::AngleAxisd(tilt(rng), Vector3::UnitX()) *
				                           Eigen::AngleAxisd(tilt(rng), Vector3::UnitY()) *
				                           Eigen::AngleAxisd(tilt(rng), Vector3::UnitZ()))
				                              .toRotationMatrix();
				const Vector3 centre(1.205 * i + 0.3 * (j % 2), 0.205 * j, 0.205 * k);
				world.addBlock(orientedBox(centre, Vector3(0.6, 0.1, 0.1), R), material, k == 0 && i % 3 == 0);
			}
	return blocksOf(world);
}

}  // namespace

TEST(MSCCollider, OneAndTwoThreadsFindTheSamePairsAndLinkedSets) {
	// Each round the blocks drift (some jump, re-searched; round 4 most:
	// a full search); the collider on 2 threads must return what one on 1
	// thread returns, pair for pair, linked set for linked set, counter for
	// counter.
	std::vector<Block> blocks = slenderLattice(5);
	const double d0 = 0.02;
	MSCCollider one, two;
	std::mt19937 rng(6);
	std::uniform_real_distribution<double> unit(0, 1);
	const int threadsBefore = omp_get_max_threads();
	for (int round = 0; round < 6; ++round) {
		std::vector<std::pair<int, int>> pairsOne, pairsTwo;
		BroadPhaseStatistics statsOne, statsTwo;
		omp_set_num_threads(1);
		one.findPairs(blocks, d0, pairsOne, statsOne);
		omp_set_num_threads(2);
		two.findPairs(blocks, d0, pairsTwo, statsTwo);
		omp_set_num_threads(threadsBefore);
		ASSERT_GT(statsOne.shellTests, 40000) << "round " << round;
		ASSERT_GT(pairsOne.size(), 4000u) << "round " << round;
		ASSERT_EQ(pairsOne, pairsTwo) << "round " << round;
		EXPECT_EQ(statsOne.shellPairs, statsTwo.shellPairs);
		EXPECT_EQ(statsOne.shellTests, statsTwo.shellTests);
		EXPECT_EQ(statsOne.subUnitPairs, statsTwo.subUnitPairs);
		EXPECT_EQ(statsOne.pairsReused, statsTwo.pairsReused);
		EXPECT_EQ(statsOne.blocksResearched, statsTwo.blocksResearched);
		ASSERT_TRUE(sameLinkedSets(one, two, static_cast<int>(pairsOne.size()))) << "round " << round;
		for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
			Block& block = blocks[b];
			if (block.fixed) continue;
			const bool jump = (round % 2 == 1 && b % 200 == 0) || (round == 4 && b % 4 != 0);
			const double step = (jump ? 2.0 : 0.2) * d0;
			const Vector3 shift = step * Vector3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
			for (Vector3& x : block.vertices) x += shift;
			block.centroid += shift;
		}
	}
}

