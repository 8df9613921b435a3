// detectPairContacts: the narrow phase's four steps (PairDetection.hpp) run in
// order on one pair. Each step has its own file:
//   PreparedBlock    the blocks' per-call view and per-thread buffers;
//   SeparatingAxes   1. face and edge axes, rejection beyond d0;
//   Entrance         2. the entrance feature, with hysteresis;
//   SubContacts      3. vertex-face and edge-edge sub-contacts;
//   StructuralType   4. the structural type;
//   ExactPredicates  the exact signs all of them use.
#include "PairDetection.hpp"

#include "Entrance.hpp"
#include "PreparedBlock.hpp"
#include "SeparatingAxes.hpp"
#include "StructuralType.hpp"
#include "SubContacts.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace dda {

using namespace narrow;

// Performance. The narrow phase runs for every pair the broad phase reports,
// so it avoids work whose result it does not need, without changing any
// result: the bounding boxes are tested before any face plane is built, face
// areas are computed only when a tie between faces needs them, edge data only
// when every face axis passed, per-call buffers are reused per thread (no heap
// allocation in the steady state), signs of triple products of unit normals
// and exact collinearity are settled by a double-precision filter with a
// proven round-off bound before falling back to CGAL's exact predicates, and a
// sub-contact's gap comes from its stencil without the full linearisation.
// Every double result is computed by the same expressions as before.

namespace {
// Whether every axis that may be the pair's entrance lies more than d0
// deeper than the pair's best axis of all. The covered-face rules (internal
// faces, faces opposing one and the edges of one are no entrance) are for a
// block that meets an exposed face of the fixed mass, as one sliding over a
// flush seam does. Here it meets none: it touches the covered block only
// where a corner or edge of it reaches the surface at a junction of held
// blocks, and an entrance that deep measured its sub-contacts against a face
// a block's width away, found or not as the blocks strained by 1e-8 m (each
// time it came back, a compressed spring's energy was added). The pair's own
// contact, as two convex blocks, follows the blocks' motion continuously and
// is no deeper than their penetration (the depth bound, step 3).
bool coveredOnly(const Prepared& a, const Prepared& b, const AxisSearch& axes, double d0) {
	if (!a.internalFaces && !b.internalFaces) return false;
	return axes.best() < axes.deepestBound - d0;
}
}  // namespace

namespace {
// The pair as two plain convex blocks (no face internal, no cover), after a
// full search when it came with linked sub-units (coveredOnly).
bool detectAsPlainBlocks(const BlockGeometry& blockA, const BlockGeometry& blockB, const DetectionSettings& settings,
                         PairContacts& out, const EntranceFeature& previous, const LinkedSubUnits* linked,
                         NarrowPhaseWork* work) {
	if (linked) {
		++work->fullSearches;
		return detectPairContacts(blockA, blockB, settings, out, previous, nullptr, work);
	}
	BlockGeometry plainA = blockA, plainB = blockB;
	plainA.internalFaces = plainB.internalFaces = nullptr;
	plainA.covers = plainB.covers = nullptr;
	return detectPairContacts(plainA, plainB, settings, out, previous, nullptr, work);
}
}  // namespace

bool detectPairContacts(const BlockGeometry& blockA, const BlockGeometry& blockB, const DetectionSettings& settings,
                        PairContacts& out, const EntranceFeature& previous, const LinkedSubUnits* linked,
                        NarrowPhaseWork* work) {
	const double d0 = settings.contactDistance, tol = settings.lengthTolerance;
	NarrowPhaseWork ownWork;
	if (!work) work = &ownWork;

	// Bounding boxes widened by d0.
	Prepared a = prepareBounds(blockA);
	Prepared b = prepareBounds(blockB);
	for (int k = 0; k < 3; ++k) {
		if (b.lower(k) > a.upper(k) + d0 || a.lower(k) > b.upper(k) + d0) return false;
	}
	Scratch& s = scratch();
	prepareFaces(a, s, 0);
	prepareFaces(b, s, 1);
	ensureIdentity(s, a, b);
	prepareSubUnits(a, linked, 0, s, work->subUnitTests);
	prepareSubUnits(b, linked, 1, s, work->subUnitTests);
	const double sinTolerance = std::sin(settings.angleTolerance);

	// 1. Face axes, then the edge axes of the Minkowski difference's faces
	// (SeparatingAxes.hpp): any axis farther than d0 rejects the pair.
	const double hysteresis = std::max(settings.hysteresis, tol);
	std::vector<FaceCandidate>& faces = s.candidates;
	AxisSearch axes;
	if (!searchFaceAxes(a, b, d0, hysteresis, faces, axes)) return false;
	prepareEdges(a, s, 0);
	prepareEdges(b, s, 1);
	if (!searchEdgeAxes(a, b, d0, sinTolerance, previous, s, axes)) return false;
	// Linked sub-units hold every contact feature while the pair penetrates by
	// at most d0 / 2; the linked axes bound the depth from above (the full
	// search's best axis separates at least as much), so a deeper bound sends
	// the pair to the full search.
	if (linked && !(axes.deepestBound >= -0.5 * d0)) {
		++work->fullSearches;
		return detectPairContacts(blockA, blockB, settings, out, previous, nullptr, work);
	}

	// A pair that touches only where covered faces meet the surface is two
	// plain convex blocks (coveredOnly); the full search decides that.
	if (coveredOnly(a, b, axes, d0)) return detectAsPlainBlocks(blockA, blockB, settings, out, previous, linked, work);

	// 2. The entrance feature (Entrance.hpp).
	Entrance entrance = chooseEntrance(faces, axes, a, b, tol, hysteresis, previous);

	// The same bound holds for the entrance itself, which may be the previous
	// one kept by hysteresis a little deeper than the best axis; and a
	// previous entrance that is not linked could have been kept by the full
	// search: both go to the full search too.
	if (linked && (!(entrance.separation >= -0.5 * d0) || !previousLinked(a, b, previous))) {
		++work->fullSearches;
		return detectPairContacts(blockA, blockB, settings, out, previous, nullptr, work);
	}

	// 3. Sub-contacts (SubContacts.hpp), into `out` as into a new PairContacts,
	// but `contacts` keeps its capacity (World reuses its results from chunk to
	// chunk).
	const bool keptPrevious = entrance.keptPrevious;  // findSubContacts may fall back to a face
	findSubContacts(a, b, faces, axes, previous, settings, sinTolerance, s, entrance, out);
	// A previous entrance kept by hysteresis whose contacts all lie deeper
	// than the pair's penetration (or beyond d0) holds nothing: the pair takes
	// the entrance a first contact would (no previous), so that a pair within
	// d0 keeps its sub-contacts.
	if (out.contacts.empty() && keptPrevious)
		return detectPairContacts(blockA, blockB, settings, out, EntranceFeature{}, linked, work);
	out.entrance = entrance.feature;
	out.separation = entrance.separation;
	out.pairSeparation = std::max(axes.deepestBound, axes.nearParallelBest);

	// 4. Structural type from the contact points of the sub-contacts
	// (StructuralType.hpp).
	out.type = classifyPair(a, b, out, d0 + tol, sinTolerance, s);
	return true;
}

std::optional<PairContacts> detectPairContacts(const BlockGeometry& blockA, const BlockGeometry& blockB,
                                               const DetectionSettings& settings, const EntranceFeature& previous,
                                               const LinkedSubUnits* linked, NarrowPhaseWork* work) {
	PairContacts out;
	if (!detectPairContacts(blockA, blockB, settings, out, previous, linked, work)) return std::nullopt;
	return out;
}

}  // namespace dda
