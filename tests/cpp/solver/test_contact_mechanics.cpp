// Contact springs and friction of one sub-contact (solver/ContactEquations):
// their stiffness and force terms against finite differences of the exact
// contact energy, and the open-close state rules.
#include "dda/solver/ContactEquations.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace dda;

namespace {

Block blockAt(const Vector3& centroid, double young, double size, double frictionAngle) {
	Block b;
	b.centroid = centroid;
	b.material.young = young;
	b.material.frictionAngle = frictionAngle;
	b.size = size;
	return b;
}

// A vertex of block i exactly on a tilted face triangle of block j (closed, d0 = 0).
Contact closedVertexFaceContact(const Block& bi, const Block& bj) {
	const Vector3 f0(-1, -1, 0.1), f1(2, -0.5, -0.2), f2(0.3, 1.8, 0.25);
	const Vector3 normal = (f1 - f0).cross(f2 - f0).normalized();
	// A point inside the triangle, on its plane.
	const Vector3 onFace = (f0 + f1 + f2) / 3.0;
	Contact c;
	c.geometry.kind = ContactKind::VertexFace;
	c.geometry.stencil = vertexFaceStencil(onFace, f0, f1, f2);
	c.geometry.normal = normal;
	c.geometry.pointI = onFace;
	c.geometry.pointJ = onFace;
	c.geometry.gap = 0;
	IntegratorSettings settings;
	prepareContact(c, bi, bj, settings);
	return c;
}

// Exact energy of a locked contact for unknowns D = (Di, Dj): normal spring on
// the exact distance of the moved stencil, shear spring on the exact relative
// displacement of the anchors, projected on the start-of-step tangent plane.
double lockedEnergy(const Contact& c, const Block& bi, const Block& bj, const Vector24& D) {
	const Vector12 Di = D.head<12>(), Dj = D.tail<12>();
	const double dn = *exactNormalDistance(c.geometry.stencil, bi.centroid, bj.centroid, Di, Dj);
	const Vector3 delta = (c.trial.anchorI + displacementAt(c.trial.anchorI - bi.centroid, Di)) -
	                      (c.trial.anchorJ + displacementAt(c.trial.anchorJ - bj.centroid, Dj));
	const Vector3& n = c.geometry.normal;
	const Vector3 shear = delta - n * n.dot(delta);
	return 0.5 * c.normalStiffness * dn * dn + 0.5 * c.shearStiffness * shear.squaredNorm();
}

// Gradient and Hessian of `energy` at D = 0 by central differences with step h.
template <class Energy>
void finiteDifferences(const Energy& energy, double h, Vector24& gradient, Matrix24& hessian) {
	for (int a = 0; a < 24; ++a) {
		Vector24 e = Vector24::Zero();
		e(a) = h;
		gradient(a) = (energy(e) - energy(-e)) / (2 * h);
		for (int b = 0; b < 24; ++b) {
			Vector24 f = Vector24::Zero();
			f(b) = h;
			hessian(a, b) = (energy(e + f) - energy(e - f) - energy(-e + f) + energy(-e - f)) / (4 * h * h);
		}
	}
}

}  // namespace

