#include "InternalFaces.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace dda {

bool insideFacePolygon(const Vector3& x, const std::vector<Vector3>& vertices, const std::vector<int>& face,
                       const Vector3& n, double tolerance) {
	for (std::size_t k = 0; k < face.size(); ++k) {
		const Vector3& p = vertices[face[k]];
		const Vector3& q = vertices[face[(k + 1) % face.size()]];
		const Vector3 inward = n.cross(q - p);
		const double length = inward.norm();
		if (length > 0 && (x - p).dot(inward) < -tolerance * length) return false;
	}
	return true;
}

double FaceCover::depthInside(const Vector3& x) const {
	if (planes.empty()) return -std::numeric_limits<double>::infinity();
	double depth = std::numeric_limits<double>::infinity();
	for (const Eigen::Vector4d& p : planes) depth = std::min(depth, p.w() - p.head<3>().dot(x));
	return depth;
}

namespace {
// The shortest chord [m] of convex body `cover` along unit direction d from
// the corners of `face` (corners of `vertices` on cover's surface, on the face
// that covers it): how far each reaches into `cover` before it leaves through
// a face plane that d points out of, the least over the corners (>= 0).
double coverDepth(const std::vector<Vector3>& vertices, const std::vector<int>& face, const PlacedPolyhedron& cover,
                  const Vector3& d) {
	const std::vector<Vector3>& v = *cover.vertices;
	double depth = std::numeric_limits<double>::infinity();
	for (const std::vector<int>& k : cover.shape->faces) {
		const Vector3 n = faceNormal(v, k);
		const double along = n.dot(d);
		if (!(along > 0)) continue;
		for (int c : face) depth = std::min(depth, std::max(0.0, n.dot(v[k[0]] - vertices[c])) / along);
	}
	return std::isfinite(depth) ? depth : 0.0;
}

// The cover of `face` (of `vertices`, outward normal n) by body `cover`,
// whose face `covering` lies on it: see FaceCover.
FaceCover faceCover(const std::vector<Vector3>& vertices, const std::vector<int>& face, const PlacedPolyhedron& cover,
                    int covering, const Vector3& n) {
	FaceCover out;
	out.depth = coverDepth(vertices, face, cover, n);
	const std::vector<Vector3>& v = *cover.vertices;
	for (std::size_t k = 0; k < cover.shape->faces.size(); ++k) {
		if (static_cast<int>(k) == covering) continue;
		const Vector3 m = faceNormal(v, cover.shape->faces[k]);
		out.planes.emplace_back(m.x(), m.y(), m.z(), m.dot(v[cover.shape->faces[k][0]]));
	}
	return out;
}

// Marks the faces of bodies a and b that cover each other (see markInternalFaces),
// and with cover vectors their covers (the deepest when several bodies cover a face).
void markCoveredFaces(const PlacedPolyhedron& A, const PlacedPolyhedron& B, double tolerance,
                      double parallelAngleTolerance, std::vector<char>& internalA, std::vector<char>& internalB,
                      std::vector<FaceCover>* coverA, std::vector<FaceCover>* coverB) {
	const std::vector<Vector3>& verticesA = *A.vertices;
	const std::vector<Vector3>& verticesB = *B.vertices;
	for (std::size_t f = 0; f < A.shape->faces.size(); ++f) {
		const Vector3 nf = faceNormal(verticesA, A.shape->faces[f]);
		const Vector3& pf = verticesA[A.shape->faces[f][0]];
		for (std::size_t g = 0; g < B.shape->faces.size(); ++g) {
			const Vector3 ng = faceNormal(verticesB, B.shape->faces[g]);
			if (nf.dot(ng) > -1 + parallelAngleTolerance * parallelAngleTolerance) continue;
			bool coplanar = true;
			for (int v : B.shape->faces[g]) coplanar = coplanar && std::abs(nf.dot(verticesB[v] - pf)) <= tolerance;
			if (!coplanar) continue;
			bool fCovered = true, gCovered = true;
			for (int v : A.shape->faces[f])
				fCovered = fCovered && insideFacePolygon(verticesA[v], verticesB, B.shape->faces[g], ng, tolerance);
			for (int v : B.shape->faces[g])
				gCovered = gCovered && insideFacePolygon(verticesB[v], verticesA, A.shape->faces[f], nf, tolerance);
			if (fCovered) internalA[f] = 1;
			if (gCovered) internalB[g] = 1;
			if (fCovered && coverA) {
				FaceCover c = faceCover(verticesA, A.shape->faces[f], B, static_cast<int>(g), nf);
				if ((*coverA)[f].planes.empty() || c.depth > (*coverA)[f].depth) (*coverA)[f] = std::move(c);
			}
			if (gCovered && coverB) {
				FaceCover c = faceCover(verticesB, B.shape->faces[g], A, static_cast<int>(f), ng);
				if ((*coverB)[g].planes.empty() || c.depth > (*coverB)[g].depth) (*coverB)[g] = std::move(c);
			}
		}
	}
}
}  // namespace

void markInternalFaces(const std::vector<PlacedPolyhedron>& bodies, double relativeLengthTolerance,
                       double parallelAngleTolerance, std::vector<std::vector<char>>& internal,
                       std::vector<std::vector<FaceCover>>* covers) {
	internal.assign(bodies.size(), {});
	if (covers) covers->assign(bodies.size(), {});
	std::vector<int> given;
	std::vector<Eigen::AlignedBox3d> boxes(bodies.size());
	for (std::size_t b = 0; b < bodies.size(); ++b) {
		if (!bodies[b].shape) continue;
		given.push_back(static_cast<int>(b));
		internal[b].assign(bodies[b].shape->faces.size(), 0);
		if (covers) (*covers)[b].assign(bodies[b].shape->faces.size(), FaceCover{});
		for (const Vector3& x : *bodies[b].vertices) boxes[b].extend(x);
	}
	std::sort(given.begin(), given.end(), [&](int a, int b) { return boxes[a].min().x() < boxes[b].min().x(); });
	for (std::size_t i = 0; i < given.size(); ++i) {
		const int a = given[i];
		for (std::size_t j = i + 1; j < given.size(); ++j) {
			const int b = given[j];
			const double tolerance =
			    relativeLengthTolerance * std::max(boxes[a].diagonal().norm(), boxes[b].diagonal().norm());
			if (boxes[b].min().x() > boxes[a].max().x() + tolerance) break;
			Eigen::AlignedBox3d grown = boxes[a];
			grown.min().array() -= tolerance;
			grown.max().array() += tolerance;
			if (!grown.intersects(boxes[b])) continue;
			markCoveredFaces(bodies[a], bodies[b], tolerance, parallelAngleTolerance, internal[a], internal[b],
			                 covers ? &(*covers)[a] : nullptr, covers ? &(*covers)[b] : nullptr);
		}
	}
}

}  // namespace dda
