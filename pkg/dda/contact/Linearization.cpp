#include "Linearization.hpp"

#include <cmath>
#include <string>

namespace dda {

namespace {

// Stencil points of block i: Q1 only (vertex-face) or Q1, Q2 (edge-edge).
int pointsOfBlockI(ContactKind kind) { return kind == ContactKind::VertexFace ? 1 : 2; }

bool positiveFinite(double x) { return x > 0 && std::isfinite(x); }

}  // namespace

ContactStencil vertexFaceStencil(const Vector3& vertex, const Vector3& f0, const Vector3& f1, const Vector3& f2) {
	ContactStencil s;
	s.kind = ContactKind::VertexFace;
	s.points = {vertex, f0, f1, f2};
	s.sigma = -1;
	return s;
}

ContactStencil edgeEdgeStencil(const Vector3& p1, const Vector3& p2, const Vector3& p3, const Vector3& p4,
                               const Vector3& reference) {
	ContactStencil s;
	s.kind = ContactKind::EdgeEdge;
	s.points = {p1, p2, p3, p4};
	// n = s0 (a x b)/|a x b| with n . reference >= 0; sigma = -s0.
	const double orientation = (p2 - p1).cross(p4 - p3).dot(reference);
	s.sigma = orientation < 0 ? 1 : -1;
	return s;
}

FaceTriangle chooseFaceTriangle(const std::vector<Vector3>& vertices, const std::vector<int>& face) {
	const std::size_t m = face.size();
	if (m < 3) throw InputError("a face needs at least 3 corners, got " + std::to_string(m));
	for (int v : face) {
		if (v < 0 || static_cast<std::size_t>(v) >= vertices.size()) {
			throw InputError("face refers to vertex " + std::to_string(v) + " but there are " +
			                 std::to_string(vertices.size()) + " vertices");
		}
	}
	FaceTriangle out;
	out.corners = {face[0], face[1], face[2]};
	// Largest |cross|, the first of equal ones. |cross| = sqrt(squared) is
	// taken only for a triangle whose squared norm is above the best's: sqrt
	// rounds monotonically, so any other has |cross| <= the best's and would
	// not replace it (NaN compares false both ways), as with every norm taken.
	double bestNorm = -1, bestSquared = -1;
	for (std::size_t a = 0; a < m; ++a) {
		for (std::size_t b = a + 1; b < m; ++b) {
			for (std::size_t c = b + 1; c < m; ++c) {
				const Vector3& pa = vertices[face[a]];
				const Vector3 cross = (vertices[face[b]] - pa).cross(vertices[face[c]] - pa);
				const double squared = cross.squaredNorm();
				const bool first = c == 2;  // a, b, c = 0, 1, 2
				if (!first && !(squared > bestSquared)) continue;
				const double norm = std::sqrt(squared);  // cross.norm()
				if (first) {  // also the triangle's (corners) cross when none is chosen (NaN)
					out.firstCross = out.cross = cross;
					out.firstCrossNorm = out.crossNorm = norm;
				}
				if (norm > bestNorm) {
					bestNorm = norm;
					bestSquared = squared;
					out.corners = {face[a], face[b], face[c]};  // a < b < c keeps the cyclic order
					out.cross = cross;
					out.crossNorm = norm;
				}
			}
		}
	}
	return out;
}

std::array<int, 3> chooseFaceCorners(const std::vector<Vector3>& vertices, const std::vector<int>& face) {
	return chooseFaceTriangle(vertices, face).corners;
}

double stencilDeterminant(const std::array<Vector3, 4>& q) {
	// Subtracting row 1 from rows 2-4 of the 4x4 determinant leaves the 3x3
	// determinant of the differences, which keeps round-off relative to the
	// stencil's size rather than its distance from the origin.
	return (q[1] - q[0]).dot((q[2] - q[0]).cross(q[3] - q[0]));
}

double stencilArea(ContactKind kind, const std::array<Vector3, 4>& q) {
	if (kind == ContactKind::VertexFace) return (q[2] - q[1]).cross(q[3] - q[1]).norm();
	return (q[1] - q[0]).cross(q[3] - q[2]).norm();
}

LinearizedDistance linearizeNormalDistance(const ContactStencil& stencil, const Vector3& ci, const Vector3& cj) {
	LinearizedDistance out;
	const auto& q = stencil.points;
	out.area = stencilArea(stencil.kind, q);
	out.delta = stencilDeterminant(q);
	if (!positiveFinite(out.area)) return out;
	out.valid = true;
	out.d0 = stencil.sigma * out.delta / out.area;

	// dDelta/dQ_k: the cofactor of row k (one row per point, so Delta is affine
	// in each point); the row of Q1 from translation invariance.
	const Vector3 r2 = q[1] - q[0], r3 = q[2] - q[0], r4 = q[3] - q[0];
	std::array<Vector3, 4> g;
	g[1] = r3.cross(r4);
	g[2] = r4.cross(r2);
	g[3] = r2.cross(r3);
	g[0] = -(g[1] + g[2] + g[3]);

	const double scale = stencil.sigma / out.area;
	const int nI = pointsOfBlockI(stencil.kind);
	for (int k = 0; k < 4; ++k) {
		const bool ofI = k < nI;
		const Vector3 offset = q[k] - (ofI ? ci : cj);
		(ofI ? out.ei : out.ej) += displacementTransposeTimes(offset, g[k], scale);
	}
	return out;
}

std::array<Vector3, 4> movedStencilPoints(const ContactStencil& stencil, const Vector3& ci, const Vector3& cj,
                                          const Vector12& Di, const Vector12& Dj) {
	std::array<Vector3, 4> moved;
	const int nI = pointsOfBlockI(stencil.kind);
	for (int k = 0; k < 4; ++k) {
		const bool ofI = k < nI;
		const Vector3& q = stencil.points[k];
		moved[k] = q + displacementAt(q - (ofI ? ci : cj), ofI ? Di : Dj);
	}
	return moved;
}

std::optional<double> exactNormalDistance(const ContactStencil& stencil, const Vector3& ci, const Vector3& cj,
                                          const Vector12& Di, const Vector12& Dj) {
	const std::array<Vector3, 4> moved = movedStencilPoints(stencil, ci, cj, Di, Dj);
	const double area = stencilArea(stencil.kind, moved);
	if (!positiveFinite(area)) return std::nullopt;
	return stencil.sigma * stencilDeterminant(moved) / area;
}

}  // namespace dda