TEST(ContactMechanics, LockedTermsAreTheHessianAndGradientOfTheExactEnergy) {
	const Block bi = blockAt(Vector3(0.2, -0.1, 1.1), 1e7, 1.0, 0.5);
	const Block bj = blockAt(Vector3(0.1, 0.3, -0.9), 2e7, 1.3, 0.6);
	Contact c = closedVertexFaceContact(bi, bj);
	ASSERT_TRUE(c.normal.valid);
	ASSERT_NEAR(c.normal.d0, 0.0, 1e-15);
	c.trial.state = ContactState::Locked;
	c.slipLimit = 1e30;  // far from its limit: the spring alone
	c.slipping = false;
	// Anchors a little apart in the tangent plane: a pre-stretched shear spring.
	const Vector3 tangent = c.geometry.normal.unitOrthogonal();
	c.trial.anchorI = c.geometry.pointI + 1e-3 * tangent;
	c.trial.anchorJ = c.geometry.pointJ;

	Matrix24 K;
	Vector24 F;
	ASSERT_TRUE(contactTerms(c, bi, bj, K, F));
	EXPECT_NEAR((K - K.transpose()).norm(), 0.0, 1e-9 * K.norm());

	// Gradient: F = -dE/dD at D = 0; Hessian: K = d2E/dD2 at D = 0.
	Vector24 gradient;
	Matrix24 hessian;
	finiteDifferences([&](const Vector24& D) { return lockedEnergy(c, bi, bj, D); }, 1e-6, gradient, hessian);
	EXPECT_LT((F + gradient).norm(), 1e-6 * gradient.norm());
	EXPECT_LT((K - hessian).norm(), 1e-6 * hessian.norm());
}

namespace {

// Energy of a closed contact with Coulomb's limit L on its tangential spring
// (the Huber function psi of ContactEquations.hpp) for unknowns D: normal
// spring on the exact distance of the moved stencil, tangential spring on the
// exact relative displacement of the anchors in the start-of-step tangent plane.
double coulombEnergy(const Contact& c, const Block& bi, const Block& bj, const Vector24& D, double limit) {
	const Vector12 Di = D.head<12>(), Dj = D.tail<12>();
	const double dn = *exactNormalDistance(c.geometry.stencil, bi.centroid, bj.centroid, Di, Dj);
	const Vector3 delta = (c.trial.anchorI + displacementAt(c.trial.anchorI - bi.centroid, Di)) -
	                      (c.trial.anchorJ + displacementAt(c.trial.anchorJ - bj.centroid, Dj));
	const Vector3& n = c.geometry.normal;
	const double s = (delta - n * n.dot(delta)).norm(), ks = c.shearStiffness;
	const double psi = ks * s <= limit ? 0.5 * ks * s * s : limit * s - limit * limit / (2 * ks);
	return 0.5 * c.normalStiffness * dn * dn + psi;
}

}  // namespace

TEST(ContactMechanics, SlipTermsAreTheHessianAndGradientOfTheCoulombEnergy) {
	const double phi = 0.4;
	const Block bi = blockAt(Vector3(0.2, -0.1, 1.1), 1e7, 1.0, phi);
	const Block bj = blockAt(Vector3(0.1, 0.3, -0.9), 2e7, 1.3, phi);
	Contact c = closedVertexFaceContact(bi, bj);
	// Penetrating by 1e-4 m (N = kn 1e-4), anchors stretched 3 x past the limit.
	c.normal.d0 = -1e-4;
	c.isNew = false;
	c.history.state = ContactState::Locked;
	const Vector3 tangent = c.geometry.normal.unitOrthogonal();
	const double N = c.normalStiffness * 1e-4, reach = std::tan(phi) * N / c.shearStiffness;
	c.history.anchorI = c.geometry.pointI + 3 * reach * tangent;
	c.history.anchorJ = c.geometry.pointJ;
	c.history.normalForce = N;  // the step's first limit
	startTrial(c, false);
	const Vector12 zero = Vector12::Zero();
	evaluateContact(c, bi, bj, zero, zero);
	ASSERT_EQ(c.trial.state, ContactState::Sliding);
	EXPECT_NEAR(c.slipLimit, std::tan(phi) * N, 1e-12 * N);
	EXPECT_LT((c.trial.slidingDirection - tangent).norm(), 1e-12);

	Matrix24 K;
	Vector24 F;
	ASSERT_TRUE(contactTerms(c, bi, bj, K, F));
	EXPECT_NEAR((K - K.transpose()).norm(), 0.0, 1e-9 * K.norm());
	// Against the exact energy, whose distance at D = 0 is the stencil's own
	// (0: the vertex lies on the face), the model's d0 must be that too; the
	// -1e-4 above only set the normal force, hence the limit.
	c.normal.d0 = 0;
	ASSERT_TRUE(contactTerms(c, bi, bj, K, F));
	Vector24 gradient;
	Matrix24 hessian;
	finiteDifferences([&](const Vector24& D) { return coulombEnergy(c, bi, bj, D, c.slipLimit); }, 1e-7, gradient,
	                  hessian);
	EXPECT_LT((F + gradient).norm(), 1e-6 * gradient.norm());
	EXPECT_LT((K - hessian).norm(), 1e-4 * hessian.norm());
	// The friction force on block i is the limit, against the stretch.
	EXPECT_LT((F.head<3>() + c.slipLimit * tangent).norm(), 1e-6 * c.slipLimit);
}

