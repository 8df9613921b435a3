// The normal distance of a DDA contact, linearised in the 24 unknowns of the
// two blocks in contact (Wu et al. 2014, Eq. 12-16, derived afresh here).
//
// Stencil. A contact is described by four points Q1..Q4 [m]:
//   - vertex-face: Q1 the vertex of block i; Q2, Q3, Q4 three corners of the
//     face of block j, counter-clockwise seen from outside block j (any three
//     corners of a face of buildConvexPolyhedron taken in the face's cyclic
//     order; chooseFaceCorners gives the best-conditioned choice);
//   - edge-edge: Q1, Q2 the endpoints of the edge of block i; Q3, Q4 those of
//     the edge of block j.
// With the 4x4 determinant
//   Delta = det [[1, Q1], [1, Q2], [1, Q3], [1, Q4]]
//         = (Q2 - Q1) . ((Q3 - Q1) x (Q4 - Q1))      [m^3]
// (six times the signed volume of the tetrahedron Q1..Q4) and
//   S = |(Q3 - Q2) x (Q4 - Q2)|   (vertex-face: twice the triangle's area)
//   S = |(Q2 - Q1) x (Q4 - Q3)|   (edge-edge)             [m^2]
// the signed normal distance is
//   d_n = sigma Delta / S   [m],   sigma = +-1 fixed per contact,
// with the convention of Distance.hpp: d_n > 0 separated, d_n < 0
// penetrating.
//   - vertex-face: Delta = (Q2-Q1).((Q3-Q2)x(Q4-Q2)) = -S n.(Q1 - Q2), n the
//     outward normal of the face's triangle, so sigma = -1 and
//     d_n = n.(Q1 - Q2): the height of the vertex above the face plane.
//   - edge-edge: Delta = (Q2-Q1).((Q3-Q1)x(Q4-Q3)) = -(Q3-Q1).(a x b) with
//     a = Q2-Q1, b = Q4-Q3, so with n = s0 (a x b)/|a x b| and s0 = +-1 chosen
//     by the reference direction (n . reference >= 0, as in edgeEdgeDistance),
//     d_n = n.(Q3 - Q1) = -s0 Delta / S: sigma = -s0.
//
// Linearisation. A point Q_k of block b(k) (centroid c_b) moves by
// u_k = T(Q_k - c_b) D_b (dda::displacementMatrix). Delta is affine in each
// point separately (a determinant with one row per point), so
//   Delta(Q + u) = Delta0 + sum_k g_k . u_k + O(u^2),
//   g_1 = -(g_2 + g_3 + g_4),   g_2 = (Q3-Q1) x (Q4-Q1),
//   g_3 = (Q4-Q1) x (Q2-Q1),    g_4 = (Q2-Q1) x (Q3-Q1),
// and, keeping S at its start-of-step value as DDA does,
//   d_n ~= d0 + e_i . D_i + e_j . D_j,   d0 = sigma Delta0 / S,
//   e_b = (sigma / S) sum_{k in block b} T(Q_k - c_b)^T g_k.
// This is the exact first derivative of d_n only where Delta0 = 0 (the
// contact closed: vertex on the plane, edges meeting). Elsewhere the exact
// derivative has the extra term -sigma Delta0 dS / S^2 = -d0 dS / S, first
// order in the rotation and strain of the face or edges and proportional to
// the gap d0; DDA drops it, so penalty springs act along the start-of-step
// normal (tests/cpp/contact/test_contact_geometry.cpp checks that the difference is
// exactly this term).
#pragma once

#include "dda/block/Displacement.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"

#include <array>
#include <optional>
#include <vector>

namespace dda {

enum class ContactKind { VertexFace, EdgeEdge };

struct ContactStencil {
	ContactKind kind = ContactKind::VertexFace;
	// Q1..Q4 as above [m]; which block each belongs to follows from `kind`.
	std::array<Vector3, 4> points;
	// +1 or -1: d_n = sigma Delta / S.
	double sigma = -1;
};

// Vertex q of block i against the face triangle (f0, f1, f2) of block j,
// counter-clockwise seen from outside block j.
ContactStencil vertexFaceStencil(const Vector3& vertex, const Vector3& f0, const Vector3& f1, const Vector3& f2);

// Edge p1p2 of block i against edge p3p4 of block j, normal oriented by
// `reference` as in edgeEdgeDistance (reference perpendicular to p1p2 x p3p4
// keeps the cross product's own orientation: sigma = -1).
ContactStencil edgeEdgeStencil(const Vector3& p1, const Vector3& p2, const Vector3& p3, const Vector3& p4,
                               const Vector3& reference);

// Three corners of a convex face (indices into `vertices`, counter-clockwise
// seen from outside) spanning the triangle of largest area, returned in the
// face's cyclic order (so still counter-clockwise). A face of
// buildConvexPolyhedron may be planar only to within its tolerance; the
// largest triangle makes the stencil's plane the least sensitive to that.
// Throws InputError for fewer than 3 corners or an index out of range.
std::array<int, 3> chooseFaceCorners(const std::vector<Vector3>& vertices, const std::vector<int>& face);

// chooseFaceCorners' triangle with cross products it computes on the way (the
// same doubles as computing them again): (f1 - f0) x (f2 - f0) of the chosen
// triangle and of the face's first three corners, and their norms.
struct FaceTriangle {
	std::array<int, 3> corners{};
	Vector3 cross = Vector3::Zero();       // [m^2]
	double crossNorm = 0;                  // [m^2]
	Vector3 firstCross = Vector3::Zero();  // [m^2]
	double firstCrossNorm = 0;             // [m^2]
};
FaceTriangle chooseFaceTriangle(const std::vector<Vector3>& vertices, const std::vector<int>& face);

// Delta = det [[1, Q1], [1, Q2], [1, Q3], [1, Q4]] [m^3].
double stencilDeterminant(const std::array<Vector3, 4>& q);
// S of the stencil's kind [m^2].
double stencilArea(ContactKind kind, const std::array<Vector3, 4>& q);

struct LinearizedDistance {
	// False when S is not positive and finite (zero-area face triangle,
	// parallel or zero-length edges): then d0 = 0 and e_i = e_j = 0. Callers
	// should not linearise edge-edge contacts flagged parallel at all.
	bool valid = false;
	double d0 = 0;                    // sigma Delta0 / S [m]
	Vector12 ei = Vector12::Zero();   // d(d_n)/dD_i: [-] translations, [m] rotations and strains
	Vector12 ej = Vector12::Zero();   // d(d_n)/dD_j, same units
	double delta = 0;                 // Delta0 [m^3]
	double area = 0;                  // S at the start of the step [m^2]
};

// Linearises the stencil's normal distance about D_i = D_j = 0; ci, cj are the
// centroids [m] of blocks i and j (the origins of their displacement functions).
LinearizedDistance linearizeNormalDistance(const ContactStencil& stencil, const Vector3& ci, const Vector3& cj);

// Exact d_n = sigma Delta / S after moving every Q_k by T(Q_k - c_b) D_b,
// Delta AND S recomputed from the moved points (for tests and diagnostics).
// Empty when the moved S is not positive and finite.
std::optional<double> exactNormalDistance(const ContactStencil& stencil, const Vector3& ci, const Vector3& cj,
                                          const Vector12& Di, const Vector12& Dj);

// The stencil's points moved by the two blocks' unknowns (linear displacement
// function, as in DDA's contact equations).
std::array<Vector3, 4> movedStencilPoints(const ContactStencil& stencil, const Vector3& ci, const Vector3& cj,
                                          const Vector12& Di, const Vector12& Dj);

}  // namespace dda
