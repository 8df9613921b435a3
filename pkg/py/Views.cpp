// What YADE sees of the DDA contacts (yade_dda.views): per block pair with a
// closed contact the pair's resultant, and per block its force and torque.
//
// A pair's sub-contacts (vertex-face, edge-edge) push with
// F_k = n_k N_k + S_k on block i (n_k from block j towards i, N_k >= 0 in
// compression, S_k in the tangent plane; contacts() shows the same numbers).
// YADE's interactions carry one force per body pair, so the pair's
// sub-contacts are summed here, in body order id1 < id2 and YADE's signs
// (PolyhedraGeom/PolyhedraPhys as Law2_PolyhedraGeom_PolyhedraPhys_Volumetric
// writes them): the normal points from id1 to id2; the force on id2 is
// normalForce + shearForce and the force on id1 its opposite.
//   - normal: the unit sum of the sub-contacts' normals weighted by their
//     normal forces (plain sum when no normal force is compressive);
//   - normalForce: (F . normal) normal and shearForce: F - normalForce, with
//     F the total force on id2; |normalForce| is the sum of the sub-contacts'
//     normal forces when they share a normal (face-face, edge-face contacts);
//   - contactPoint: the sub-contacts' points weighted by |normal force|;
//   - kn, ks [N/m]: the sums of the sub-contacts' penalty springs;
//     tanPhi: the largest tan(friction angle) among them.
// A block's force is the sum of the forces on it (contacts, point loads,
// fixed-point springs): everything but gravity and inertia, as O.forces holds
// for YADE's bodies (NewtonIntegrator adds gravity itself). Its torque is
// taken about its centroid. A concave block shows as a YADE clump: each
// member (part) carries its part's contacts, torque about the part's own
// centroid, and the clump the block's loads and fixed-point springs, torque
// about the block's centroid; YADE's unbalancedForce adds them up.
#include "YadeSync.hpp"
#include "dda/solver/BlockEquations.hpp"

#include <algorithm>
#include <map>
#include <utility>

namespace dda {

namespace {

struct PairSum {
	Vector3 weightedNormal = Vector3::Zero();  // sum of N_k n_k, n_k from id1 to id2
	Vector3 plainNormal = Vector3::Zero();     // sum of n_k
	Vector3 force = Vector3::Zero();           // total force on id2 [N]
	Vector3 weightedPoint = Vector3::Zero();   // sum of |N_k| p_k
	Vector3 plainPoint = Vector3::Zero();
	double weight = 0, kn = 0, ks = 0, tanPhi = 0;
	int count = 0;
};

// The forces on block i from its closed contacts [N], their torques about
// its centroid [N m], and (when `pairs`) the body pairs' sums, in one pass.
void contactSums(const SceneLink& s, const std::vector<Vector3>* position, std::vector<Vector3>* force,
                 std::vector<Vector3>* torque, std::map<std::pair<int, int>, PairSum>* pairs) {
	const World& w = s.world;
	for (const Contact& c : w.contacts()) {
		if (c.history.state == ContactState::Open) continue;
		const int i = c.key.blockI, j = c.key.blockJ;
		const BodyLink* li = s.bodyLink(i);
		const BodyLink* lj = s.bodyLink(j);
		if (!li || !lj) continue;
		const Vector3 onI = c.geometry.normal * c.history.normalForce + c.history.shearForce;
		(*force)[i] += onI;
		(*force)[j] -= onI;
		(*torque)[i] += (c.point - (*position)[i]).cross(onI);
		(*torque)[j] -= (c.point - (*position)[j]).cross(onI);
		if (!pairs) continue;
		// Body order: id1 is the smaller body id. The normal n_k points from j
		// to i: from id1 to id2 when i is id2.
		const bool iIsSecond = li->bodyId > lj->bodyId;
		const std::pair<int, int> key = iIsSecond ? std::make_pair(lj->bodyId, li->bodyId)
		                                          : std::make_pair(li->bodyId, lj->bodyId);
		PairSum& p = (*pairs)[key];
		const Vector3 normal12 = iIsSecond ? c.geometry.normal : Vector3(-c.geometry.normal);
		p.weightedNormal += std::max(c.history.normalForce, 0.0) * normal12;
		p.plainNormal += normal12;
		p.force += iIsSecond ? onI : Vector3(-onI);
		const double weight = std::abs(c.history.normalForce);
		p.weightedPoint += weight * c.point;
		p.plainPoint += c.point;
		p.weight += weight;
		p.kn += c.normalStiffness;
		p.ks += c.shearStiffness;
		p.tanPhi = std::max(p.tanPhi, c.frictionTangent);
		++p.count;
	}
}

}  // namespace

ContactViews contactViews(const SceneLink& s, const IntegratorSettings& settings, bool withPairs) {
	const World& w = s.world;
	const int n = w.blockCount();
	std::vector<Vector3> force(n, Vector3::Zero()), torque(n, Vector3::Zero()), position(n);
	for (int i = 0; i < n; ++i) position[i] = w.block(i).isPart() ? s.partPosition(i) : w.block(i).centroid;
	std::map<std::pair<int, int>, PairSum> pairs;
	contactSums(s, &position, &force, &torque, withPairs ? &pairs : nullptr);
	ContactViews out;
	out.pairs.reserve(pairs.size());
	for (const auto& [ids, p] : pairs) {
		const Vector3 sum = p.weightedNormal.squaredNorm() > 0 ? p.weightedNormal : p.plainNormal;
		const Vector3 normal = sum.squaredNorm() > 0 ? Vector3(sum.normalized()) : Vector3(Vector3::UnitZ());
		const Vector3 normalForce = p.force.dot(normal) * normal;
		const Vector3 point = p.weight > 0 ? Vector3(p.weightedPoint / p.weight) : Vector3(p.plainPoint / p.count);
		out.pairs.push_back(PairView{ids.first, ids.second, point, normal, normalForce, Vector3(p.force - normalForce),
		                             p.kn, p.ks, p.tanPhi});
	}
	out.bodies.reserve(n);
	for (int i = 0; i < n; ++i) {
		const BodyLink* link = s.bodyLink(i);
		if (!link) continue;
		const Block& b = w.block(i);
		// A concave block's loads and springs act on its clump (its members
		// carry their parts' contacts, as YADE's clump members do).
		const ClumpLink* clump = s.clumpLink(i);
		Vector3 f = clump ? Vector3(Vector3::Zero()) : force[i], m = clump ? Vector3(Vector3::Zero()) : torque[i];
		for (const PointLoad& load : b.loads) {
			f += load.force;
			m += (load.position - b.centroid).cross(load.force);
		}
		for (const FixedPoint& point : b.fixedPoints) {
			const Vector3 spring = fixedPointStiffness(point, b, settings) * (point.anchor - point.position);
			f += spring;
			m += (point.position - b.centroid).cross(spring);
		}
		if (clump) {
			out.bodies.push_back(BodyForce{link->bodyId, force[i], torque[i]});
			out.bodies.push_back(BodyForce{clump->bodyId, f, m});
		} else {
			out.bodies.push_back(BodyForce{link->bodyId, f, m});
		}
	}
	return out;
}

}  // namespace dda
