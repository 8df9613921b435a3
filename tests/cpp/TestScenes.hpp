// Scene builders shared by the C++ tests (tests/cpp/<layer>/*.cpp): axis-aligned and
// oriented boxes, random unknowns, a random scene of slender and compact, turned, fixed
// and free blocks with a few exact placements, a settling pile of cubes with its
// gravity settings; and the contact set a broad phase plus the narrow phase find.
#pragma once

#include "dda/collider/Collider.hpp"
#include "dda/collider/ColliderFactory.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"
#include "dda/solver/World.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace dda::testing {

// Corners of the axis-aligned box [lo, hi] [m].
inline std::vector<Vector3> boxPoints(const Vector3& lo, const Vector3& hi) {
	std::vector<Vector3> p;
	for (int i = 0; i < 8; ++i)
		p.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
	return p;
}

inline std::vector<Vector3> orientedBox(const Vector3& centre, const Vector3& half, const Eigen::Matrix3d& R) {
	std::vector<Vector3> points;
	for (int i = 0; i < 8; ++i) {
		const Vector3 local((i & 1 ? 1 : -1) * half.x(), (i & 2 ? 1 : -1) * half.y(), (i & 4 ? 1 : -1) * half.z());
		points.push_back(centre + R * local);
	}
	return points;
}

inline Eigen::Matrix3d randomRotation(std::mt19937& rng) {
	std::uniform_real_distribution<double> unit(0, 1);
	const Vector3 axis = Vector3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
	return Eigen::AngleAxisd(3.2 * unit(rng), axis).toRotationMatrix();
}

// 12 unknowns drawn uniformly from [-1, 1].
inline Vector12 randomUnknowns(std::mt19937& rng) {
	std::uniform_real_distribution<double> u(-1, 1);
	Vector12 D;
	for (int i = 0; i < 12; ++i) D(i) = u(rng);
	return D;
}

// n blocks: slender (up to 15:1, 15 m long) and compact boxes, randomly
// turned, in a 25 m cube so that many touch or nearly touch; about 30% fixed;
// then unit cubes exactly corner on corner and edge on edge.
inline World randomScene(int n, unsigned seed) {
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> unit(0, 1);
	World world;
	Material material;
	for (int k = 0; k < n; ++k) {
		const double length = unit(rng) < 0.5 ? 1 + 14 * unit(rng) : 1 + unit(rng);
		const Vector3 half(0.5 * length, 0.25 + 0.25 * unit(rng), 0.25 + 0.25 * unit(rng));
		const Eigen::Matrix3d R = randomRotation(rng);
		const Vector3 centre(25 * unit(rng), 25 * unit(rng), 25 * unit(rng));
		world.addBlock(orientedBox(centre, half, R), material, unit(rng) < 0.3);
	}
	const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
	world.addBlock(orientedBox(Vector3(30, 0, 0), Vector3(0.5, 0.5, 0.5), I), material, false);
	world.addBlock(orientedBox(Vector3(31, 1, 1), Vector3(0.5, 0.5, 0.5), I), material, false);
	world.addBlock(orientedBox(Vector3(30, 3, 0), Vector3(0.5, 0.5, 0.5), I), material, true);
	world.addBlock(orientedBox(Vector3(31, 3, 1), Vector3(0.5, 0.5, 0.5), I), material, false);
	return world;
}

inline std::vector<Block> blocksOf(const World& world) {
	std::vector<Block> blocks;
	for (int i = 0; i < world.blockCount(); ++i) blocks.push_back(world.block(i));
	return blocks;
}

// A fixed floor and 2 x 2 x `layers` unit cubes, slightly turned, 5 cm
// apart, dropped from a few cm; optionally one more cube `dropHeight` [m]
// above the pile (it arrives while the pile rests).
inline World cubePile(std::unique_ptr<Collider> collider, int layers, double dropHeight, double frictionDeg = 30) {
	const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
	World world;
	world.setCollider(std::move(collider));
	Material rock;
	rock.frictionAngle = frictionDeg * M_PI / 180;
	world.addBlock(orientedBox(Vector3(0, 0, -0.5), Vector3(3, 3, 0.5), I), rock, true);
	std::mt19937 rng(7);
	std::uniform_real_distribution<double> tilt(-0.03, 0.03);
	for (int layer = 0; layer < layers; ++layer)
		for (int k = 0; k < 4; ++k) {
			const Eigen::Matrix3d R = Eigen::AngleAxisd(tilt(rng), Vector3::UnitZ()).toRotationMatrix() *
			                          Eigen::AngleAxisd(tilt(rng), Vector3::UnitX()).toRotationMatrix();
			const Vector3 centre(-0.55 + 1.1 * (k % 2), -0.55 + 1.1 * (k / 2), 0.55 + 1.08 * layer);
			world.addBlock(orientedBox(centre, Vector3(0.5, 0.5, 0.5), R), rock, false);
		}
	if (dropHeight > 0)
		world.addBlock(orientedBox(Vector3(-0.3, -0.2, 0.55 + 1.08 * layers + dropHeight), Vector3(0.5, 0.5, 0.5), I),
		               rock, false);
	return world;
}