TEST(ContactMechanics, StatesFollowTheTrialSolution) {
	const double phi = 0.5;
	const Block bi = blockAt(Vector3(0, 0, 1), 1e7, 1.0, phi);
	const Block bj = blockAt(Vector3(0, 0, -1), 1e7, 1.0, phi);
	Contact c = closedVertexFaceContact(bi, bj);
	c.isNew = true;
	const Vector3 n = c.geometry.normal;
	const Vector3 t = n.unitOrthogonal();
	Vector12 Di = Vector12::Zero();
	const Vector12 Dj = Vector12::Zero();
	// A fresh trial at D, its limit from the normal force there.
	auto evaluate = [&](const Vector12& D) {
		startTrial(c, false);
		evaluateContact(c, bi, bj, D, Dj);
		updateFrictionLimit(c, true);
		return evaluateContact(c, bi, bj, D, Dj);
	};

	// Apart: open, no force, no terms. Into the face: closed, N = kn |d|, locked.
	Di.head<3>() = 1e-4 * n;
	evaluate(Di);
	EXPECT_EQ(c.trial.state, ContactState::Open);
	EXPECT_EQ(c.trial.normalForce, 0.0);
	Matrix24 K;
	Vector24 F;
	EXPECT_FALSE(contactTerms(c, bi, bj, K, F));
	Di.head<3>() = -1e-4 * n;
	evaluate(Di);
	EXPECT_EQ(c.trial.state, ContactState::Locked);
	const double N = c.normalStiffness * 1e-4;
	EXPECT_NEAR(c.trial.normalForce, N, 1e-9 * N);
	// Apart by a hair is open: an unbonded contact never pulls.
	Di.head<3>() = 1e-12 * n;
	evaluate(Di);
	EXPECT_EQ(c.trial.state, ContactState::Open);

	// Tangential motion: locked within tan(phi) N / ks, sliding beyond, along it.
	const double reach = std::tan(phi) * N / c.shearStiffness;
	Di.head<3>() = -1e-4 * n + 0.99 * reach * t;
	evaluate(Di);
	EXPECT_EQ(c.trial.state, ContactState::Locked);
	Di.head<3>() = -1e-4 * n + 1.01 * reach * t;
	evaluate(Di);
	EXPECT_EQ(c.trial.state, ContactState::Sliding);
	EXPECT_LT((c.trial.slidingDirection - t).norm(), 1e-9);
	EXPECT_NEAR(c.slipLimit, std::tan(phi) * N, 1e-9 * N);
	// Its tangential force is the limit, against the slip.
	EXPECT_LT((tangentialForce(c, bi, bj, Di, Dj) + c.slipLimit * t).norm(), 1e-9 * c.slipLimit);

	// After the step the spring keeps the stretch that carries the limit.
	finishContact(c, bi, bj, Di, Dj);
	const Vector3 stretched = (c.trial.anchorI + Di.head<3>()) - c.trial.anchorJ;
	EXPECT_NEAR((stretched - n * n.dot(stretched)).norm(), reach, 1e-9 * reach);
	EXPECT_LT((c.trial.shearForce + c.slipLimit * t).norm(), 1e-9 * c.slipLimit);
}

