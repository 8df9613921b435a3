#include "ContactEquations.hpp"

#include <algorithm>
#include <cmath>

namespace dda {

namespace {

constexpr double kRoundoff = 0x1p-53;  // unit roundoff of double

Matrix3 tangentProjector(const Vector3& normal) { return Matrix3::Identity() - normal * normal.transpose(); }

// [T_i(x_i), -T_j(x_j)]: the relative displacement of two material points per unit of the 24 unknowns.
Eigen::Matrix<double, 3, 24> relativeDisplacementMatrix(const Block& blockI, const Vector3& xi, const Block& blockJ,
                                                        const Vector3& xj) {
	Eigen::Matrix<double, 3, 24> G;
	G.leftCols<12>() = displacementMatrix(xi - blockI.centroid);
	G.rightCols<12>() = -displacementMatrix(xj - blockJ.centroid);
	return G;
}

Vector24 stacked(const Vector12& a, const Vector12& b) {
	Vector24 v;
	v << a, b;
	return v;
}

bool closed(ContactState state) { return state != ContactState::Open; }

// A friction limit follows the normal force, which follows the friction (a
// block tipped by friction at one corner presses another): from solve to
// solve the two can swap between two values (seen in a pile of 30 stiff
// cubes: limits alternating by 60% for 20 solves). A limit whose normal
// force swings back (a change opposite to its last) moves only this
// fraction of the way: a swap of gain -g (g near 1) then shrinks by about
// (1 - g)/2 per solve. Any limit >= 0 resists slip, so how the limit is
// reached changes no energy balance.
constexpr double kLimitRelaxation = 0.5;


// The shear spring's separation: where block i's anchor ends minus where block j's does [m].
Vector3 anchorSeparation(const ContactHistory& trial, const Block& blockI, const Block& blockJ, const Vector12& Di,
                         const Vector12& Dj) {
	return (trial.anchorI + displacementAt(trial.anchorI - blockI.centroid, Di)) -
	       (trial.anchorJ + displacementAt(trial.anchorJ - blockJ.centroid, Dj));
}

// Tangential force limit L [N] of a closed contact with normal force N [N].
double slipLimit(const Contact& contact, double normalForce) {
	return contact.frictionTangent * std::max(0.0, normalForce) + (contact.trial.bonded ? contact.cohesionForce : 0.0);
}

// C = (L/|s_k|)(P - l l^T) of a sliding contact's Newton model (zero when
// |s_k| = 0), as (L/|s_k|) m m^T with m = n x l: the same matrix in exact
// arithmetic (I = n n^T + l l^T + m m^T), but positive semi-definite after
// round-off too. Formed as P - l l^T its rounding left eigenvalues of about
// -1e-16 L/|s_k| (L/|s_k| up to ks), enough to break the Cholesky of a
// scene mixing 1 mm and 100 m blocks (tests/fuzz/known-limits).
Matrix3 slipStiffness(const Contact& contact) {
	const double stretch = contact.stretch.norm();
	if (!(stretch > 0)) return Matrix3::Zero();
	const Vector3 m = contact.geometry.normal.cross(contact.stretch / stretch).normalized();
	return (contact.slipLimit / stretch) * m * m.transpose();
}

}  // namespace

double normalSpringEnergy(bool bonded, double kn, double d) {
	const double c = bonded ? d : std::min(0.0, d);
	return 0.5 * kn * c * c;
}

NormalSecant normalSecant(bool bonded, double kn, double d0, double d) {
	// Closed at both ends (or bonded): U is quadratic there, its secant
	// slope the mean of the two ends' slopes, kn (d + d0) / 2.
	if (bonded || (d0 <= 0 && d <= 0)) return {0.5 * kn * (d + d0), 0.5 * kn};
	if (d0 <= 0) {
		// Released within the step: (0 - U(d0)) / (d - d0), d - d0 >= -d0 > 0.
		if (d0 == 0) return {0.0, 0.0};
		const double q = d - d0;
		return {-0.5 * kn * d0 * d0 / q, 0.5 * kn * d0 * d0 / (q * q)};
	}
	if (d >= 0) return {0.0, 0.0};  // apart at both ends
	// Closing within the step: U(d) / (d - d0), d - d0 <= -d0 < 0.
	const double q = d - d0;
	return {0.5 * kn * d * d / q, 0.5 * kn * (d * d - 2 * d * d0) / (q * q)};
}

bool hasNormalTerms(const Contact& contact) {
	if (!contact.normal.valid) return false;
	return closed(contact.trial.state) || (contact.secantWeight > 0 && contact.normal.d0 < 0);
}

double normalModelError(const Contact& contact, const Vector12& Di, const Vector12& Dj) {
	if (!(contact.secantWeight > 0) || !contact.normal.valid) return 0.0;
	const double kn = contact.normalStiffness, d0 = contact.normal.d0;
	const double d = contactGap(contact, Di, Dj), dk = contact.trialGap;
	const bool bonded = contact.trial.bonded;
	const NormalSecant at = normalSecant(bonded, kn, d0, d), model = normalSecant(bonded, kn, d0, dk);
	return contact.gamma * contact.secantWeight * std::abs(at.value - (model.value + model.slope * (d - dk)));
}

void prepareContact(Contact& contact, const Block& blockI, const Block& blockJ, const IntegratorSettings& settings) {
	const double stiffnessI = blockI.material.young * blockI.size;
	const double stiffnessJ = blockJ.material.young * blockJ.size;
	contact.normalStiffness = settings.contactPenaltyFactor * std::min(stiffnessI, stiffnessJ);
	contact.shearStiffness = settings.shearStiffnessRatio * contact.normalStiffness;
	contact.frictionTangent = std::tan(std::min(blockI.material.frictionAngle, blockJ.material.frictionAngle));
	// Static friction (IntegratorSettings::staticFrictionExcess): a contact
	// that ended the last step locked holds up to (1 + excess) Coulomb's
	// limit until it slips (dropStaticFriction); one that slid, or is new,
	// has Coulomb's.
	contact.staticFriction = contact.history.state == ContactState::Locked ? 1 + settings.staticFrictionExcess : 1.0;
	contact.frictionTangent *= contact.staticFriction;
	contact.cohesionForce = std::min(blockI.material.cohesion, blockJ.material.cohesion) * contact.area;
	contact.tensileForce = std::min(blockI.material.tensileStrength, blockJ.material.tensileStrength) * contact.area;
	contact.normal = linearizeNormalDistance(contact.geometry.stencil, blockI.centroid, blockJ.centroid);
	contact.trialGap = contact.normal.d0;
	const double gamma = settings.newmarkGamma;
	contact.gamma = gamma;
	contact.springWeight = (2 * gamma - 1) / gamma;
	contact.secantWeight = 2 * (1 - gamma) / gamma;
}

void startTrial(Contact& contact, bool formBonds) {
	if (!contact.isNew) {
		contact.trial = contact.history;
	} else {
		contact.trial = ContactHistory();
		contact.trial.bonded = formBonds && contact.normal.valid && contact.normal.d0 <= 0 &&
		                       (contact.cohesionForce > 0 || contact.tensileForce > 0);
	}
	if (!closed(contact.trial.state)) {
		// An open contact's spring is unstretched: its anchors are its points now.
		contact.trial.anchorI = contact.geometry.pointI;
		contact.trial.anchorJ = contact.geometry.pointJ;
		contact.trial.slidingDirection.setZero();
		contact.trial.normalForce = 0;
	}
	contact.stretch.setZero();
	contact.slipping = false;
	contact.limitChange = 0;
	// A provisional limit from the normal force the contact ended the last
	// step with; World::step sets the first pass's from the gap now.
	contact.slipLimit = slipLimit(contact, contact.trial.normalForce);
}

double contactGap(const Contact& contact, const Vector12& Di, const Vector12& Dj) {
	return contact.normal.d0 + contact.normal.ei.dot(Di) + contact.normal.ej.dot(Dj);
}

TangentialTerm tangentialTerm(const Contact& contact) {
	if (!(contact.slipLimit > 0)) return TangentialTerm::None;
	return contact.slipping ? TangentialTerm::FrictionLoad : TangentialTerm::ShearSpring;
}

void tangentBasis(const Vector3& normal, Vector3& t1, Vector3& t2) {
	// Crossed with the coordinate axis least aligned with the normal, so
	// never with a near-parallel one.
	const Vector3 a = normal.cwiseAbs();
	const int axis = a.x() <= a.y() && a.x() <= a.z() ? 0 : (a.y() <= a.z() ? 1 : 2);
	t1 = normal.cross(Vector3::Unit(axis)).normalized();
	t2 = normal.cross(t1).normalized();
}

Matrix24 ContactTerms::stiffness() const {
	Matrix24 k = Matrix24::Zero();
	for (int r = 0; r < rank; ++r) k.noalias() += (weight[r] * vector[r]) * vector[r].transpose();
	return k;
}

bool contactTerms(const Contact& contact, const Block& blockI, const Block& blockJ, ContactTerms& terms) {
	const ContactHistory& trial = contact.trial;
	const TangentialTerm tangential = tangentialTerm(contact);
	const bool normalTerms = hasNormalTerms(contact);
	terms.rank = 0;
	if (!normalTerms && tangential == TangentialTerm::None) return false;
	terms.force.setZero();
	auto add = [&terms](double weight, const Vector24& v) {
		terms.weight[terms.rank] = weight;
		terms.vector[terms.rank] = v;
		++terms.rank;
	};
	if (normalTerms) {
		const Vector24 e = stacked(contact.normal.ei, contact.normal.ej);
		const double kn = contact.normalStiffness;
		if (contact.secantWeight > 0) {
			// springWeight x the spring (while closed) plus secantWeight x the
			// secant force, expanded about the trial gap d_k.
			const double d0 = contact.normal.d0, dk = contact.trialGap;
			const NormalSecant h = normalSecant(trial.bonded, kn, d0, dk);
			const double spring = closed(trial.state) ? contact.springWeight * kn : 0.0;
			add(spring + contact.secantWeight * h.slope, e);
			terms.force.noalias() = (-spring * d0 + contact.secantWeight * (h.slope * (dk - d0) - h.value)) * e;
		} else {
			add(kn, e);
			terms.force.noalias() = -kn * contact.normal.d0 * e;
		}
	}
	if (tangential == TangentialTerm::None) return true;
	// The tangential spring's force in the step's equations is 1/gamma times
	// its physical one (exactly 1 for Shi's scheme).
	const double weight = 1 / contact.gamma;
	const Eigen::Matrix<double, 3, 24> G = relativeDisplacementMatrix(blockI, trial.anchorI, blockJ, trial.anchorJ);
	const Vector3 separation = trial.anchorI - trial.anchorJ;
	if (tangential == TangentialTerm::ShearSpring) {
		// G^T P G = (G^T t1)(G^T t1)^T + (G^T t2)(G^T t2)^T.
		const Matrix3 P = tangentProjector(contact.geometry.normal);
		const double ks = contact.shearStiffness;
		Vector3 t1, t2;
		tangentBasis(contact.geometry.normal, t1, t2);
		add(weight * ks, G.transpose() * t1);
		add(weight * ks, G.transpose() * t2);
		terms.force.noalias() -= (weight * ks) * G.transpose() * (P * separation);
	} else {
		// G^T C G as the outer product of G^T m with itself (symmetric and
		// positive semi-definite to round-off; see slipStiffness).
		const double stretch = contact.stretch.norm();
		if (!(stretch > 0)) return true;  // no slip direction: nothing to add
		const Vector3 l = contact.stretch / stretch;
		const Vector3 m = contact.geometry.normal.cross(l).normalized();
		const double c = weight * contact.slipLimit / stretch;
		const Vector24 Gm = G.transpose() * m;
		add(c, Gm);
		terms.force.noalias() -= G.transpose() * ((weight * contact.slipLimit) * l) + (c * m.dot(separation)) * Gm;
	}
	return true;
}

bool contactTerms(const Contact& contact, const Block& blockI, const Block& blockJ, Matrix24& stiffness,
                  Vector24& force) {
	ContactTerms terms;
	const bool any = contactTerms(contact, blockI, blockJ, terms);
	stiffness = terms.stiffness();
	force = any ? terms.force : Vector24::Zero();
	return any;
}

namespace {
// The contact's normal force over the step [N], compression positive: the
// spring's -kn d while closed (Shi's scheme), else gamma times the
// equations' force, (2 gamma - 1) kn max(0, -d) - 2 (1 - gamma) h(d).
double meanNormalForce(const Contact& contact, bool closedNow, double gap) {
	const double kn = contact.normalStiffness;
	const double spring = closedNow ? -kn * gap : 0.0;
	if (!(contact.secantWeight > 0) || !contact.normal.valid) return spring;
	const double secant = normalSecant(contact.trial.bonded, kn, contact.normal.d0, gap).value;
	return contact.gamma * (contact.springWeight * spring - contact.secantWeight * secant);
}
}  // namespace

bool evaluateContact(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di,
                     const Vector12& Dj) {
	ContactHistory& trial = contact.trial;
	const bool closedBefore = closed(trial.state), slippingBefore = contact.slipping, bondedBefore = trial.bonded;
	const double kn = contact.normalStiffness;
	const double gap = contact.normal.valid ? contactGap(contact, Di, Dj) : 0.0;
	// A bond holds in tension up to its strength; beyond, it breaks for good.
	if (trial.bonded && kn * gap > contact.tensileForce) trial.bonded = false;
	bool closedNow = contact.normal.valid && (trial.bonded || gap < 0);
	contact.trialGap = gap;
	trial.normalForce = meanNormalForce(contact, closedNow, gap);
	contact.stretch.setZero();
	contact.slipping = false;
	if (contact.slipLimit > 0 || trial.bonded) {
		const Vector3 s = tangentProjector(contact.geometry.normal) * anchorSeparation(trial, blockI, blockJ, Di, Dj);
		if (trial.bonded && contact.shearStiffness * s.norm() > contact.slipLimit) {
			// Shear beyond friction plus cohesion breaks the bond; without it
			// the contact holds no tension, and its limit loses the cohesion.
			trial.bonded = false;
			closedNow = contact.normal.valid && gap < 0;
			trial.normalForce = meanNormalForce(contact, closedNow, gap);
			contact.slipLimit = slipLimit(contact, trial.normalForce);
		}
		contact.stretch = s;
		contact.slipping = contact.slipLimit > 0 && contact.shearStiffness * s.norm() > contact.slipLimit;
	}
	if (!closedNow)
		trial.state = ContactState::Open;
	else if (contact.slipping || !(contact.slipLimit > 0))
		trial.state = ContactState::Sliding;  // at the limit, or nothing holds it
	else
		trial.state = ContactState::Locked;
	if (contact.slipping) trial.slidingDirection = contact.stretch.normalized();
	return closedBefore != closedNow || slippingBefore != contact.slipping || bondedBefore != trial.bonded;
}

double updateFrictionLimit(Contact& contact, bool apply) {
	// The limit's normal force follows the contact's: halfway where it
	// swings back (a change opposite to its last).
	const double before = contact.slipLimit;
	const double target = slipLimit(contact, contact.trial.normalForce);
	const double change = target - before;
	if (!apply) return std::abs(change);
	const double weight = change * contact.limitChange < 0 ? kLimitRelaxation : 1.0;
	contact.slipLimit = before + weight * change;
	contact.limitChange = weight * change;
	return std::abs(target - before);
}

void dropStaticFriction(Contact& contact) {
	if (contact.staticFriction == 1 || !contact.slipping) return;
	contact.frictionTangent /= contact.staticFriction;
	contact.staticFriction = 1;
}

double limitForceChange(const Contact& contact) {
	const double before = contact.slipLimit;
	const double target = slipLimit(contact, contact.trial.normalForce);
	if (!(before > 0) || contact.trial.bonded) return std::abs(target - before);
	const double spring = contact.shearStiffness * contact.stretch.norm();
	return std::abs(std::min(spring, target) - std::min(spring, before));
}

double limitExcess(const Contact& contact) {
	const double before = contact.slipLimit;
	if (!(before > 0)) return 0.0;
	const double target = slipLimit(contact, contact.trial.normalForce);
	if (contact.trial.bonded) return std::max(0.0, before - target);
	const double spring = contact.shearStiffness * contact.stretch.norm();
	return std::max(0.0, std::min(spring, before) - std::min(spring, target));
}

double forceScale(const Contact& contact) {
	const double carried = std::min(contact.shearStiffness * contact.stretch.norm(), contact.slipLimit);
	return std::max(slipLimit(contact, contact.trial.normalForce), carried);
}

void setFrictionLimit(Contact& contact) {
	const double target = slipLimit(contact, contact.trial.normalForce);
	contact.limitChange = target - contact.slipLimit;
	contact.slipLimit = target;
}

void lowerFrictionLimit(Contact& contact) {
	if (slipLimit(contact, contact.trial.normalForce) < contact.slipLimit) setFrictionLimit(contact);
}

Vector3 tangentialForce(const Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di,
                        const Vector12& Dj) {
	const TangentialTerm tangential = tangentialTerm(contact);
	if (tangential == TangentialTerm::None) return Vector3::Zero();
	const ContactHistory& trial = contact.trial;
	const Vector3 s = tangentProjector(contact.geometry.normal) * anchorSeparation(trial, blockI, blockJ, Di, Dj);
	if (tangential == TangentialTerm::ShearSpring) return -contact.shearStiffness * s;
	const double stretch = contact.stretch.norm();
	if (!(stretch > 0)) return Vector3::Zero();
	return -(contact.slipLimit * contact.stretch / stretch + slipStiffness(contact) * (s - contact.stretch));
}

namespace {
// The bound E on the rounding of searchLine's computed phi' over t in [0, 1].
double roundoffBound(const ContactLine* begin, const ContactLine* end, double slope, double curvature) {
	// E: |computed - exact| over t in [0, 1]. Each term's rounding is a
	// few units of roundoff u of a bound m_c on the sizes it is computed
	// from (the normal spring's w_s kn (|d| + |d'|) |d'|, zero and exact
	// when the gap stays positive; the tangential one w_t (ks (|s|_1 +
	// |s'|_1) |s'|_1 + L |s'|_1), which also covers the two sides of the
	// stick-slip branch); the sum's is (n - 1) u times the sum of the
	// terms' sizes. Taken 4 x over (n + 20) u; a negative curvature
	// (round-off of a quadratic form) makes phi' fall by at most
	// |curvature| on [0, 1]. w_s, w_c, w_t are the line's springWeight,
	// secantWeight, tangentialWeight (1, 0, 1 under Shi's scheme, where
	// E is the same number as without them).
	//
	// The secant term (gamma < 1) w_c h(d) d', with d = d(0) + t d' the
	// gap and h = normalSecant(d0, d).value, has m_c = w_c kn (|d(0)| +
	// |d'| + |d0|) |d'|. Exact h rises with d (ContactEquations.hpp), so
	// the exact phi' still rises with t, and:
	// - the computed gap misses d by at most 2u (|d(0)| + |d'|) (t d'
	//   and the sum, t in [0, 1]);
	// - h is continuous with 0 <= h' <= kn/2 in every branch (closed:
	//   kn/2; released: kn d0^2 / 2q^2 with |q| = |d - d0| >= |d0|;
	//   closing: kn (d^2 - 2 d d0) / 2q^2 <= kn/2 as q^2 = that +
	//   d0^2), so that miss moves h by at most u kn (|d(0)| + |d'|);
	// - each branch evaluated at the computed gap rounds by at most
	//   about 4u (q's rounding and three operations) of its size,
	//   which is at most kn/2 (|d| + |d0|): kn |d + d0|/2 closed,
	//   kn d0^2 / 2|q| <= kn |d0|/2 released, kn d^2 / 2|q| <= kn |d|/2
	//   closing;
	// - the two products with w_c and d' add 2u of |w_c h d'|.
	// Together about 5u m_c, within the 4 (n + 20) u taken. Apart at
	// both ends (d0 > 0 and the gap positive over the line) the secant
	// is exactly 0, computed and exact.
	double size = std::abs(slope) + std::abs(curvature);
	for (const ContactLine* line = begin; line != end; ++line) {
		const double gap = line->gap, rate = std::abs(line->gapRate);
		const bool apart = !line->bonded && gap > 0 && gap + line->gapRate > 4 * kRoundoff * (gap + rate);
		if (!apart) size += line->springWeight * line->normalStiffness * (std::abs(gap) + rate) * rate;
		if (line->secantWeight > 0 && !(apart && line->startGap > 0))
			size += line->secantWeight * line->normalStiffness *
			        (std::abs(gap) + rate + std::abs(line->startGap)) * rate;
		if (line->tangential) {
			const double s = line->stretch.cwiseAbs().sum(), r = line->stretchRate.cwiseAbs().sum();
			size += line->tangentialWeight * (line->shearStiffness * (s + r) * r + line->limit * r);
		}
	}
	const double n = static_cast<double>(end - begin);
	return 4 * (n + 20) * kRoundoff * size + (curvature < 0 ? -curvature : 0);
}
}  // namespace

double searchLine(const ContactLine* begin, const ContactLine* end, double slope, double curvature, bool certified,
                  long* evaluations) {
	long count = 0;
	auto derivative = [&](double at) {
		++count;
		double value = slope + at * curvature;
		for (const ContactLine* line = begin; line != end; ++line) value += line->derivative(at);
		return value;
	};
	auto finish = [&](double t) {
		if (evaluations) *evaluations += count;
		return t;
	};
	const double atOne = derivative(1);
	if (!(atOne > 0)) return finish(1);
	// Certificates: every computed phi' at t <= negativeUpTo is negative, at
	// t >= positiveFrom positive (none yet: outside [0, 1]).
	double negativeUpTo = -1, positiveFrom = 2, bound = 0;
	auto learn = [&](double at, double value) {
		if (value < -2 * bound) negativeUpTo = std::max(negativeUpTo, at);
		if (value > 2 * bound) positiveFrom = std::min(positiveFrom, at);
	};
	if (certified) {
		bound = roundoffBound(begin, end, slope, curvature);
		if (!std::isfinite(bound)) certified = false;
	}
	if (certified) {
		learn(1, atOne);
		// Regula falsi (Illinois) towards the root, each value a certificate
		// when far enough from zero; stops once a value is within 2E (at the
		// root as far as phi' can tell) or the certificates are 4e-12 apart.
		double a = 0, fa = derivative(0), b = 1, fb = atOne;
		learn(0, fa);
		int side = 0;
		for (int k = 0; k < 12 && fa <= 0 && positiveFrom - negativeUpTo > 4e-12; ++k) {
			double p = a - fa * (b - a) / (fb - fa);
			if (!(p > a && p < b)) p = 0.5 * (a + b);
			const double fp = derivative(p);
			learn(p, fp);
			if (std::abs(fp) <= 2 * bound) {
				// Certificates just outside the zone where phi' cannot tell
				// its sign: about 2E over the slope on either side.
				const double rise = (fb - fa) / (b - a);
				double step = rise > 0 ? 4 * bound / rise : 1e-12;
				for (int tries = 0; tries < 3 && positiveFrom - negativeUpTo > 4e-12; ++tries, step *= 4) {
					if (p - step > negativeUpTo && p - step > 0) learn(p - step, derivative(p - step));
					if (p + step < positiveFrom && p + step < 1) learn(p + step, derivative(p + step));
				}
				break;
			}
			if (fp > 0) {
				b = p, fb = fp;
				if (side == 1) fa *= 0.5;
				side = 1;
			} else {
				a = p, fa = fp;
				if (side == -1) fb *= 0.5;
				side = -1;
			}
		}
	}
	double low = 0, high = 1;
	for (int k = 0; k < 60 && high - low > 1e-12; ++k) {
		const double mid = 0.5 * (low + high);
		bool positive;
		if (mid <= negativeUpTo)
			positive = false;
		else if (mid >= positiveFrom)
			positive = true;
		else {
			const double value = derivative(mid);
			positive = value > 0;
			if (certified) learn(mid, value);
		}
		(positive ? high : low) = mid;
	}
	return finish(0.5 * (low + high));
}

ContactLine contactLine(const Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di,
                        const Vector12& Dj, const Vector12& deltaI, const Vector12& deltaJ) {
	ContactLine line;
	if (!contact.normal.valid) return line;
	const ContactHistory& trial = contact.trial;
	line.gap = contactGap(contact, Di, Dj);
	line.gapRate = contact.normal.ei.dot(deltaI) + contact.normal.ej.dot(deltaJ);
	line.normalStiffness = contact.normalStiffness;
	line.shearStiffness = contact.shearStiffness;
	line.bonded = trial.bonded;
	line.startGap = contact.normal.d0;
	line.springWeight = contact.springWeight;
	line.secantWeight = contact.secantWeight;
	line.tangentialWeight = 1 / contact.gamma;
	line.limit = contact.slipLimit;
	line.tangential = line.limit > 0;
	if (line.tangential) {
		const Matrix3 P = tangentProjector(contact.geometry.normal);
		line.stretch = P * anchorSeparation(trial, blockI, blockJ, Di, Dj);
		line.stretchRate = P * (displacementAt(trial.anchorI - blockI.centroid, deltaI) -
		                        displacementAt(trial.anchorJ - blockJ.centroid, deltaJ));
	}
	return line;
}

ContactStepEnergy contactStepEnergy(const Contact& contact, const Block& blockI, const Block& blockJ,
                                    const Vector12& Di, const Vector12& Dj) {
	ContactStepEnergy energy;
	const ContactHistory& trial = contact.trial;
	const double kn = contact.normalStiffness;
	const double d0 = contact.normal.d0, d1 = contactGap(contact, Di, Dj);
	// The spring's energy U at both ends, and its Bregman divergence B =
	// U(0) - U(D) - U'(D) (0 - D) times 2 gamma - 1 (the secant force's work
	// is -(U(D) - U(0)) exactly: it dissipates nothing). A contact that
	// opened in the step (Shi's scheme: no force at its end) lost what it
	// held: B = U(d0).
	if (contact.normal.valid) {
		const double c0 = trial.bonded ? d0 : std::min(0.0, d0), c1 = trial.bonded ? d1 : std::min(0.0, d1);
		energy.start = 0.5 * kn * c0 * c0;
		energy.end = 0.5 * kn * c1 * c1;
		// U'(D) = kn c1 and d(D) - d(0) = d1 - d0.
		energy.damping = (2 * contact.gamma - 1) * (energy.start - energy.end + kn * c1 * (d1 - d0));
	}
	const TangentialTerm tangential = tangentialTerm(contact);
	if (tangential == TangentialTerm::None) return energy;
	const double ks = contact.shearStiffness;
	const Matrix3 P = tangentProjector(contact.geometry.normal);
	const Vector3 s0 = P * (trial.anchorI - trial.anchorJ);
	const Vector3 s1 = P * anchorSeparation(trial, blockI, blockJ, Di, Dj);
	energy.start += 0.5 * ks * s0.squaredNorm();
	if (tangential == TangentialTerm::ShearSpring) {
		energy.end += 0.5 * ks * s1.squaredNorm();
		energy.damping += 0.5 * ks * (s1 - s0).squaredNorm();
	} else {
		const double r = contact.slipLimit / ks, norm = s1.norm();
		if (!(norm > 0)) return energy;
		energy.end += 0.5 * ks * r * r;
		energy.friction = contact.slipLimit * (norm - r);
		energy.damping += 0.5 * ks * (r * s1 / norm - s0).squaredNorm();
	}
	return energy;
}

void finishContact(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di, const Vector12& Dj) {
	ContactHistory& trial = contact.trial;
	trial.shearForce.setZero();
	if (!closed(trial.state) || !contact.normal.valid) {
		trial.normalForce = 0;
		return;
	}
	const TangentialTerm tangential = tangentialTerm(contact);
	if (tangential == TangentialTerm::None) {
		// No tangential spring this step (no limit: frictionless, or a
		// contact whose limit starts from zero): it ends unstretched, or the
		// next step's spring would start stretched by the whole step's slip
		// and release energy it never stored (seen: 1.9e5 J at one contact
		// of a stiff pile).
		trial.anchorI -= tangentProjector(contact.geometry.normal) * anchorSeparation(trial, blockI, blockJ, Di, Dj);
	} else if (tangential == TangentialTerm::ShearSpring) {
		trial.shearForce = -contact.shearStiffness * contact.stretch;
	} else if (tangential == TangentialTerm::FrictionLoad) {
		// Slip: the spring keeps the stretch r l that carries the limit
		// force; block i's anchor moves back by the slip, s - r l.
		const double norm = contact.stretch.norm();
		const Vector3 l = contact.stretch / norm;
		const double r = contact.slipLimit / contact.shearStiffness;
		trial.anchorI -= contact.stretch - r * l;
		trial.shearForce = -contact.slipLimit * l;
		trial.slidingDirection = l;
	}
}

}  // namespace dda
