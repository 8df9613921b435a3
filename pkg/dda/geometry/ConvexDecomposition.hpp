// A closed non-convex surface split into convex parts (concaveBlock(surface=...)):
// CGAL's Nef polyhedra in exact arithmetic and convex_decomposition_3, which
// cuts the solid along planes through its reflex edges. Geometry only; m.
#pragma once

#include "dda/core/Types.hpp"

#include <array>
#include <vector>

namespace dda {

// The convex parts [m] (corner lists) of the solid bounded by `triangles`
// (indices into `points`), a closed, oriented or not, manifold surface
// without self-intersections. The parts come from CGAL's
// convex_decomposition_3 on the exact solid; their corners are the exact
// vertices rounded to double (a vertex two parts share rounds the same way in
// both), less the points on a part's edges or faces that are no corner of it
// (hullCorners). They fill the solid and meet face to face, not always on
// whole faces: conformParts makes them match. Throws InputError naming the
// problem: NaN or inf, a triangle index out of range or repeated, a surface
// that is not one closed manifold (the number of border edges), one that
// intersects itself, or one that encloses no volume.
std::vector<std::vector<Vector3>> convexDecomposition(const std::vector<Vector3>& points,
                                                      const std::vector<std::array<int, 3>>& triangles);

}  // namespace dda
