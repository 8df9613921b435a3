#include "InitialOverlaps.hpp"

#include "TimeStepControl.hpp"
#include "dda/contact/PairDetection.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dda {

std::vector<InitialOverlap> findInitialOverlaps(const std::vector<const Block*>& blocks, int firstNew,
                                                const IntegratorSettings& settings) {
	std::vector<InitialOverlap> found;
	const int n = static_cast<int>(blocks.size());
	if (firstNew >= n) return found;
	std::vector<Eigen::AlignedBox3d> boxes(n);
	double weight = 0;
	for (int b = 0; b < n; ++b) {
		for (const Vector3& x : blocks[b]->vertices) boxes[b].extend(x);
		if (!blocks[b]->fixed) weight += blocks[b]->mass;
	}
	weight *= settings.gravity.norm();
	// d0 as World::step takes it at the first step after blocks were added.
	const double allowed = TimeStepControl::allowedDisplacement(settings, [&] {
		return TimeStepControl::motionHalfSize(
		    n, [&](int k) -> const std::vector<Vector3>& { return blocks[k]->vertices; },
		    [&](int k) { return blocks[k]->fixed; });
	});
	const double d0 = settings.contactDistance > 0 ? settings.contactDistance : settings.contactDistanceFactor * allowed;

	// Sweep along x: pairs whose boxes overlap (a pair deeper than any
	// tolerance overlaps its boxes).
	std::vector<int> order(n);
	std::iota(order.begin(), order.end(), 0);
	std::sort(order.begin(), order.end(), [&](int a, int b) { return boxes[a].min().x() < boxes[b].min().x(); });
	for (int s = 0; s < n; ++s) {
		for (int t = s + 1; t < n; ++t) {
			int a = order[s], b = order[t];
			if (boxes[b].min().x() > boxes[a].max().x()) break;
			if (a > b) std::swap(a, b);
			if (b < firstNew || (blocks[a]->fixed && blocks[b]->fixed) || !boxes[a].intersects(boxes[b])) continue;
			// Parts of one concave block (Block::body; the list is the world's blocks first, in order).
			const int bodyA = blocks[a]->body < 0 ? a : blocks[a]->body, bodyB = blocks[b]->body < 0 ? b : blocks[b]->body;
			if (bodyA == bodyB) continue;
			const Block& A = *blocks[a];
			const Block& B = *blocks[b];
			DetectionSettings detection;
			detection.contactDistance = 0;
			detection.lengthTolerance =
			    kDefaultRelativeLengthTolerance * std::max(boxes[a].diagonal().norm(), boxes[b].diagonal().norm());
			const auto pair = detectPairContacts(BlockGeometry{A.shape.get(), &A.vertices, interiorPoint(A)},
			                                     BlockGeometry{B.shape.get(), &B.vertices, interiorPoint(B)}, detection);
			if (!pair || pair->separation >= 0) continue;
			const double kn = settings.contactPenaltyFactor * std::min(A.material.young * blocks[bodyA]->size,
			                                                           B.material.young * blocks[bodyB]->size);
			const double tolerance =
			    std::min(d0, std::max(2 * weight / kn, kInitialOverlapRelative * std::max(A.size, B.size)));
			if (-pair->separation > tolerance) found.push_back({a, b, -pair->separation, tolerance});
		}
	}
	std::sort(found.begin(), found.end(), [](const InitialOverlap& x, const InitialOverlap& y) {
		return x.depth != y.depth ? x.depth > y.depth : std::make_pair(x.blockA, x.blockB) < std::make_pair(y.blockA, y.blockB);
	});
	return found;
}

}  // namespace dda
