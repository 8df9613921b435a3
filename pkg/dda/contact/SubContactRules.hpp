// The rule families of step 3 (findSubContacts, SubContacts.hpp), one file
// each, and what they share. Internal to the narrow phase: included only by
// the files below, never outside pkg/dda/contact. Units: m.
//   SubContactKernels.cpp  a vertex-face and an edge-edge sub-contact, and
//                          where a point projects on a face
//   OwnEntrance.cpp        a corner against its own entrance face (internal
//                          faces, covered seams, covered ridges)
//   FaceEntrance.cpp       a face entrance's search
//   EdgeEntrance.cpp       an edge entrance: far features, second crossings,
//                          the fallback's corners
//   ParallelEdges.cpp      near-parallel edges that overlap
//   SubContacts.cpp        findSubContacts: the dispatch and the tied faces
// Every family keeps the rule of doc/DESIGN.md (Contacts, item 2): no
// sub-contact is deeper than the pair's penetration, min(s, 0) less the
// length tolerance for s the pair's largest separation over the axes tested.
#pragma once

#include "SubContacts.hpp"

#include <limits>
#include <optional>
#include <vector>

namespace dda::narrow::rules {

// An edge-edge sub-contact of a face entrance pushes within 60 degrees of the
// face's normal (cosine, dimensionless): an edge crossing a face's edge
// steeply has its line distance in the face's plane, a contact of the
// neighbouring face, and its corners' contacts hold the pair along the normal.
inline constexpr double kEdgeNormalMinCosine = 0.5;

// --- SubContactKernels.cpp

// Smallest in-plane distance [m] of x's projection from the lines of face f's
// edges, positive inside the polygon (as vertexFaceDistance's insideMargin).
double insideMargin(const Prepared& block, int f, const Vector3& x);

// Does x's projection on the plane of face f lie within `reach` [m] of the
// polygon (a distance to the polygon, not a margin per edge line)?
bool projectionNearFace(const Prepared& block, int f, const Vector3& x, double reach);

// The stencil's start-of-step normal distance, as linearizeNormalDistance's
// d0 (0 and invalid when S is not positive and finite).
double stencilGap(const ContactStencil& stencil, bool& valid);

// The vertex-face sub-contact of corner `vertex` of block i on face `face` of block j.
SubContact vertexFaceContact(bool firstIsA, const Prepared& blockI, int vertex, const Prepared& blockJ, int face);

// Gap and normal bounds a caller will require of an edge-edge sub-contact;
// checking them before the closest points saves work, not results.
struct EdgeContactLimits {
	double highestGap = std::numeric_limits<double>::infinity();   // [m]
	double deepestGap = -std::numeric_limits<double>::infinity();  // [m]
	const Vector3* direction = nullptr;  // normal . direction >= minCosine when set
	double minCosine = 0;
};

// Edge-edge sub-contact of edge e1 of block i and e2 of block j, or nothing
// when the edges are parallel or their closest points are not strictly inside
// both segments (more than lengthTolerance from every endpoint), or it fails
// `limits`.
std::optional<SubContact> edgeEdgeContact(bool firstIsA, const Prepared& blockI, int e1, const Prepared& blockJ,
                                          int e2, const DetectionSettings& settings, double sinTolerance,
                                          const EdgeContactLimits& limits = {});

// --- OwnEntrance.cpp

// The vertex-face contact of corner q of `block` against its own entrance
// face of `other` (the exposed face q lies farthest above), appended to `out`
// when within `reach` and no deeper than `lowest` (or held at a covered seam).
void ownEntranceContact(const Prepared& block, bool blockIsA, int q, const Prepared& other, double reach,
                        double tolerance, double lowest, std::vector<SubContact>& out);

// --- FaceEntrance.cpp

// Whether edge-edge sub-contact `crossing` lies within `merge` [m] of a
// vertex-face contact in `found` that pushes the same way: that contact's.
bool besideVertexContact(const SubContact& crossing, const std::vector<SubContact>& found, double merge);

// The usable edges of face f of `owner` (edgeList order) into `out`.
void edgesOfFace(const Prepared& owner, int f, std::vector<int>& out);

// Step 3 for a face entrance: face f of `owner` entered by `other`.
void faceEntranceContacts(const Prepared& owner, bool ownerIsA, int f, const Prepared& other, double depthBound,
                          double crossingBound, const DetectionSettings& settings, double sinTolerance, Scratch& s,
                          std::vector<SubContact>& out);

// --- EdgeEntrance.cpp

// An edge entrance whose edges cross (out[0]): what the best face finds away
// from the crossing.
void otherFeaturesOfEdgeEntrance(const Prepared& a, const Prepared& b, const EntranceFeature& face, double depthBound,
                                 double crossingBound, const DetectionSettings& settings, double sinTolerance,
                                 Scratch& s, std::vector<SubContact>& out);

// An edge entrance whose edges cross (out[0]): each entrance edge's second
// crossings with the faces at the other entrance edge.
void crossingsAcrossEntranceFaces(const Prepared& a, const Prepared& b, int edgeA, int edgeB, double crossingBound,
                                  const DetectionSettings& settings, double sinTolerance, Scratch& s,
                                  std::vector<SubContact>& out);

// An edge entrance that fell back to the best face: the two edges' ends
// against their own entrance faces.
void cornersOfEdgeEntrance(const Prepared& a, int edgeA, const Prepared& b, int edgeB, double depthBound,
                           const DetectionSettings& settings, std::vector<SubContact>& out);

// --- ParallelEdges.cpp

// The contact of two edges parallel within the angle tolerance that overlap
// with no other sub-contact pushing the pair apart, or nothing.
std::optional<SubContact> nearParallelEdgeContact(const Prepared& a, int edgeA, const Prepared& b, int edgeB,
                                                  double depth, double tolerance, double lowest,
                                                  const KeptEdgePoint* kept);

// --- SubContacts.cpp

// faceEntranceContacts for entrance face `face` of A or of B, entered by the
// other block.
void entranceFaceContacts(const Prepared& a, const Prepared& b, const EntranceFeature& face, double depthBound,
                          double crossingBound, const DetectionSettings& settings, double sinTolerance, Scratch& s,
                          std::vector<SubContact>& out);

}  // namespace dda::narrow::rules
