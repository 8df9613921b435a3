// The narrow phase's working view of one block of a pair (Prepared: corners,
// topology, face planes built when first needed, the sub-units it may use)
// and the per-thread buffers behind it (Scratch), shared by the steps of
// detectPairContacts (PairDetection.hpp; internal to pkg/dda/contact). The
// plane distance every step measures with is here, inline: it is the
// innermost loop of the narrow phase. Units: m.
#pragma once

#include "ExactPredicates.hpp"
#include "PairDetection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace dda::narrow {

// Face f's plane (FacePlane without firstNormal/firstNorm, which the returned
// triangle holds). Both the per-call path (ensurePlane) and
// BlockPlanes::compute use this one function, so a cached plane holds the
// same doubles as one built per call.
FaceTriangle buildFacePlane(const std::vector<Vector3>& v, const std::vector<int>& face, FacePlane& plane);

// The normal of a face's first three corners (unnormalised), scored by
// likelySeparatingFace: (v1 - v0) x (v2 - v0), the triangle chooseFaceTriangle
// tries first (its firstCross).
Vector3 firstCornersNormal(const std::vector<Vector3>& v, const std::vector<int>& face);

// A face axis of step 1 with its separation [m]: the entrance candidates.
struct FaceCandidate {
	EntranceFeature feature;
	double separation = 0;
};

// Per-thread buffers reused between calls (detectPairContacts is not
// re-entrant within one thread).
struct Scratch {
	std::vector<FacePlane> faces[2];
	std::vector<double> areas[2];  // < 0 until computed
	std::vector<char> planeReady[2];
	std::vector<double> separations[2];  // face axes' separations
	std::vector<char> separationReady[2];
	std::vector<EdgeData> edges[2];
	std::vector<FaceCandidate> candidates;
	std::vector<double> cornerDistances;
	std::vector<char> cornerDistanceReady;
	std::vector<int> used, faceEdges;
	std::vector<int> outsideCorners;  // faceEntranceContacts: corners measured against their own face
	std::vector<int> edgeFacesB, arcSides;  // the edge axes' Gauss-map test
	std::vector<Vector3> inwardNormalsB;     // minus the normals of edgeFacesB, in its order
	std::vector<std::array<int, 3>> edgesB;  // B's edges for edge axes: edge, its two faces
	std::vector<int> crossingEdges;          // per edge of A: positions in edgesB whose arcs cross
	std::vector<int> faceRows, faceSigns;    // per face of A: its row of Gauss-map signs per edge of B
	std::vector<char> faceMark;
	std::vector<Vector3> pointsA, pointsB;
	std::vector<unsigned char> cornerSides;  // featureOf: per corner, a point's sides of it
	std::vector<char> farEdges;              // featureOf: edges with a point beyond their box
	std::vector<int> identity;  // 0, 1, 2, ...: "every sub-unit"
	std::vector<char> vertexLinked[2];
};
Scratch& scratch();

// A list of sub-unit indices (linked ones, or all of them).
struct Indices {
	const int* first = nullptr;
	int count = 0;
	const int* begin() const { return first; }
	const int* end() const { return first + count; }
};

// A block with the per-call data the narrow phase needs.
struct Prepared {
	const PolyhedronTopology* shape = nullptr;
	const std::vector<Vector3>* vertices = nullptr;
	Vector3 centroid = Vector3::Zero();
	// Face planes: the block's BlockPlanes (every plane built), or the
	// thread's buffer with planeReady flags (built when first needed).
	const FacePlane* faces = nullptr;
	FacePlane* ownFaces = nullptr;  // the buffer, nullptr with BlockPlanes
	char* planeReady = nullptr;     // nullptr with BlockPlanes
	const BlockPlanes* planes = nullptr;
	double* areas = nullptr;
	double* separations = nullptr;
	char* separationReady = nullptr;
	const EdgeData* edges = nullptr;
	int faceTotal = 0;
	Vector3 lower = Vector3::Zero(), upper = Vector3::Zero();  // bounding box [m]
	const std::vector<char>* internalFaces = nullptr;
	const std::vector<FaceCover>* covers = nullptr;  // BlockGeometry::covers
	// The sub-units the narrow phase may use (all, or those a broad phase
	// linked to the pair), and per corner whether it is one of them.
	Indices vertexList, edgeList, faceList;
	const char* vertexLinked = nullptr;  // nullptr: every corner
	long* tests = nullptr;               // vertex-face and edge-edge tests made

	bool linkedVertex(int v) const { return !vertexLinked || vertexLinked[v]; }

	// A face covered by a coplanar face of a neighbouring fixed block: never an
	// entrance, and its edges give no edge axes.
	bool internal(int f) const { return internalFaces && (*internalFaces)[f]; }
	// How far past internal face f its flush neighbour surely reaches [m] (0: unknown).
	double coverDepth(int f) const { return covers ? (*covers)[f].depth : 0.0; }
	// How deep x lies inside internal face f's flush neighbour from the
	// neighbour's other faces [m] (-infinity: unknown).
	double depthInCover(int f, const Vector3& x) const {
		return covers ? (*covers)[f].depthInside(x) : -std::numeric_limits<double>::infinity();
	}
	bool internalEdge(int e) const {
		return internalFaces && ((*internalFaces)[shape->edgeFaces[e][0]] || (*internalFaces)[shape->edgeFaces[e][1]]);
	}

