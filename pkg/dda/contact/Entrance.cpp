#include "Entrance.hpp"

#include <algorithm>
#include <limits>

namespace dda::narrow {

namespace {

// Two face areas within this fraction of each other tie (dimensionless), so
// identical blocks are ordered by block and face index, not by round-off.
// Rule: above the round-off of an area (~1e-15), below any real difference.
constexpr double kAreaTieRelative = 1e-9;

}  // namespace

Entrance chooseEntrance(const std::vector<FaceCandidate>& faces, const AxisSearch& axes, const Prepared& a,
                        const Prepared& b, double lengthTolerance, double hysteresis, const EntranceFeature& previous) {
	const double best = axes.best();
	if (previous.kind == EntranceFeature::EdgePair && axes.previousEdge.valid &&
	    axes.previousEdge.separation >= best - hysteresis)
		return {previous, axes.previousEdge.separation, true};
	const FaceCandidate* previousFace = nullptr;
	for (const FaceCandidate& c : faces)
		if (c.feature == previous) previousFace = &c;
	if (previousFace && previousFace->separation >= best - hysteresis)
		return {previousFace->feature, previousFace->separation, true};
	if (axes.bestEdge.valid && axes.bestEdge.separation > axes.bestFace + lengthTolerance)
		return {{EntranceFeature::EdgePair, axes.bestEdgeA, axes.bestEdgeB}, axes.bestEdge.separation};
	const FaceCandidate& c = chooseFace(faces, a, b, lengthTolerance, previous);
	return {c.feature, c.separation};
}

const FaceCandidate& chooseFace(const std::vector<FaceCandidate>& faces, const Prepared& a, const Prepared& b,
                                double lengthTolerance, const EntranceFeature& previous) {
	double best = -std::numeric_limits<double>::infinity();
	for (const FaceCandidate& c : faces) best = std::max(best, c.separation);
	const FaceCandidate* chosen = nullptr;
	double chosenArea = 0;
	for (const FaceCandidate& c : faces) {
		if (c.separation < best - lengthTolerance) continue;
		if (c.feature == previous) return c;
		const double area = (c.feature.kind == EntranceFeature::FaceOfA ? a : b).area(c.feature.feature);
		if (!chosen || area > chosenArea * (1 + kAreaTieRelative)) {
			chosen = &c;
			chosenArea = area;
		}
	}
	return *chosen;
}

bool previousLinked(const Prepared& a, const Prepared& b, const EntranceFeature& previous) {
	const auto has = [](const Indices& list, int x) { return std::binary_search(list.begin(), list.end(), x); };
	switch (previous.kind) {
		case EntranceFeature::FaceOfA: return has(a.faceList, previous.feature);
		case EntranceFeature::FaceOfB: return has(b.faceList, previous.feature);
		case EntranceFeature::EdgePair: return has(a.edgeList, previous.feature) && has(b.edgeList, previous.other);
		case EntranceFeature::None: return true;
	}
	return true;
}

}  // namespace dda::narrow
