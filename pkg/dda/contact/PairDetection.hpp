// Narrow phase of one pair of convex blocks: is the pair within the contact
// distance, what is its structural contact type (Wu et al. 2014, Table 1), and
// which vertex-face and edge-edge sub-contacts represent it.
//
// Method: separating axes, then the entrance feature.
//   0. Early out: the corners' bounding boxes, widened by d0, do not overlap.
//   1. Separation along every candidate axis: the outward normal of each face
//      of either block (separation = smallest signed distance of the other
//      block's corners from the plane of the face's chooseFaceCorners
//      triangle, the plane every vertex-face gap uses) and the cross product
//      of each non-parallel edge pair whose arcs cross on the Gauss map (a
//      face of the Minkowski difference; n oriented out of A at its edge,
//      separation = n . (point on B's edge - point on A's edge)). For convex
//      blocks the largest separation is minus the least penetration depth
//      when they overlap, and a lower bound of their distance when apart
//      (equal to it unless the closest features are two corners or a corner
//      and an edge). A pair with an axis farther than d0, or with bounding
//      boxes farther than d0 apart, has no contact: both imply a distance
//      above d0, so a pair within d0 is never missed.
//   2. The axis of largest separation is the entrance feature: the face the
//      other block's corners enter, or the crossing edges. In order:
//        - the previous step's entrance feature while its separation stays
//          within max(hysteresis, lengthTolerance) of the best axis (Shi's
//          rule that a contact keeps its entrance face);
//        - an edge axis only when it beats the best face by more than
//          lengthTolerance (faces win ties);
//        - among faces within lengthTolerance of the best: the larger area
//          (equal to a relative 1e-9), then A before B, then the lower face
//          index (deterministic).
//      Internal faces (a flush fixed neighbour, or another part of the same
//      concave block, covers them), faces opposing one and edges of one are
//      no entrance. But a pair whose best eligible axis lies more than d0
//      below its best axis of all touches no exposed face: it meets only
//      where a corner or edge of the covered block reaches the surface at a
//      junction of held blocks. It is detected as two plain convex blocks
//      (no face internal). Against an eligible face that deep its
//      sub-contacts came and went as the blocks strained by 1e-8 m.
//   3. Sub-contacts. "Within d0" below means within d0 + lengthTolerance (a
//      face is planar only to within its tolerance, so a corner touching it
//      may lie that far off its triangle's plane). A face entrance F of block
//      R, normal n, entered by the other block I gives
//        - vertex-face F <- P for each corner P of I within d0 of F's plane
//          whose projection lies within d0 of F (a corner just past F's
//          edge or corner is a vertex-edge or vertex-vertex contact, entered
//          through F); but a corner below F's plane that lies outside R,
//          past an exposed face of R and past an edge of F along which none
//          of its own edges runs (within the angle tolerance), is measured
//          against its own entrance face of R instead, as the corners Q
//          below are: its gap is then positive (outsideBeyondFaceEdge,
//          FaceEntrance.cpp: no overlap at a corner outside R to push on);
//          and so is a corner of I within d0 of F's plane that is not F's
//          (its projection more than d0 from F, or deeper below the plane
//          than the pair's penetration): a corner over a face of R beside
//          F;
//        - vertex-face G <- Q for each corner Q of F within d0 of I, G the
//          face of I of largest signed distance of Q (Q's own entrance face),
//          Q's projection within d0 of G, and Q not within
//          cornerMergeDistance of a corner P already used (corners that
//          coincide, to round-off or to the small strains of the blocks
//          since they met, give one contact, not two opposed ones);
//        - edge-edge for each edge of I crossing an edge of F with both
//          closest points more than lengthTolerance inside the segments (a
//          crossing at an endpoint is a vertex contact), non-parallel, its
//          gap within d0, its point on I's edge within d0 of F's plane, its
//          normal within 60 degrees of n and its gap no deeper than the
//          pair's penetration (to lengthTolerance; an edge piercing F steeply
//          near F's boundary has its line distance in F's plane and would
//          push sideways by an unrelated depth); and not within
//          cornerMergeDistance of a vertex-face contact above whose normal
//          is within ~25 degrees of its own (offset squares cross each
//          other's edges right beside a corner that already has its contact;
//          a crossing next to a corner with no contact, or pushing another
//          way, stays).
//      No sub-contact is deeper than the pair's penetration: its gap is at
//      least min(s, 0) - lengthTolerance, s the entrance axis's separation
//      (the pair's best axis, or the previous entrance kept by hysteresis);
//      an edge crossing's also no deeper than the axes of edge pairs parallel
//      within the angle tolerance allow (they are no entrance, and their
//      contact is the vertex contacts at their ends, measured along the
//      entrance face). A face entrance that finds no sub-contact gives way
//      to the next face tied with the best (within lengthTolerance) that
//      finds some.
//      A translation of the penetration depth separates the blocks and moves
//      any gap by at most that depth, so a deeper gap is no contact.
//      Last, a pair that overlaps (its largest separation, near-parallel edge
//      axes included, below -lengthTolerance) with no sub-contact of
//      negative gap gets the contact of its near-parallel edge pair of
//      largest separation: the point of either edge deepest inside the other
//      block (the deeper of the two) against that point's own entrance face,
//      a vertex-face stencil keyed as the two edges' edge-edge contact
//      (nearParallelEdgeContact, ParallelEdges.cpp: two edges crossing at an
//      angle below the tolerance with the ends of both outside the other
//      block overlap at no corner, and have no crossing contact).
//      An edge entrance gives its edge-edge sub-contact (block i = A), or
//      falls back to the best face when the two edges do not cross strictly
//      inside; the depth bound then stays the edge axis's (the face's own
//      separation may be a block's width deep), and each end of the two
//      edges within d0 adds its vertex-face contact against its own entrance
//      face (the closest features are then a corner and an edge, which the
//      face alone may not see). With the crossing, the best face (chosen as in step 2) adds
//      the sub-contacts it finds by the rules above away from the crossing:
//      a block rocking on a crossing near one corner can have its far
//      corner within d0 as well, and with the crossing alone that corner
//      would enter the other block unopposed. What the face finds at the
//      crossing (the same edges, or a point within cornerMergeDistance of
//      it) is left to the crossing. And where either entrance edge runs on
//      across a face at the other entrance edge, its crossings with that
//      face's other edges are edge-edge sub-contacts by the face-entrance
//      rules above (edge of the crossing block as i, within d0, normal
//      within 60 degrees of that face's, no deeper than the bound, not
//      beside a vertex contact or the entrance crossing): the second point
//      of an edge lying across a face, which the best face finds only when
//      it is that face (crossingsAcrossEntranceFaces, EdgeEntrance.cpp).
//      Edge-edge stencils take as reference direction (from block i
//      towards block j) the sum of the outward normals of the faces at i's
//      edge minus that at j's edge.
//   4. Structural type from the contact features: on each block, the points
//      of its sub-contacts (pointI or pointJ) lie within d0 + lengthTolerance
//      of one corner (vertex), else of one edge (edge), else span a face.
//      Without sub-contacts, the corners of each block within that tolerance
//      of its extreme along the entrance normal are used instead. The
//      entrance normal alone would not do: in an exact corner-on-corner
//      placement it is a face normal, whose support is a whole face.
//      Two edges are parallel when their cross product is exactly zero
//      (CGAL exact predicate) or within the angle tolerance.
// Signs that decide topology (which side of a face plane a corner is on when
// its double distance is below round-off; whether two edges meet exactly;
// whether Gauss-map arcs cross) use CGAL's exact predicates; distances are
// doubles. Exact placements (corner on corner, on an edge, on a face; edges
// crossing or collinear; coplanar faces) are touching with d0 = 0.
//
// Geometry only: blocks are given as vertex arrays plus topology. Units: m.
#pragma once

