#include "ConvexDecomposition.hpp"

#include "ConvexPolyhedron.hpp"
#include "dda/core/Errors.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Nef_polyhedron_3.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/convex_decomposition_3.h>

#include <cmath>
#include <sstream>

namespace dda {

namespace {
using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using Nef = CGAL::Nef_polyhedron_3<Kernel>;
using Polyhedron = CGAL::Polyhedron_3<Kernel>;
namespace PMP = CGAL::Polygon_mesh_processing;

// The surface as a CGAL polyhedron, outward, or InputError naming what is wrong with it.
Polyhedron closedSurface(const std::vector<Vector3>& points, const std::vector<std::array<int, 3>>& triangles) {
	std::vector<Kernel::Point_3> soupPoints;
	for (std::size_t i = 0; i < points.size(); ++i) {
		if (!points[i].allFinite()) throw InputError("surface point " + std::to_string(i) + " is not finite");
		soupPoints.emplace_back(points[i].x(), points[i].y(), points[i].z());
	}
	std::vector<std::vector<std::size_t>> soup;
	for (std::size_t t = 0; t < triangles.size(); ++t) {
		const auto& tri = triangles[t];
		for (int v : tri)
			if (v < 0 || v >= static_cast<int>(points.size()))
				throw InputError("triangle " + std::to_string(t) + " has corner index " + std::to_string(v) +
				                 ", out of range (" + std::to_string(points.size()) + " points)");
		if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
			throw InputError("triangle " + std::to_string(t) + " repeats a corner");
		soup.push_back({static_cast<std::size_t>(tri[0]), static_cast<std::size_t>(tri[1]),
		                static_cast<std::size_t>(tri[2])});
	}
	if (soup.size() < 4) throw InputError("a closed surface needs at least 4 triangles");
	if (!PMP::is_polygon_soup_a_polygon_mesh(soup))
		throw InputError("the triangles do not make one manifold surface with consistent orientation (an edge "
		                 "shared by more than two triangles, or two triangles on one edge in the same direction)");
	Polyhedron surface;
	PMP::polygon_soup_to_polygon_mesh(soupPoints, soup, surface);
	int borderEdges = 0;
	for (auto h : halfedges(surface)) borderEdges += is_border(h, surface);
	if (borderEdges > 0)
		throw InputError("the surface is open: " + std::to_string(borderEdges) +
		                 " edges belong to one triangle only; a block needs a closed surface");
	if (PMP::does_self_intersect(surface)) throw InputError("the surface intersects itself");
	if (!PMP::is_outward_oriented(surface)) PMP::reverse_face_orientations(surface);
	return surface;
}
}  // namespace

std::vector<std::vector<Vector3>> convexDecomposition(const std::vector<Vector3>& points,
                                                      const std::vector<std::array<int, 3>>& triangles) {
	Polyhedron surface = closedSurface(points, triangles);
	Nef solid(surface);
	CGAL::convex_decomposition_3(solid);
	std::vector<std::vector<Vector3>> parts;
	// The first volume is the outside; the marked ones are the solid's parts.
	auto volume = solid.volumes_begin();
	for (++volume; volume != solid.volumes_end(); ++volume) {
		if (!volume->mark()) continue;
		Polyhedron piece;
		solid.convert_inner_shell_to_polyhedron(volume->shells_begin(), piece);
		std::vector<Vector3> corners;
		for (auto v = piece.vertices_begin(); v != piece.vertices_end(); ++v)
			corners.emplace_back(CGAL::to_double(v->point().x()), CGAL::to_double(v->point().y()),
			                     CGAL::to_double(v->point().z()));
		std::vector<Vector3> kept;
		for (int i : hullCorners(corners)) kept.push_back(corners[i]);
		parts.push_back(std::move(kept));
	}
	if (parts.empty()) throw InputError("the surface encloses no volume");
	return parts;
}

}  // namespace dda
