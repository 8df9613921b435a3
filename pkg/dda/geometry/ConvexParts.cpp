#include "ConvexParts.hpp"

#include "InternalFaces.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <tuple>

namespace dda {

namespace {

using Polygon2 = std::vector<Eigen::Vector2d>;

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

double signedArea(const Polygon2& p) {
	double twice = 0;
	for (std::size_t k = 0; k < p.size(); ++k) twice += cross2(p[k], p[(k + 1) % p.size()]);
	return 0.5 * twice;
}

// The part of convex polygon `subject` inside convex polygon `clip`
// (Sutherland-Hodgman; either orientation).
Polygon2 clipConvex(Polygon2 subject, const Polygon2& clip) {
	const double orientation = signedArea(clip) >= 0 ? 1.0 : -1.0;
	for (std::size_t k = 0; k < clip.size() && !subject.empty(); ++k) {
		const Eigen::Vector2d& s = clip[k];
		const Eigen::Vector2d edge = clip[(k + 1) % clip.size()] - s;
		auto side = [&](const Eigen::Vector2d& p) { return orientation * cross2(edge, p - s); };
		Polygon2 kept;
		for (std::size_t m = 0; m < subject.size(); ++m) {
			const Eigen::Vector2d& p = subject[m];
			const Eigen::Vector2d& q = subject[(m + 1) % subject.size()];
			const double sp = side(p), sq = side(q);
			if (sp >= 0) kept.push_back(p);
			if ((sp >= 0) != (sq >= 0)) kept.push_back(p + (sp / (sp - sq)) * (q - p));
		}
		subject = std::move(kept);
	}
	return subject;
}

struct PartView {
	const ConvexPolyhedron* part;
	Eigen::AlignedBox3d box;
	std::vector<Vector3> normals;  // per face, outward
};

// The smallest overlap of the two parts' extents over the separating axes
// [m] (<= 0 or within the tolerance: a plane separates them).
double smallestOverlap(const PartView& a, const PartView& b) {
	double smallest = std::numeric_limits<double>::infinity();
	auto test = [&](const Vector3& axis) {
		double minA = std::numeric_limits<double>::infinity(), maxA = -minA, minB = minA, maxB = -minA;
		for (const Vector3& x : a.part->vertices) {
			minA = std::min(minA, axis.dot(x));
			maxA = std::max(maxA, axis.dot(x));
		}
		for (const Vector3& x : b.part->vertices) {
			minB = std::min(minB, axis.dot(x));
			maxB = std::max(maxB, axis.dot(x));
		}
		smallest = std::min(smallest, std::min(maxA, maxB) - std::max(minA, minB));
	};
	for (const Vector3& n : a.normals) test(n);
	for (const Vector3& n : b.normals) test(n);
	for (const auto& ea : a.part->edges) {
		const Vector3 da = a.part->vertices[ea[1]] - a.part->vertices[ea[0]];
		for (const auto& eb : b.part->edges) {
			const Vector3 db = b.part->vertices[eb[1]] - b.part->vertices[eb[0]];
			const Vector3 axis = da.cross(db);
			const double length = axis.norm();
			if (length > 1e-12 * da.norm() * db.norm()) test(axis / length);
		}
	}
	return smallest;
}

// The length tolerance of a pair of parts [m] (kCoplanarRelativeTolerance x
// the larger bounding-box diagonal), or a negative value when their boxes,
// grown by it, do not meet (no face of theirs can touch).
double touchingTolerance(const PartView& a, const PartView& b) {
	const double tolerance =
	    kCoplanarRelativeTolerance * std::max(a.box.diagonal().norm(), b.box.diagonal().norm());
	Eigen::AlignedBox3d grown = a.box;
	grown.min().array() -= tolerance;
	grown.max().array() += tolerance;
	return grown.intersects(b.box) ? tolerance : -1.0;
}

// A face f of part a and a face g of part b that share a region of positive
// area, neither lying wholly on the other (see the header).
struct PartialFaces {
	int f = -1, g = -1;
	double area = 0;
};

// Whether parts a and b share a face region of positive area; a pair of faces
// of theirs that share one only in part goes to `partial` (the first found).
bool shareFace(const PartView& a, const PartView& b, double tolerance, PartialFaces* partial,
               std::vector<PartialFaces>* every = nullptr) {
	const ConvexPolyhedron& A = *a.part;
	const ConvexPolyhedron& B = *b.part;
	bool shared = false;
	for (std::size_t f = 0; f < A.faces.size(); ++f) {
		const Vector3& nf = a.normals[f];
		const Vector3& pf = A.vertices[A.faces[f][0]];
		for (std::size_t g = 0; g < B.faces.size(); ++g) {
			if (nf.dot(b.normals[g]) > -1 + 1e-12) continue;
			bool coplanar = true;
			for (int v : B.faces[g]) coplanar = coplanar && std::abs(nf.dot(B.vertices[v] - pf)) <= tolerance;
			if (!coplanar) continue;
			const Vector3 u = nf.unitOrthogonal(), w = nf.cross(u);
			Polygon2 pa, pb;
			for (int v : A.faces[f]) pa.emplace_back(u.dot(A.vertices[v] - pf), w.dot(A.vertices[v] - pf));
			for (int v : B.faces[g]) pb.emplace_back(u.dot(B.vertices[v] - pf), w.dot(B.vertices[v] - pf));
			const double area = std::abs(signedArea(clipConvex(pa, pb)));
			if (area <= tolerance * std::max(a.box.diagonal().norm(), b.box.diagonal().norm())) continue;
			bool fCovered = true, gCovered = true;
			for (int v : A.faces[f]) fCovered = fCovered && insideFacePolygon(A.vertices[v], B.vertices, B.faces[g], b.normals[g], tolerance);
			for (int v : B.faces[g]) gCovered = gCovered && insideFacePolygon(B.vertices[v], A.vertices, A.faces[f], nf, tolerance);
			if (!fCovered && !gCovered && partial && partial->f < 0)
				*partial = PartialFaces{static_cast<int>(f), static_cast<int>(g), area};
			if (every) every->push_back(PartialFaces{static_cast<int>(f), static_cast<int>(g), area});
			shared = true;
		}
	}
	return shared;
}

}  // namespace

namespace {

PartView viewOf(const ConvexPolyhedron& part) {
	PartView view;
	view.part = &part;
	for (const Vector3& x : part.vertices) view.box.extend(x);
	for (const auto& face : part.faces) view.normals.push_back(faceNormal(part.vertices, face));
	return view;
}

// The pieces of `part` below and above the plane n . x = d (each the hull of
// its side's corners, those within `tolerance` of the plane on both, and the
// edge crossings, each computed once for both), or nothing when the plane
// leaves every corner on one side (within the tolerance).
std::vector<std::vector<Vector3>> splitPart(const ConvexPolyhedron& part, const Vector3& n, double d,
                                            double tolerance) {
	std::vector<double> side;
	bool below = false, above = false;
	for (const Vector3& x : part.vertices) {
		side.push_back(n.dot(x) - d);
		below = below || side.back() < -tolerance;
		above = above || side.back() > tolerance;
	}
	if (!below || !above) return {};
	std::vector<Vector3> lower, upper;
	for (std::size_t v = 0; v < part.vertices.size(); ++v) {
		if (side[v] <= tolerance) lower.push_back(part.vertices[v]);
		if (side[v] >= -tolerance) upper.push_back(part.vertices[v]);
	}
	for (const auto& e : part.edges) {
		const double sa = side[e[0]], sb = side[e[1]];
		if ((sa < -tolerance && sb > tolerance) || (sa > tolerance && sb < -tolerance)) {
			const Vector3& a = part.vertices[e[0]];
			const Vector3& b = part.vertices[e[1]];
			const Vector3 x = a + (sa / (sa - sb)) * (b - a);
			lower.push_back(x);
			upper.push_back(x);
		}
	}
	return {lower, upper};
}

// One cut that resolves a partly shared face pair, or false when none is left.
bool conformOnce(std::vector<std::vector<Vector3>>& parts) {
	std::vector<ConvexPolyhedron> polyhedra;
	for (std::size_t p = 0; p < parts.size(); ++p) {
		try {
			polyhedra.push_back(buildConvexPolyhedron(parts[p]));
		} catch (const InputError& error) {
			throw InputError("part " + std::to_string(p) + " of the concave block: " + error.what());
		}
	}
	std::vector<PartView> views;
	for (const ConvexPolyhedron& p : polyhedra) views.push_back(viewOf(p));
	for (std::size_t a = 0; a < parts.size(); ++a)
		for (std::size_t b = 0; b < parts.size(); ++b) {
			if (a == b) continue;
			const double tolerance = touchingTolerance(views[a], views[b]);
			if (tolerance < 0) continue;
			PartialFaces partial;
			shareFace(views[a], views[b], tolerance, &partial);
			if (partial.f < 0) continue;
			// Cut b by the first plane through an edge of a's face f, perpendicular to f, that cuts it.
			const ConvexPolyhedron& A = polyhedra[a];
			const std::vector<int>& face = A.faces[partial.f];
			const Vector3& nf = views[a].normals[partial.f];
			for (std::size_t k = 0; k < face.size(); ++k) {
				const Vector3& s = A.vertices[face[k]];
				const Vector3 m = nf.cross(A.vertices[face[(k + 1) % face.size()]] - s).normalized();
				std::vector<std::vector<Vector3>> pieces = splitPart(polyhedra[b], m, m.dot(s), tolerance);
				if (pieces.empty()) continue;
				for (const std::vector<Vector3>& piece : pieces) {
					try {
						buildConvexPolyhedron(piece);
					} catch (const InputError& error) {
						throw InputError("parts " + std::to_string(a) + " and " + std::to_string(b) +
						                 " of the concave block share part of a face, and cutting part " +
						                 std::to_string(b) + " along it leaves a piece that is no block (" +
						                 error.what() + "); give parts whose shared faces match");
					}
				}
				parts[b] = pieces[0];
				parts.insert(parts.begin() + static_cast<long>(b) + 1, pieces[1]);
				return true;
			}
		}
	return false;
}

}  // namespace

void checkConvexParts(const std::vector<ConvexPolyhedron>& parts) {
	const int n = static_cast<int>(parts.size());
	if (n == 0) throw InputError("a concave block needs at least one part");
	std::vector<PartView> views;
	for (const ConvexPolyhedron& part : parts) views.push_back(viewOf(part));
	std::vector<int> root(n);
	std::iota(root.begin(), root.end(), 0);
	auto find = [&](int p) {
		while (root[p] != p) p = root[p] = root[root[p]];
		return p;
	};
	for (int a = 0; a < n; ++a)
		for (int b = a + 1; b < n; ++b) {
			const double tolerance = touchingTolerance(views[a], views[b]);
			if (tolerance < 0) continue;
			const double overlap = smallestOverlap(views[a], views[b]);
			if (overlap > tolerance) {
				std::ostringstream message;
				message << "parts " << a << " and " << b << " of the concave block overlap: no plane separates them "
				        << "(they overlap by at least " << overlap << " m along every separating axis); the parts must "
				        << "meet face to face without overlapping";
				throw InputError(message.str());
			}
			PartialFaces partial;
			if (shareFace(views[a], views[b], tolerance, &partial)) root[find(a)] = find(b);
			if (partial.f >= 0) {
				std::ostringstream message;
				message << "parts " << a << " and " << b << " of the concave block share " << partial.area
				        << " m^2 of face " << partial.f << " of part " << a << " and face " << partial.g << " of part "
				        << b << ", but neither face lies wholly on the other; split the parts so that each face they "
				        << "share is a whole face of at least one of them (conformParts does)";
				throw InputError(message.str());
			}
		}
	for (int p = 1; p < n; ++p)
		if (find(p) != find(0)) {
			std::ostringstream message;
			message << "part " << p << " of the concave block shares no face with part 0, directly or through "
			        << "other parts; a concave block is one piece: its parts must meet face to face";
			throw InputError(message.str());
		}
}


std::vector<std::vector<Vector3>> conformParts(const std::vector<std::vector<Vector3>>& parts) {
	std::vector<std::vector<Vector3>> conformed = parts;
	constexpr std::size_t kMostParts = 1000;
	while (conformOnce(conformed))
		if (conformed.size() > kMostParts)
			throw InputError("making the concave block's shared faces match split it into more than " +
			                 std::to_string(kMostParts) + " parts; give parts whose shared faces match");
	return conformed;
}

std::vector<SharedFace> sharedFaces(const std::vector<ConvexPolyhedron>& polyhedra) {
	const int n = static_cast<int>(polyhedra.size());
	std::vector<PartView> views;
	for (const ConvexPolyhedron& p : polyhedra) views.push_back(viewOf(p));
	std::vector<int> order(n);
	std::iota(order.begin(), order.end(), 0);
	std::sort(order.begin(), order.end(), [&](int x, int y) { return views[x].box.min().x() < views[y].box.min().x(); });
	std::vector<SharedFace> found;
	for (int s = 0; s < n; ++s)
		for (int t = s + 1; t < n; ++t) {
			const int a = std::min(order[s], order[t]), b = std::max(order[s], order[t]);
			const double reach = kCoplanarRelativeTolerance *
			                     std::max(views[a].box.diagonal().norm(), views[b].box.diagonal().norm());
			if (views[order[t]].box.min().x() > views[order[s]].box.max().x() + reach) break;
			const double tolerance = touchingTolerance(views[a], views[b]);
			if (tolerance < 0) continue;
			std::vector<PartialFaces> pairs;
			shareFace(views[a], views[b], tolerance, nullptr, &pairs);
			for (const PartialFaces& p : pairs) found.push_back(SharedFace{a, p.f, b, p.g, p.area});
		}
	std::sort(found.begin(), found.end(), [](const SharedFace& x, const SharedFace& y) {
		return std::tie(x.a, x.b, x.f, x.g) < std::tie(y.a, y.b, y.f, y.g);
	});
	return found;
}

MassProperties unionMassProperties(const std::vector<MassProperties>& parts) {
	MassProperties whole;
	for (const MassProperties& p : parts) {
		whole.volume += p.volume;
		whole.centroid += p.volume * p.centroid;
	}
	whole.centroid /= whole.volume;
	for (const MassProperties& p : parts) {
		const Vector3 d = p.centroid - whole.centroid;
		whole.secondMoment += p.secondMoment + p.volume * d * d.transpose();
	}
	return whole;
}

}  // namespace dda