TEST(ContactMechanics, AStepsEnergySplitsTheForcesWorkExactly) {
	// contactStepEnergy's terms against the work of the forces the model
	// applies, F(D) . D (the scheme's kinetic energy change): for random
	// stretches, slips and gaps, start - end - damping - friction == work,
	// with damping and friction >= 0 (seeded; printed on failure).
	const unsigned seed = 20261125;
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> u(-1, 1);
	const double phi = 0.6;
	const Block bi = blockAt(Vector3(0.2, -0.1, 1.1), 1e7, 1.0, phi);
	const Block bj = blockAt(Vector3(0.1, 0.3, -0.9), 2e7, 1.3, phi);
	int slipping = 0, locked = 0;
	for (int trial = 0; trial < 2000; ++trial) {
		Contact c = closedVertexFaceContact(bi, bj);
		c.normal.d0 = 1e-4 * u(rng);
		c.isNew = false;
		c.history.state = ContactState::Locked;
		const Vector3 tangent = (Vector3(u(rng), u(rng), u(rng)).cross(c.geometry.normal)).normalized();
		c.history.anchorI = c.geometry.pointI + 1e-5 * u(rng) * tangent;
		c.history.anchorJ = c.geometry.pointJ;
		startTrial(c, false);
		Vector12 Di = Vector12::Zero(), Dj = Vector12::Zero();
		for (int k = 0; k < 12; ++k) Di(k) = 1e-4 * u(rng);
		// The model at the solution (a converged iteration), with the limit of its normal force there.
		evaluateContact(c, bi, bj, Di, Dj);
		updateFrictionLimit(c, true);
		evaluateContact(c, bi, bj, Di, Dj);
		if (!isClosed(c)) continue;
		Matrix24 K;
		Vector24 F;
		ASSERT_TRUE(contactTerms(c, bi, bj, K, F));
		const Vector24 D = (Vector24() << Di, Dj).finished();
		const double work = (F - K * D).dot(D);
		const ContactStepEnergy e = contactStepEnergy(c, bi, bj, Di, Dj);
		const double scale = std::max({std::abs(work), e.start, e.end, e.damping, e.friction});
		EXPECT_NEAR(e.start - e.end - e.damping - e.friction, work, 1e-9 * scale) << "seed " << seed << " trial " << trial;
		EXPECT_GE(e.damping, -1e-12 * scale);
		EXPECT_GE(e.friction, -1e-12 * scale);
		(c.trial.state == ContactState::Sliding ? slipping : locked) += 1;
	}
	EXPECT_GT(slipping, 100);
	EXPECT_GT(locked, 100);
}

TEST(ContactMechanics, FrictionlessContactsSlideAndCarryNoFrictionTerms) {
	const Block bi = blockAt(Vector3(0, 0, 1), 1e7, 1.0, 0.0);
	const Block bj = blockAt(Vector3(0, 0, -1), 1e7, 1.0, 0.3);
	Contact c = closedVertexFaceContact(bi, bj);
	EXPECT_EQ(c.frictionTangent, 0.0);  // the smaller friction angle of the two blocks
	c.isNew = true;
	c.normal.d0 = -1e-6;  // already penetrating: starts closed
	startTrial(c, false);
	const Vector12 zero = Vector12::Zero();
	evaluateContact(c, bi, bj, zero, zero);
	EXPECT_EQ(c.trial.state, ContactState::Sliding);
	Matrix24 K;
	Vector24 F;
	ASSERT_TRUE(contactTerms(c, bi, bj, K, F));
	const Vector24 e = (Vector24() << c.normal.ei, c.normal.ej).finished();
	EXPECT_LT((F + c.normalStiffness * c.normal.d0 * e).norm(), 1e-12 * F.norm());
}