// Gravity, 2 ms steps, and DESS's candidate-pair cache on or off.
inline IntegratorSettings gravitySettings(bool reuse) {
	IntegratorSettings settings;
	settings.gravity = Vector3(0, 0, -9.81);
	settings.maxTimeStep = 2e-3;
	settings.reuseCandidatePairs = reuse;
	return settings;
}

// A floor and 12 L's, T's (three or four unit cubes) and cubes, turned at
// random, 2 x 2 per layer 4 m apart (no two overlap: a T reaches 1.7 m from
// its centre), dropped; Young's modulus `young`; `concave` false
// adds every part of an L or T as a convex block of its own. `roofs` puts
// roofs in place of the L's: two parallelepipeds 1 m x 1 m x 0.5 m sharing
// their seam face, each sheared down by 0.2 m away from it, so the top faces
// meet at a ridge (11 degrees) and the bottom ones in a valley: a face's
// plane runs on past the ridge above the other part, outside the block.
inline World randomConcavePile(unsigned seed, bool concave, double young, bool roofs = false,
                               const std::string& collider = "DESS") {
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> unit(0, 1);
	World world;
	Material rock{2600, young, 0.25};
	rock.frictionAngle = 0.4;
	world.addBlock(orientedBox(Vector3(4, 4, -0.5), Vector3(8, 8, 0.5), Matrix3::Identity()), rock, true);
	for (int k = 0; k < 12; ++k) {
		const Vector3 centre(2 + 4 * (k % 2) + 0.3 * unit(rng), 2 + 4 * (k / 2 % 2) + 0.3 * unit(rng),
		                     2 + 3.6 * (k / 4) + 0.3 * unit(rng));
		const Matrix3 R = k % 3 == 2 ? Matrix3(Eigen::AngleAxisd(6.3 * unit(rng), Vector3::UnitZ()).toRotationMatrix())
		                             : Matrix3(randomRotation(rng));
		if (k % 3 == 2) {
			world.addBlock(orientedBox(centre, Vector3(0.5, 0.5, 0.5), R), rock, false);
			continue;
		}
		if (roofs && k % 3 == 0) {
			std::vector<std::vector<Vector3>> parts;
			for (const double side : {-1.0, 1.0}) {
				std::vector<Vector3> corners;
				for (const double x : {0.0, side})
					for (const double y : {-0.5, 0.5})
						for (const double z : {-0.25, 0.25})
							corners.push_back(centre + R * Vector3(x, y, z - 0.2 * std::abs(x)));
				parts.push_back(corners);
			}
			world.addConcaveBlock(parts, rock, false, false);
			continue;
		}
		std::vector<Vector3> offsets = {Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(0, 1, 0)};
		if (k % 3 == 1) offsets.push_back(Vector3(-1, 0, 0));
		std::vector<std::vector<Vector3>> parts;
		for (const Vector3& o : offsets) {
			std::vector<Vector3> corners = boxPoints(o - Vector3(0.5, 0.5, 0.5), o + Vector3(0.5, 0.5, 0.5));
			for (Vector3& x : corners) x = centre + R * x;
			parts.push_back(corners);
		}
		if (concave)
			world.addConcaveBlock(parts, rock, false, k % 2 == 0);
		else
			for (const auto& part : parts) world.addBlock(part, rock, false, k % 2 == 0);
	}
	world.setCollider(makeCollider(collider));
	return world;
}

// The steps randomConcavePile is run with: gravity, 2 ms, one thread,
// average acceleration (beta 1/4, gamma 1/2: the account balances to
// round-off without Shi's numerical damping).
inline IntegratorSettings concavePileSettings() {
	IntegratorSettings settings;
	settings.gravity = Vector3(0, 0, -9.81);
	settings.maxTimeStep = 2e-3;
	settings.threads = 1;
	settings.newmarkGamma = 0.5;
	settings.newmarkBeta = 0.25;
	return settings;
}

// What a broad phase and the narrow phase find: per pair within d0 its
// structural type and entrance feature, (a, b, -1, type, entrance kind,
// entrance feature x 1000 + other), and every sub-contact, (a, b, kind,
// block i is a, feature 1, feature 2).
using ContactSet = std::set<std::tuple<int, int, int, int, int, int>>;

inline DetectionSettings detectionSettings(double d0) {
	DetectionSettings settings;
	settings.contactDistance = d0;
	settings.lengthTolerance = 1e-9;
	return settings;
}

