#include "PreparedBlock.hpp"

namespace dda::narrow {

namespace {

// Edge e's data from its corners and its faces' planes (shared as above).
void buildEdge(const std::vector<Vector3>& v, const PolyhedronTopology& shape, const FacePlane* faces, int e,
               EdgeData& d) {
	d.direction = v[shape.edges[e][1]] - v[shape.edges[e][0]];
	d.length = d.direction.norm();
	const auto& ef = shape.edgeFaces[e];
	d.arc = faces[ef[1]].normal.cross(faces[ef[0]].normal);
}

// Bounding box of the corners.
void cornerBounds(const std::vector<Vector3>& v, Vector3& lower, Vector3& upper) {
	lower = upper = v.front();
	for (const Vector3& x : v) {
		lower = lower.cwiseMin(x);
		upper = upper.cwiseMax(x);
	}
}

}  // namespace

// Face f's plane (FacePlane without firstNormal/firstNorm, which the returned
// triangle holds). Both the per-call path (ensurePlane) and
// BlockPlanes::compute use this one function, so a cached plane holds the
// same doubles as one built per call.
FaceTriangle buildFacePlane(const std::vector<Vector3>& v, const std::vector<int>& face, FacePlane& plane) {
	const FaceTriangle triangle = chooseFaceTriangle(v, face);
	plane.corners = triangle.corners;
	const Vector3& f0 = v[plane.corners[0]];
	// The triangle's (f1 - f0) x (f2 - f0), normalized as Eigen's normalized()
	// does: divided by its norm, sqrt(squaredNorm()), when that is > 0 (as the
	// squared norm then is), else unchanged.
	plane.normal = triangle.crossNorm > 0 ? Vector3(triangle.cross / triangle.crossNorm) : triangle.cross;
	plane.side1 = (v[plane.corners[1]] - f0).norm();
	plane.side2 = (v[plane.corners[2]] - f0).norm();
	return triangle;
}

// The normal of a face's first three corners (unnormalised), scored by
// likelySeparatingFace: (v1 - v0) x (v2 - v0), the triangle chooseFaceTriangle
// tries first (its firstCross).
Vector3 firstCornersNormal(const std::vector<Vector3>& v, const std::vector<int>& face) {
	const Vector3& f0 = v[face[0]];
	return (v[face[1]] - f0).cross(v[face[2]] - f0);
}

Scratch& scratch() {
	thread_local Scratch s;
	return s;
}

// Step 0 data: the block and its bounding box.
Prepared prepareBounds(const BlockGeometry& block) {
	Prepared p;
	p.shape = block.shape;
	p.vertices = block.vertices;
	p.centroid = block.centroid;
	p.internalFaces = block.internalFaces;
	p.covers = block.covers;
	p.planes = block.planes;
	if (p.planes) {
		p.lower = p.planes->lower;
		p.upper = p.planes->upper;
	} else {
		cornerBounds(*block.vertices, p.lower, p.upper);
	}
	return p;
}

// Face planes (into the thread's buffer `slot`), each built when first needed
// (ensurePlane): a pair rejected by one face axis builds few of them.
void prepareFaces(Prepared& p, Scratch& s, int slot) {
	const std::size_t count = p.shape->faces.size();
	if (p.planes) {
		p.faces = p.planes->faces.data();
		p.ownFaces = nullptr;
		p.planeReady = nullptr;
	} else {
		s.faces[slot].resize(count);
		s.planeReady[slot].assign(count, 0);
		p.faces = p.ownFaces = s.faces[slot].data();
		p.planeReady = s.planeReady[slot].data();
	}
	s.areas[slot].assign(count, -1.0);
	s.separations[slot].resize(count);
	s.separationReady[slot].assign(count, 0);
	p.areas = s.areas[slot].data();
	p.separations = s.separations[slot].data();
	p.separationReady = s.separationReady[slot].data();
	p.faceTotal = static_cast<int>(count);
}

// Edge data of the edges the pair may use (after prepareSubUnits).
void prepareEdges(Prepared& p, Scratch& s, int slot) {
	if (p.planes) {
		p.edges = p.planes->edges.data();
		return;
	}
	std::vector<EdgeData>& edges = s.edges[slot];
	edges.resize(p.edgeCount());
	for (int e : p.edgeList) {
		const auto& ef = p.shape->edgeFaces[e];
		ensurePlane(p, ef[0]);
		ensurePlane(p, ef[1]);
		buildEdge(*p.vertices, *p.shape, p.faces, e, edges[e]);
	}
	p.edges = edges.data();
}

// planeDistance's exact test, for a point near the plane (out of line).
[[gnu::noinline]] double planeDistanceNearPlane(const Prepared& block, int f, const Vector3& x, const Vector3& offset,
                                                double d) {
	const FacePlane& plane = block.faces[f];
	const Vector3& f0 = block.corner(plane.corners[0]);
	const double scale = offset.norm() + plane.side1 + plane.side2;
	if (std::abs(d) > kRoundoffRelative * scale) return d;
	const Vector3& f1 = block.corner(plane.corners[1]);
	const Vector3& f2 = block.corner(plane.corners[2]);
	const int side = exactOrientation(f0, f1, f2, x);
	if (side == 0) return 0;
	const bool outside = side > 0;
	return (outside == (d > 0)) ? d : 0;
}

// Makes s.identity hold 0 .. n - 1 at least, for both blocks of a pair before
// either's lists point into it.
void ensureIdentity(Scratch& s, const Prepared& a, const Prepared& b) {
	const int largest = std::max({a.cornerCount(), a.edgeCount(), a.faceCount(), b.cornerCount(), b.edgeCount(),
	                              b.faceCount()});
	std::vector<int>& identity = s.identity;
	if (static_cast<int>(identity.size()) >= largest) return;
	identity.resize(largest);
	for (int i = 0; i < largest; ++i) identity[i] = i;
}

// The sub-units block `p` (slot 0: A, 1: B) offers the pair: the linked ones,
// or all (after ensureIdentity). Also points p.tests at the pair's counter.
void prepareSubUnits(Prepared& p, const LinkedSubUnits* linked, int slot, Scratch& s, long& tests) {
	p.tests = &tests;
	const int corners = p.cornerCount(), edges = p.edgeCount(), faces = p.faceCount();
	const std::vector<int>& identity = s.identity;
	if (!linked) {
		p.vertexList = {identity.data(), corners};
		p.edgeList = {identity.data(), edges};
		p.faceList = {identity.data(), faces};
		p.vertexLinked = nullptr;
		return;
	}
	const auto list = [](const SubUnitList& v) { return Indices{v.begin(), static_cast<int>(v.size())}; };
	p.vertexList = list(linked->vertices[slot]);
	p.edgeList = list(linked->edges[slot]);
	p.faceList = list(linked->faces[slot]);
	std::vector<char>& vertexMark = s.vertexLinked[slot];
	vertexMark.assign(corners, 0);
	for (int v : linked->vertices[slot]) vertexMark[v] = 1;
	p.vertexLinked = vertexMark.data();
}

}  // namespace dda::narrow

namespace dda {

void BlockPlanes::compute(const PolyhedronTopology& shape, const std::vector<Vector3>& vertices) {
	const int faceCount = static_cast<int>(shape.faces.size());
	faces.resize(faceCount);
	for (int f = 0; f < faceCount; ++f) {
		FacePlane& plane = faces[f];
		const FaceTriangle triangle = narrow::buildFacePlane(vertices, shape.faces[f], plane);
		plane.firstNormal = triangle.firstCross;  // firstCornersNormal
		plane.firstNorm = triangle.firstCrossNorm;
	}
	const int edgeCount = static_cast<int>(shape.edges.size());
	edges.resize(edgeCount);
	for (int e = 0; e < edgeCount; ++e) narrow::buildEdge(vertices, shape, faces.data(), e, edges[e]);
	narrow::cornerBounds(vertices, lower, upper);
}

}  // namespace dda