TEST(ContactMechanics, PenaltyScalesWithTheSofterBlock) {
	const Block bi = blockAt(Vector3(0, 0, 1), 1e9, 2.0, 0.3);
	const Block bj = blockAt(Vector3(0, 0, -1), 1e7, 1.0, 0.3);
	IntegratorSettings settings;
	Contact c = closedVertexFaceContact(bi, bj);
	prepareContact(c, bi, bj, settings);
	EXPECT_DOUBLE_EQ(c.normalStiffness, settings.contactPenaltyFactor * 1e7 * 1.0);
	EXPECT_DOUBLE_EQ(c.shearStiffness, settings.shearStiffnessRatio * c.normalStiffness);
}

TEST(ContactMechanics, SecantForceIsTheDiscreteGradientOfTheSpringEnergy) {
	// The secant slope h(d) of U (normalSecant) against its definition and its
	// derivative against finite differences, on random start and end gaps
	// across every case (closed or apart at either end, bonded): h (d - d0) =
	// U(d) - U(d0) exactly (the secant force's work is minus the energy's
	// change), h' = dh/dd >= 0 and h non-decreasing in d (U convex, so the
	// step's energy stays convex).
	std::mt19937 rng(20261125);
	std::uniform_real_distribution<double> gap(-1e-3, 1e-3);
	const double kn = 4e10;
	for (int k = 0; k < 20000; ++k) {
		const bool bonded = k % 5 == 0;
		const double d0 = gap(rng), d = gap(rng);
		if (std::abs(d - d0) < 1e-6) continue;
		const NormalSecant h = normalSecant(bonded, kn, d0, d);
		const double change = normalSpringEnergy(bonded, kn, d) - normalSpringEnergy(bonded, kn, d0);
		ASSERT_NEAR(h.value * (d - d0), change, 1e-12 * kn * 1e-6 + 1e-10 * std::abs(change)) << d0 << " " << d;
		const double step = 1e-9;
		const double fd = (normalSecant(bonded, kn, d0, d + step).value - normalSecant(bonded, kn, d0, d - step).value) /
		                  (2 * step);
		ASSERT_NEAR(h.slope, fd, 1e-5 * kn) << d0 << " " << d;
		ASSERT_GE(h.slope, 0.0);
		ASSERT_LE(h.value, normalSecant(bonded, kn, d0, d + 1e-5).value + 1e-9 * kn * 1e-5);
	}
	// at d = d0 the secant is the spring's own slope: no division by zero
	const NormalSecant same = normalSecant(false, kn, -1e-4, -1e-4);
	EXPECT_DOUBLE_EQ(same.value, -kn * 1e-4);
	EXPECT_TRUE(std::isfinite(normalSecant(false, kn, 0.0, 1e-4).value));
	EXPECT_TRUE(std::isfinite(normalSecant(false, kn, 1e-4, 0.0).value));
}

