// Exact volume integrals of a polyhedron: volume, centroid and the second
// moments about the centroid, J = integral over the body of (x-c)(x-c)^T dV.
// Computed by splitting each face into triangles and each triangle with a
// reference point into a signed tetrahedron, whose moments have closed forms;
// no sampling, exact up to round-off. Units: L^3, L, L^5.
#pragma once

#include "ConvexPolyhedron.hpp"

#include <Eigen/Core>

namespace dda {

struct MassProperties {
	double volume = 0;                           // m^3
	Vector3 centroid = Vector3::Zero();          // m
	Eigen::Matrix3d secondMoment = Eigen::Matrix3d::Zero();  // m^5, about the centroid
};

// Faces must be closed and oriented outward (as buildConvexPolyhedron returns);
// for a convex polygon the fan triangulation is used. Faces from rounded input
// are nearly, not exactly, planar (within kCoplanarRelativeTolerance x size,
// see ConvexPolyhedron.hpp): the fan triangles of neighbouring faces still share
// their edges, so the integrals are those of that closed triangulated surface,
// which differs from the block by at most that tolerance x its surface area.
MassProperties computeMassProperties(const std::vector<Vector3>& vertices,
                                     const std::vector<std::vector<int>>& faces);

}  // namespace dda
