#include "Distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dda {

namespace {

double clamp01(double x) { return std::min(1.0, std::max(0.0, x)); }

// A unit vector perpendicular to the unit vector u.
Vector3 anyPerpendicular(const Vector3& u) {
	// Cross with the coordinate axis least aligned with u: never a zero result.
	int k = 0;
	if (std::abs(u.y()) < std::abs(u(k))) k = 1;
	if (std::abs(u.z()) < std::abs(u(k))) k = 2;
	return u.cross(Vector3::Unit(k)).normalized();
}

// The closest points of two segments P1 + s a, P3 + t b, s, t in [0, 1], for
// the cases without a unique line solution (parallel or zero-length edges):
// fix s = 0 (or the only value), project, clamp, project back. Always finite.
void closestParametersFallback(const Vector3& a, const Vector3& b, const Vector3& w, double& s, double& t) {
	// w = P3 - P1. Minimise |P1 + s a - P3 - t b| = |s a - t b - w|.
	const double aa = a.squaredNorm(), bb = b.squaredNorm();
	if (aa == 0 && bb == 0) {
		s = t = 0;
		return;
	}
	if (aa == 0) {
		s = 0;
		t = clamp01(-b.dot(w) / bb);
		return;
	}
	if (bb == 0) {
		t = 0;
		s = clamp01(a.dot(w) / aa);
		return;
	}
	// Start from s = 0 (P1), best t, then best s for that t. For parallel
	// segments this gives a pair at the minimal distance.
	s = 0;
	t = clamp01(-b.dot(w) / bb);
	s = clamp01(a.dot(w + t * b) / aa);
	t = clamp01(b.dot(s * a - w) / bb);
}

}  // namespace

VertexFaceResult vertexFaceDistance(const Vector3& p, const std::vector<Vector3>& vertices,
                                    const std::vector<int>& face, double insideTolerance) {
	VertexFaceResult result;
	result.normal = faceNormal(vertices, face);  // validates the face
	Vector3 mean = Vector3::Zero();
	for (int v : face) mean += vertices[v];
	mean /= static_cast<double>(face.size());
	const Vector3& n = result.normal;
	result.distance = n.dot(p - mean);
	result.projection = p - result.distance * n;

	// Inside test in the plane: for a counter-clockwise edge a->b seen from n,
	// the inward in-plane normal is n x (b - a). The component of p along n does
	// not change the dot product, so p itself can be used instead of its
	// projection; differences are taken before products to keep round-off
	// relative to the face size, not to the distance from the origin.
	double margin = std::numeric_limits<double>::infinity();
	for (std::size_t k = 0; k < face.size(); ++k) {
		const Vector3& a = vertices[face[k]];
		const Vector3& b = vertices[face[(k + 1) % face.size()]];
		const Vector3 inward = n.cross(b - a);
		const double length = inward.norm();
		if (!(length > 0)) continue;  // zero-length edge: bounded by its neighbours
		margin = std::min(margin, inward.dot(p - a) / length);
	}
	result.insideMargin = margin;
	result.inside = margin >= -insideTolerance;
	return result;
}

EdgeEdgeResult edgeEdgeDistance(const Vector3& p1, const Vector3& p2, const Vector3& p3, const Vector3& p4,
                                const Vector3& reference, double lengthTolerance, double angleTolerance) {
	EdgeEdgeResult r;
	const Vector3 a = p2 - p1, b = p4 - p3, w = p3 - p1;
	const double la = a.norm(), lb = b.norm();
	const Vector3 cross = a.cross(b);
	const double crossNorm = cross.norm();
	r.degenerate = (la == 0 || lb == 0);
	r.parallel = r.degenerate || crossNorm <= std::sin(angleTolerance) * la * lb;

	if (!r.parallel) {
		// Unique closest points of the infinite lines. With n = a x b and
		// w = s a - t b + lambda n: (w x b).n = s |n|^2 and (w x a).n = t |n|^2
		// (the cross-product form avoids the cancellation of |a|^2|b|^2-(a.b)^2).
		const double nn = crossNorm * crossNorm;
		const double sLine = w.cross(b).dot(cross) / nn;
		const double tLine = w.cross(a).dot(cross) / nn;
		const double sTol = lengthTolerance / la, tTol = lengthTolerance / lb;
		r.interior = sLine >= -sTol && sLine <= 1 + sTol && tLine >= -tTol && tLine <= 1 + tTol;
		if (sLine >= 0 && sLine <= 1 && tLine >= 0 && tLine <= 1) {
			r.s = sLine;
			r.t = tLine;
		} else if (r.interior) {
			r.s = clamp01(sLine);
			r.t = clamp01(tLine);
		} else {
			// Closest segment points lie on a boundary of the (s, t) square; the
			// squared distance is convex, so minimise over the four sides.
			double best = std::numeric_limits<double>::infinity();
			auto consider = [&](double s, double t) {
				const double d2 = (s * a - t * b - w).squaredNorm();
				if (d2 < best) {
					best = d2;
					r.s = s;
					r.t = t;
				}
			};
			for (double s : {0.0, 1.0}) consider(s, clamp01(b.dot(s * a - w) / (lb * lb)));
			for (double t : {0.0, 1.0}) consider(clamp01(a.dot(w + t * b) / (la * la)), t);
		}
		r.normal = cross / crossNorm;
		if (r.normal.dot(reference) < 0) r.normal = -r.normal;
		r.distance = r.normal.dot(w);
	} else {
		closestParametersFallback(a, b, w, r.s, r.t);
		// Normal: perpendicular to the edge direction, towards the other line.
		const bool haveAxis = la > 0 || lb > 0;
		const Vector3 axis = la > 0 ? Vector3(a / la) : lb > 0 ? Vector3(b / lb) : Vector3::Zero();
		const Vector3 offset = w - axis.dot(w) * axis;  // w with its axial part removed
		const Vector3 refPerp = reference - axis.dot(reference) * axis;
		const double offsetNorm = offset.norm(), refNorm = refPerp.norm();
		if (offsetNorm > 0) {
			r.normal = offset / offsetNorm;
		} else if (refNorm > 0) {
			r.normal = refPerp / refNorm;
		} else if (haveAxis) {
			r.normal = anyPerpendicular(axis);
		} else {
			r.normal = Vector3::UnitZ();
		}
		if (r.normal.dot(reference) < 0) r.normal = -r.normal;
		r.distance = r.normal.dot(offset);
	}
	r.closestI = p1 + r.s * a;
	r.closestJ = p3 + r.t * b;
	return r;
}

}  // namespace dda
