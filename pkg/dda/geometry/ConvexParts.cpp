#include "ConvexParts.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

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

bool insidePolygon(const Vector3& x, const ConvexPolyhedron& p, const std::vector<int>& face, const Vector3& n,
                   double tolerance) {
	for (std::size_t k = 0; k < face.size(); ++k) {
		const Vector3& s = p.vertices[face[k]];
		const Vector3 inward = n.cross(p.vertices[face[(k + 1) % face.size()]] - s);
		const double length = inward.norm();
		if (length > 0 && (x - s).dot(inward) < -tolerance * length) return false;
	}
	return true;
}

// Whether parts a and b share a face region of positive area; throws when
// neither of the two faces lies wholly on the other (see the header).
bool shareFace(const PartView& a, int ia, const PartView& b, int ib, double tolerance) {
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
			for (int v : A.faces[f]) fCovered = fCovered && insidePolygon(A.vertices[v], B, B.faces[g], b.normals[g], tolerance);
			for (int v : B.faces[g]) gCovered = gCovered && insidePolygon(B.vertices[v], A, A.faces[f], nf, tolerance);
			if (!fCovered && !gCovered) {
				std::ostringstream message;
				message << "parts " << ia << " and " << ib << " of the concave block share " << area
				        << " m^2 of face " << f << " of part " << ia << " and face " << g << " of part " << ib
				        << ", but neither face lies wholly on the other; split the parts so that each face they "
				        << "share is a whole face of at least one of them";
				throw InputError(message.str());
			}
			shared = true;
		}
	}
	return shared;
}

}  // namespace

void checkConvexParts(const std::vector<ConvexPolyhedron>& parts) {
	const int n = static_cast<int>(parts.size());
	if (n == 0) throw InputError("a concave block needs at least one part");
	std::vector<PartView> views(n);
	for (int p = 0; p < n; ++p) {
		views[p].part = &parts[p];
		for (const Vector3& x : parts[p].vertices) views[p].box.extend(x);
		for (const auto& face : parts[p].faces) views[p].normals.push_back(faceNormal(parts[p].vertices, face));
	}
	std::vector<int> root(n);
	std::iota(root.begin(), root.end(), 0);
	auto find = [&](int p) {
		while (root[p] != p) p = root[p] = root[root[p]];
		return p;
	};
	for (int a = 0; a < n; ++a)
		for (int b = a + 1; b < n; ++b) {
			const double tolerance = kCoplanarRelativeTolerance *
			                         std::max(views[a].box.diagonal().norm(), views[b].box.diagonal().norm());
			Eigen::AlignedBox3d grown = views[a].box;
			grown.min().array() -= tolerance;
			grown.max().array() += tolerance;
			if (!grown.intersects(views[b].box)) continue;
			const double overlap = smallestOverlap(views[a], views[b]);
			if (overlap > tolerance) {
				std::ostringstream message;
				message << "parts " << a << " and " << b << " of the concave block overlap: no plane separates them "
				        << "(they overlap by at least " << overlap << " m along every separating axis); the parts must "
				        << "meet face to face without overlapping";
				throw InputError(message.str());
			}
			if (shareFace(views[a], a, views[b], b, tolerance)) root[find(a)] = find(b);
		}
	for (int p = 1; p < n; ++p)
		if (find(p) != find(0)) {
			std::ostringstream message;
			message << "part " << p << " of the concave block shares no face with part 0, directly or through "
			        << "other parts; a concave block is one piece: its parts must meet face to face";
			throw InputError(message.str());
		}
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