#include "Distance.hpp"
#include "Linearization.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"
#include "dda/geometry/InternalFaces.hpp"
#include "dda/geometry/SubUnits.hpp"

#include <array>
#include <optional>
#include <vector>

namespace dda {

// The seven structural contact types of Table 1.
enum class ContactType {
	VertexVertex,
	VertexEdge,
	VertexFace,
	EdgeEdgeCrossing,
	EdgeEdgeParallel,
	EdgeFace,
	FaceFace,
};
const char* contactTypeName(ContactType type);  // "VV", "VE", "VF", "EE", "EEp", "EF", "FF"

// A face's plane as the narrow phase uses it: the chooseFaceCorners triangle
// (counter-clockwise seen from outside), its unit normal, the lengths of the
// triangle's sides at f0, and the (unnormalised) normal of the face's first
// three corners with its length (likeliest separating face, step 1).
struct FacePlane {
	std::array<int, 3> corners{};
	Vector3 normal = Vector3::UnitZ();
	double side1 = 0, side2 = 0;                // |f1 - f0|, |f2 - f0| [m]
	Vector3 firstNormal = Vector3::UnitZ();     // (v1 - v0) x (v2 - v0) [m^2]
	double firstNorm = 1;                       // |firstNormal| [m^2]
};

// An edge: its direction (end - start), its length, and the cross product of
// the outward normals of its two faces (second x first), the great circle of
// its Gauss-map arc.
struct EdgeData {
	Vector3 direction = Vector3::Zero();  // [m]
	double length = 0;                    // [m]
	Vector3 arc = Vector3::Zero();        // dimensionless
};

// A block's face planes, edge data and bounding box, computed once for its
// current corners and shared by every pair the block is in (World fills one
// per block of a candidate pair before its parallel pair loop; the pair loop
// only reads them). The values are those the narrow phase computes per pair
// without it (same expressions), so results do not depend on whether it is
// given. Valid until the block's corners change.
struct BlockPlanes {
	std::vector<FacePlane> faces;
	std::vector<EdgeData> edges;
	Vector3 lower = Vector3::Zero(), upper = Vector3::Zero();  // bounding box of the corners [m]
	void compute(const PolyhedronTopology& shape, const std::vector<Vector3>& vertices);
};

// A block as the narrow phase sees it: current corners [m] and topology.
struct BlockGeometry {
	const PolyhedronTopology* shape = nullptr;     // faces, edges, edgeFaces
	const std::vector<Vector3>* vertices = nullptr;  // current corners [m]
	Vector3 centroid = Vector3::Zero();            // [m]
	// Optional, per face: 1 for a face fully covered by a coplanar, opposed
	// face of a neighbouring fixed block (a flush joint). Such a face is not
	// a free surface: it still rejects pairs whose separation it proves and
	// bounds their penetration, but is never an entrance face, and the axes
	// of its edges reject and bound as well but are no entrance. Without
	// this, a block sliding across the joint meets the covered side face as a
	// "ghost" obstacle.
	const std::vector<char>* internalFaces = nullptr;
	// Optional: the block's planes for its current corners (BlockPlanes); when
	// absent the narrow phase builds what it needs per call.
	const BlockPlanes* planes = nullptr;
	// Optional, per face (with internalFaces): what covers an internal face
	// (markInternalFaces' FaceCover: how far past its plane the flush
	// neighbour surely reaches over the whole face [m], and the neighbour's
	// other face planes). A corner of the other block just past such a face,
	// inside that reach, is inside the fixed mass, at the seam of the two
	// blocks (ownEntranceContact).
	const std::vector<FaceCover>* covers = nullptr;
};

// Which feature is the pair's entrance feature (step 2).
struct EntranceFeature {
	enum Kind { None, FaceOfA, FaceOfB, EdgePair } kind = None;
	int feature = -1;  // face index (FaceOfA/FaceOfB) or edge of A (EdgePair)
	int other = -1;    // edge of B (EdgePair)
	bool operator==(const EntranceFeature& o) const {
		return kind == o.kind && feature == o.feature && other == o.other;
	}
};

// The pair's near-parallel edge contact of the last step (ParallelEdges.cpp,
// nearParallelEdgeContact): the edge its point lies on (of block A when onA,
// else of B), the other block's edge, and where that point ended the step
// [m]. edge = -1: none.
struct KeptEdgePoint {
	bool onA = true;
	int edge = -1, otherEdge = -1;
	Vector3 point = Vector3::Zero();
};

struct DetectionSettings {
	double contactDistance = 0;  // d0 [m], >= 0
	double lengthTolerance = 0;  // [m], > 0: coincident corners, on-segment, inside-face tests
	double angleTolerance = kDefaultParallelAngleTolerance;  // [rad], parallel edges
	// The previous entrance feature is kept while its separation is within
	// this of the best axis [m] (rule: 0.1 x d0; lengthTolerance is used when
	// smaller).
	double hysteresis = 0;
	// Two corners of the two blocks closer than this [m] are one contact
	// point (rule: 1e-3 x the smaller block's bounding-box diagonal, far above
	// the strain-driven drift of corners that started coincident, far below
	// the block's own features); lengthTolerance is used when larger.
	double cornerMergeDistance = 0;
	// Per pair: its near-parallel edge contact of the last step, whose point
	// the contact keeps while it is at least half as deep as the deepest.
	KeptEdgePoint keptEdgePoint;
};

// One vertex-face or edge-edge sub-contact. Blocks are called A and B (the
// pair's order); `first` is the block owning the vertex (vertex-face) or edge 1
// (edge-edge), i.e. block i of the stencil, the other is block j.
struct SubContact {
	ContactKind kind = ContactKind::VertexFace;
	bool firstIsA = true;  // block i of the stencil is A (else B)
	// vertex-face: feature1 = vertex of block i, feature2 = face of block j;
	// edge-edge:   feature1 = edge of block i,   feature2 = edge of block j.
	int feature1 = -1, feature2 = -1;
	// Start-of-step stencil (vertex-face: the face's chooseFaceCorners triangle,
	// so the gap below is exactly linearizeNormalDistance's d0). Its kind is
	// `kind` except for the contact of two near-parallel edges (step 3, last
	// rule): kind EdgeEdge, stencil VertexFace (pointI, a point of edge i,
	// against a face of block j), normal that face's.
	ContactStencil stencil;
	double gap = 0;  // signed normal distance [m], > 0 apart, < 0 penetrating
	// Unit normal pointing from block j towards block i: the direction of the
	// push a compressed contact gives block i. vertex-face: the outward normal
	// of block j's face; edge-edge: minus the stencil's n. For both kinds
	// gap = normal . (pointI - pointJ).
	Vector3 normal = Vector3::UnitZ();
	Vector3 pointI = Vector3::Zero();  // contact point on block i's feature [m]
	Vector3 pointJ = Vector3::Zero();  // its counterpart on block j's feature [m]
};

struct PairContacts {
	ContactType type = ContactType::VertexFace;
	EntranceFeature entrance;
	double separation = 0;              // of the entrance axis [m], <= d0
	// The largest separation over every axis tested (face normals, crossing
	// edge pairs, near-parallel ones too) [m]: > 0 when the blocks are apart
	// (a lower bound of their distance), else minus their penetration depth
	// or less. The entrance may lie deeper (its rules prefer faces, and a
	// corner by an edge takes a face), so only this one tells apart from
	// overlapping.
	double pairSeparation = 0;
	Vector3 normal = Vector3::UnitZ();  // entrance normal, unit, from A towards B
	std::vector<SubContact> contacts;   // may be empty (e.g. corners hanging past a face)
};

// The pair's contacts, or nothing when the blocks are farther apart than
// settings.contactDistance. `previous` is the pair's entrance feature of the
// last step (None when new). Never returns NaN; throws nothing for valid
// blocks of buildConvexPolyhedron.
//
// `linked` (optional): the sub-units a broad phase linked to the pair (MSC).
// Then only linked faces give face axes, only linked edge pairs give edge
// axes, and only linked corners and edges make sub-contacts; a face axis still
// measures all of the other block's corners (a middle slab of a log has no
// corner of its own, and a separation from part of a block would reject
// pairs that touch). Each feature of a contact within d0 lies within
// sqrt(2) (d0 + lengthTolerance) of the other block, so it is linked when the
// pair penetrates by at most d0 / 2 (MSCCollider.cpp gives the bound); a pair
// whose linked axes show a deeper penetration is searched again with every
// sub-unit. The result equals the unrestricted search's (tested on every step
// of random, slender and paper scenes).
// `work` (optional) is increased by what the call did.
struct NarrowPhaseWork {
	// Vertex-face plane tests plus edge-edge tests the search covers: a face
	// axis counts every corner of the other block, also when it stops early.
	long subUnitTests = 0;
	long fullSearches = 0;  // linked pairs searched again with every sub-unit
};
std::optional<PairContacts> detectPairContacts(const BlockGeometry& a, const BlockGeometry& b,
                                               const DetectionSettings& settings,
                                               const EntranceFeature& previous = {},
                                               const LinkedSubUnits* linked = nullptr, NarrowPhaseWork* work = nullptr);
// The same into `out`: true with every field of `out` set as the form above
// returns it, false (`out` unspecified) when the blocks are farther apart.
// `out.contacts` is cleared, not reallocated: a caller that reuses its
// PairContacts (World, from pair to pair) allocates only when a pair has more
// sub-contacts than its vector ever held.
bool detectPairContacts(const BlockGeometry& a, const BlockGeometry& b, const DetectionSettings& settings,
                        PairContacts& out, const EntranceFeature& previous = {}, const LinkedSubUnits* linked = nullptr,
                        NarrowPhaseWork* work = nullptr);

}  // namespace dda
