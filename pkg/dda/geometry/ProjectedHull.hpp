// Area of a point set's outline seen along a direction (a contact's area from
// its sub-contacts' points).
#pragma once

#include "ConvexPolyhedron.hpp"

#include <vector>

namespace dda {

// Area [m^2] of the convex hull of the points projected on the plane
// perpendicular to `normal` (Andrew's monotone chain, then the shoelace
// formula); 0 for fewer than 3 points or collinear ones.
double projectedHullArea(const std::vector<Vector3>& points, const Vector3& normal);

}  // namespace dda
