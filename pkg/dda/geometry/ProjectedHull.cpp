#include "ProjectedHull.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <utility>

namespace dda {

double projectedHullArea(const std::vector<Vector3>& points, const Vector3& normal) {
	if (points.size() < 3) return 0;
	const Vector3 u = normal.unitOrthogonal(), v = normal.normalized().cross(u);
	std::vector<std::pair<double, double>> p;
	p.reserve(points.size());
	for (const Vector3& x : points) p.emplace_back(u.dot(x - points[0]), v.dot(x - points[0]));
	std::sort(p.begin(), p.end());
	auto cross = [](const std::pair<double, double>& o, const std::pair<double, double>& a,
	                const std::pair<double, double>& b) {
		return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
	};
	std::vector<std::pair<double, double>> hull(2 * p.size());
	std::size_t k = 0;
	for (std::size_t i = 0; i < p.size(); ++i) {
		while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
		hull[k++] = p[i];
	}
	for (std::size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {
		while (k >= lower && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
		hull[k++] = p[i];
	}
	double twice = 0;
	for (std::size_t i = 0; i + 1 < k; ++i) twice += hull[i].first * hull[i + 1].second - hull[i + 1].first * hull[i].second;
	return 0.5 * std::abs(twice);
}

}  // namespace dda