// The line search's bisection (searchLine) with and without the certified
// skipping of evaluations: bitwise the same step on random groups of lines
// (compressed, opening and bonded normal springs, sticking and slipping
// shear springs, sizes over six decades, the root placed anywhere in (0, 1)
// or at a kink, and groups whose derivative is mostly round-off), with far
// fewer evaluations where the derivative is not. Under Shi's scheme, and
// under Newmark members with gamma in [1/2, 1) (the secant normal force from
// a random start gap, the springs weighted as Contact weights them).
namespace {
void certifiedSearchTrials(bool secant) {
	std::mt19937 rng(secant ? 2025 : 2024);
	std::uniform_real_distribution<double> u(0, 1);
	auto logUniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, u(rng)); };
	auto sign = [&]() { return u(rng) < 0.5 ? -1.0 : 1.0; };
	long plainEvaluations = 0, certifiedEvaluations = 0, searched = 0;
	for (int trial = 0; trial < 4000; ++trial) {
		const int count = static_cast<int>(logUniform(1, 3000));
		// 0, 1: generic; 2: root at a kink; 3: small rates; 4: pairs of deep
		// contacts whose terms cancel, so that the computed derivative is
		// round-off over a wide zone about the root (not monotone there).
		const int kind = trial % 5;
		// Average acceleration (1/2) in a quarter of the trials, where the
		// spring's weight is 0 and the secant carries the normal force.
		const double gamma = !secant ? 1.0 : trial % 4 == 0 ? 0.5 : 0.5 + 0.5 * u(rng);
		std::vector<ContactLine> lines(count);
		for (ContactLine& line : lines) {
			line.normalStiffness = 4e12;
			line.shearStiffness = 1.6e12;
			line.gap = u(rng) < 0.4 ? -logUniform(1e-10, 1e-6) : logUniform(1e-10, 1e-5);
			line.gapRate = sign() * logUniform(1e-12, 1e-6);
			line.bonded = u(rng) < 0.05;
			line.tangential = u(rng) < 0.6;
			if (line.tangential) {
				for (int i = 0; i < 3; ++i) {
					line.stretch(i) = sign() * logUniform(1e-11, 1e-6);
					line.stretchRate(i) = sign() * logUniform(1e-12, 1e-6);
				}
				line.limit = logUniform(1e2, 1e7);
			}
			if (kind == 3) line.gapRate *= 1e-4;
			if (secant) {
				// As prepareContact and contactLine set them.
				line.springWeight = (2 * gamma - 1) / gamma;
				line.secantWeight = 2 * (1 - gamma) / gamma;
				line.tangentialWeight = 1 / gamma;
				// The start gap: closed or apart, about the gap or far from it.
				line.startGap = u(rng) < 0.3 ? line.gap + sign() * logUniform(1e-12, 1e-6)
				                             : (u(rng) < 0.5 ? -1.0 : 1.0) * logUniform(1e-10, 1e-5);
			}
		}
		if (kind == 4)
			for (int c = 0; c + 1 < count; c += 2) {
				ContactLine &first = lines[c], &second = lines[c + 1];
				first.bonded = second.bonded = false;
				first.tangential = second.tangential = false;
				first.gap = second.gap = -logUniform(1e-3, 1e-1);
				first.gapRate = logUniform(1e-13, 1e-10);
				second.gapRate = -first.gapRate;
				if (secant) first.startGap = second.startGap = -logUniform(1e-3, 1e-1);
			}
		double curvature = logUniform(1e-3, 1e3) * (kind >= 3 ? 1e-6 : 1.0);
		double root = u(rng);
		if (kind == 2) {
			// At a normal spring's kink: where its gap changes sign.
			ContactLine& line = lines[static_cast<std::size_t>(u(rng) * count) % count];
			line.bonded = false;
			root = std::min(0.999, std::max(0.001, root));
			line.gap = -root * line.gapRate;
		}
		double atRoot = root * curvature;
		for (const ContactLine& line : lines) atRoot += line.derivative(root);
		const double slope = -atRoot;
		long plain = 0, certified = 0;
		const double a = searchLine(lines.data(), lines.data() + count, slope, curvature, false, &plain);
		const double b = searchLine(lines.data(), lines.data() + count, slope, curvature, true, &certified);
		ASSERT_EQ(a, b) << "trial " << trial << " lines " << count << " kind " << kind;
		if (a < 1) {
			++searched;
			plainEvaluations += plain;
			certifiedEvaluations += certified;
		}
	}
	EXPECT_GT(searched, 2400);
	EXPECT_LT(certifiedEvaluations, 0.6 * plainEvaluations) << certifiedEvaluations << " of " << plainEvaluations;
	std::printf("%s: evaluations: %ld certified, %ld plain, %ld searches\n", secant ? "gamma < 1" : "Shi",
	            certifiedEvaluations, plainEvaluations, searched);
}
}  // namespace

TEST(ContactMechanics, CertifiedLineSearchTakesTheBisectionsStep) { certifiedSearchTrials(false); }

TEST(ContactMechanics, CertifiedLineSearchTakesTheBisectionsStepWithTheSecant) { certifiedSearchTrials(true); }