// The narrow phase runs on the sub-units the collider links to each pair
// (MSC), or on all (the others). `work` sums the narrow phase's work.
inline ContactSet contactSet(Collider& collider, const std::vector<Block>& blocks, double d0,
                             BroadPhaseStatistics* statsOut = nullptr, NarrowPhaseWork* work = nullptr) {
	std::vector<std::pair<int, int>> pairs;
	BroadPhaseStatistics stats;
	collider.findPairs(blocks, d0, pairs, stats);
	EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
	EXPECT_TRUE(std::adjacent_find(pairs.begin(), pairs.end()) == pairs.end()) << "pairs are unique";
	EXPECT_EQ(stats.candidatePairs, static_cast<long>(pairs.size()));
	if (statsOut) *statsOut = stats;
	ContactSet out;
	for (int p = 0; p < static_cast<int>(pairs.size()); ++p) {
		const auto [a, b] = pairs[p];
		EXPECT_LT(a, b);
		EXPECT_FALSE(blocks[a].fixed && blocks[b].fixed);
		const auto result =
		    detectPairContacts(BlockGeometry{blocks[a].shape.get(), &blocks[a].vertices, blocks[a].centroid},
		                       BlockGeometry{blocks[b].shape.get(), &blocks[b].vertices, blocks[b].centroid},
		                       detectionSettings(d0), {}, collider.linked(p), work);
		if (!result) continue;
		out.insert({a, b, -1, static_cast<int>(result->type), static_cast<int>(result->entrance.kind),
		            1000 * result->entrance.feature + result->entrance.other});
		for (const SubContact& c : result->contacts)
			out.insert({a, b, static_cast<int>(c.kind), c.firstIsA, c.feature1, c.feature2});
	}
	return out;
}

// A block as the narrow phase alone sees it: topology, corners and their mean
// as the centroid [m]; `internal` marks faces covered by a neighbour (empty:
// none), `cover` their covers (markInternalFaces' depths [m] and planes; empty: unknown).
struct NarrowBlock {
	ConvexPolyhedron shape;
	std::vector<Vector3> vertices;
	Vector3 centroid = Vector3::Zero();
	std::vector<char> internal;
	std::vector<FaceCover> cover;
	BlockGeometry geometry() const {
		const bool any = std::find(internal.begin(), internal.end(), 1) != internal.end();
		return {&shape, &vertices, centroid, any ? &internal : nullptr, nullptr,
		        any && !cover.empty() ? &cover : nullptr};
	}
};


// The index of b's corner at p (within 1e-12 m), -1 when none.
inline int vertexAt(const NarrowBlock& b, const Vector3& p) {
	for (std::size_t v = 0; v < b.vertices.size(); ++v)
		if ((b.vertices[v] - p).norm() < 1e-12) return static_cast<int>(v);
	return -1;
}

// The face of `b` holding all of the given corners (within 1e-12 m), -1 when none.
inline int faceWith(const NarrowBlock& b, const std::vector<Vector3>& points) {
	for (std::size_t f = 0; f < b.shape.faces.size(); ++f) {
		bool all = true;
		for (const Vector3& p : points)
			all = all && std::any_of(b.shape.faces[f].begin(), b.shape.faces[f].end(),
			                         [&](int v) { return (b.vertices[v] - p).norm() < 1e-12; });
		if (all) return static_cast<int>(f);
	}
	return -1;
}

// The convex hull of `points` as a NarrowBlock (no internal faces).
inline NarrowBlock narrowBlock(const std::vector<Vector3>& points) {
	NarrowBlock b;
	b.shape = buildConvexPolyhedron(points);
	b.vertices = b.shape.vertices;
	for (const Vector3& p : points) b.centroid += p;
	b.centroid /= static_cast<double>(points.size());
	b.internal.assign(b.shape.faces.size(), 0);
	return b;
}

// The identity, then `count` random rotations (unit quaternions of Gaussian
// components drawn with `seed`): a placement's closed form is invariant under
// them, so the narrow phase's answer must be too.
inline std::vector<Eigen::Matrix3d> sceneRotations(unsigned seed, int count) {
	std::vector<Eigen::Matrix3d> out{Eigen::Matrix3d::Identity()};
	std::mt19937 rng(seed);
	std::normal_distribution<double> normal(0.0, 1.0);
	for (int k = 0; k < count; ++k) {
		Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
		out.push_back(q.normalized().toRotationMatrix());
	}
	return out;
}

// A pair's entrance and sub-contacts, for failure messages.
inline std::string describePair(const PairContacts& r) {
	std::ostringstream out;
	out << "entrance kind " << r.entrance.kind << " feature " << r.entrance.feature << ", separation "
	    << r.separation << ", " << r.contacts.size() << " sub-contacts:";
	for (const SubContact& c : r.contacts)
		out << "\n  " << (c.kind == ContactKind::VertexFace ? "VF" : "EE") << " i=" << (c.firstIsA ? "A" : "B")
		    << " features " << c.feature1 << "/" << c.feature2 << " gap " << c.gap << " normal "
		    << c.normal.transpose() << " pointI " << c.pointI.transpose();
	return out.str();
}

}  // namespace dda::testing