	const Vector3& corner(int v) const { return (*vertices)[v]; }
	int cornerCount() const { return static_cast<int>(vertices->size()); }
	int faceCount() const { return faceTotal; }
	int edgeCount() const { return static_cast<int>(shape->edges.size()); }
	const Vector3& edgeStart(int e) const { return corner(shape->edges[e][0]); }
	const Vector3& edgeEnd(int e) const { return corner(shape->edges[e][1]); }
	// Sum of the outward normals of the two faces sharing edge e: points out
	// of the block at the edge.
	Vector3 edgeOutward(int e) const {
		return faces[shape->edgeFaces[e][0]].normal + faces[shape->edgeFaces[e][1]].normal;
	}
	// The polygon's area [m^2], from the fan about its first corner.
	double area(int f) const {
		double& a = areas[f];
		if (a < 0) {
			const std::vector<int>& face = shape->faces[f];
			const std::vector<Vector3>& v = *vertices;
			Vector3 vectorArea = Vector3::Zero();
			for (std::size_t k = 1; k + 1 < face.size(); ++k)
				vectorArea += (v[face[k]] - v[face[0]]).cross(v[face[k + 1]] - v[face[0]]);
			a = 0.5 * vectorArea.norm();
		}
		return a;
	}
};

// Step 0 data: the block and its bounding box.
Prepared prepareBounds(const BlockGeometry& block);

// Face planes (into the thread's buffer `slot`), each built when first needed
// (ensurePlane): a pair rejected by one face axis builds few of them.
void prepareFaces(Prepared& p, Scratch& s, int slot);

inline void ensurePlane(const Prepared& p, int f) {
	if (!p.planeReady || p.planeReady[f]) return;
	buildFacePlane(*p.vertices, p.shape->faces[f], p.ownFaces[f]);
	p.planeReady[f] = 1;
}

// Edge data of the edges the pair may use (after prepareSubUnits).
void prepareEdges(Prepared& p, Scratch& s, int slot);

// Makes s.identity hold 0 .. n - 1 at least, for both blocks of a pair before
// either's lists point into it.
void ensureIdentity(Scratch& s, const Prepared& a, const Prepared& b);

// The sub-units block `p` (slot 0: A, 1: B) offers the pair: the linked ones,
// or all (after ensureIdentity). Also points p.tests at the pair's counter.
void prepareSubUnits(Prepared& p, const LinkedSubUnits* linked, int slot, Scratch& s, long& tests);

// Signed distance [m] of x from the plane of face f of `block`, > 0 outside.
// Below round-off the sign is decided exactly: a point exactly on the
// triangle's plane gets exactly 0, a point whose double distance has the
// wrong sign gets 0.
double planeDistanceNearPlane(const Prepared& block, int f, const Vector3& x, const Vector3& offset, double d);

inline double planeDistance(const Prepared& block, int f, const Vector3& x) {
	const FacePlane& plane = block.faces[f];
	const Vector3& f0 = block.corner(plane.corners[0]);
	const Vector3 offset = x - f0;
	const double d = plane.normal.dot(offset);
	// The round-off test below, |d| > kRoundoffRelative (|offset| + side1 +
	// side2), first with a cheap upper bound of |offset| in place of its
	// sqrt: the 1-norm, times 1 + 1e-6 to cover its rounding and that of the
	// computed 2-norm (each within a few DBL_EPSILON relative). Every step
	// (+, x by a positive constant) is monotone in floating point, so a |d|
	// above the larger threshold is above the exact test's too, and the
	// function returns d as before; otherwise the exact test decides as before.
	const double normBound = (std::abs(offset.x()) + std::abs(offset.y()) + std::abs(offset.z())) * (1 + 1e-6);
	if (std::abs(d) > kRoundoffRelative * (normBound + plane.side1 + plane.side2)) return d;
	return planeDistanceNearPlane(block, f, x, offset, d);
}

// A threshold for planeDistance's round-off test that holds for every point
// in the box [lower, upper] [m] (the other block's corner box): the test's
// own threshold, kRoundoffRelative (normBound + side1 + side2), with each
// |offset| component replaced by the larger of the box's ends' (|fl(x - f0)|
// <= max(|fl(lower - f0)|, |fl(upper - f0)|) since fl(. - f0) is monotone),
// summed and scaled in the same order, each step monotone in floating point:
// it is at least the threshold of any point of the box.
inline double planeRoundoffBound(const Prepared& block, int f, const Vector3& lower, const Vector3& upper) {
	const FacePlane& plane = block.faces[f];
	const Vector3& f0 = block.corner(plane.corners[0]);
	const auto larger = [&](int k) { return std::max(std::abs(lower(k) - f0(k)), std::abs(upper(k) - f0(k))); };
	const double normBound = (larger(0) + larger(1) + larger(2)) * (1 + 1e-6);
	return kRoundoffRelative * (normBound + plane.side1 + plane.side2);
}

// planeDistance for a point x of the box `bound` was computed for
// (planeRoundoffBound): a |d| above that bound is above x's own threshold,
// where planeDistance returns d (the same expressions); otherwise
// planeDistance decides. The same double either way, with one comparison
// per point instead of a norm bound.
inline double planeDistanceInBox(const Prepared& block, int f, const Vector3& x, double bound) {
	const FacePlane& plane = block.faces[f];
	const Vector3 offset = x - block.corner(plane.corners[0]);
	const double d = plane.normal.dot(offset);
	if (std::abs(d) > bound) return d;
	return planeDistance(block, f, x);
}

// Distance [m] of x from the segment pq.
inline double segmentDistance(const Vector3& x, const Vector3& p, const Vector3& q) {
	const Vector3 d = q - p;
	const double dd = d.squaredNorm();
	const double s = dd > 0 ? std::clamp(d.dot(x - p) / dd, 0.0, 1.0) : 0.0;
	return (x - (p + s * d)).norm();
}

}  // namespace dda::narrow
