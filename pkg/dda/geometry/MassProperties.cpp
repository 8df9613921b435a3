// Volume integrals of a closed, outward-oriented polyhedron by signed
// tetrahedra.
//
// Each face is fanned into triangles (v0, vk, vk+1); each triangle with an apex
// point o spans the signed tetrahedron (o, v0, vk, vk+1). The signed pieces sum
// to the body for any apex. With the apex at the origin of the local
// coordinates, a tetrahedron (0, a, b, c) has
//   volume            V   = a . (b x c) / 6
//   first moment      ∫ x dV     = V (a + b + c) / 4
//   second moment     ∫ x x^T dV = V/20 (a a^T + b b^T + c c^T + s s^T),  s = a + b + c.
// The last one follows from writing x = λa a + λb b + λc c with barycentric
// weights (λo, λa, λb, λc) uniformly distributed on the simplex, for which
// E[λi λj] = (1 + δij) / 20; the apex term vanishes because o = 0.
//
// Two passes keep round-off small for blocks far from the origin:
//   1. volume and centroid, with the apex at the vertex mean (inside a convex
//      block, so all tetrahedra are positive and nothing cancels);
//   2. J, with the apex at the centroid itself, so J = Σ ∫ y y^T dV directly in
//      centroid coordinates y = x - c, with no V c c^T to subtract.
#include "MassProperties.hpp"

#include <Eigen/Geometry>

#include <sstream>
#include <string>

namespace dda {
namespace {

using Matrix3 = Eigen::Matrix3d;

// Number of vertices of the smallest polygon.
constexpr std::size_t kMinFaceVertexCount = 3;

// Calls visit(a, b, c) for every fan triangle of every face, with a, b, c the
// triangle's vertices relative to `apex`.
template <class Visitor>
void forEachFanTriangle(const std::vector<Vector3>& vertices, const std::vector<std::vector<int>>& faces,
                        const Vector3& apex, Visitor&& visit) {
	for (const std::vector<int>& face : faces) {
		const Vector3 a = vertices[face[0]] - apex;
		for (std::size_t k = 1; k + 1 < face.size(); ++k) {
			visit(a, Vector3(vertices[face[k]] - apex), Vector3(vertices[face[k + 1]] - apex));
		}
	}
}

double tetrahedronVolume(const Vector3& a, const Vector3& b, const Vector3& c) { return a.dot(b.cross(c)) / 6.0; }

// ∫ x x^T dV over the tetrahedron (0, a, b, c) of signed volume `volume`.
Matrix3 tetrahedronSecondMoment(double volume, const Vector3& a, const Vector3& b, const Vector3& c) {
	const Vector3 s = a + b + c;
	return volume / 20.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
}

void requireValidFaces(const std::vector<Vector3>& vertices, const std::vector<std::vector<int>>& faces) {
	for (std::size_t f = 0; f < faces.size(); ++f) {
		if (faces[f].size() < kMinFaceVertexCount) {
			throw InputError("face " + std::to_string(f) + " has " + std::to_string(faces[f].size()) +
			                 " vertices, a polygon needs at least " + std::to_string(kMinFaceVertexCount));
		}
		for (int v : faces[f]) {
			if (v < 0 || static_cast<std::size_t>(v) >= vertices.size()) {
				throw InputError("face " + std::to_string(f) + " refers to vertex " + std::to_string(v) + " but there are " +
				                 std::to_string(vertices.size()) + " vertices");
			}
		}
	}
}

Vector3 vertexMean(const std::vector<Vector3>& vertices) {
	Vector3 sum = Vector3::Zero();
	for (const Vector3& v : vertices) sum += v;
	return sum / static_cast<double>(vertices.size());
}

}  // namespace

MassProperties computeMassProperties(const std::vector<Vector3>& vertices, const std::vector<std::vector<int>>& faces) {
	if (vertices.empty()) throw InputError("no vertices: the body has no volume");
	requireValidFaces(vertices, faces);

	MassProperties result;

	// Pass 1: volume and centroid.
	const Vector3 reference = vertexMean(vertices);
	Vector3 firstMoment = Vector3::Zero();  // ∫ (x - reference) dV
	forEachFanTriangle(vertices, faces, reference, [&](const Vector3& a, const Vector3& b, const Vector3& c) {
		const double volume = tetrahedronVolume(a, b, c);
		result.volume += volume;
		firstMoment += volume / 4.0 * (a + b + c);
	});
	if (!(result.volume > 0)) {
		std::ostringstream message;
		message << "the faces enclose volume " << result.volume
		        << ": they must form a closed surface oriented outward";
		throw InputError(message.str());
	}
	result.centroid = reference + firstMoment / result.volume;

	// Pass 2: second moments in centroid coordinates.
	forEachFanTriangle(vertices, faces, result.centroid, [&](const Vector3& a, const Vector3& b, const Vector3& c) {
		result.secondMoment += tetrahedronSecondMoment(tetrahedronVolume(a, b, c), a, b, c);
	});
	return result;
}

}  // namespace dda
