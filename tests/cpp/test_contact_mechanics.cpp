// Contact springs and friction of one sub-contact (solver/ContactEquations):
// their stiffness and force terms against finite differences of the exact
// contact energy, and the open-close state rules.
#include "dda/solver/ContactEquations.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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

}  // namespace

TEST(ContactMechanics, LockedTermsAreTheHessianAndGradientOfTheExactEnergy) {
	const Block bi = blockAt(Vector3(0.2, -0.1, 1.1), 1e7, 1.0, 0.5);
	const Block bj = blockAt(Vector3(0.1, 0.3, -0.9), 2e7, 1.3, 0.6);
	Contact c = closedVertexFaceContact(bi, bj);
	ASSERT_TRUE(c.normal.valid);
	ASSERT_NEAR(c.normal.d0, 0.0, 1e-15);
	c.trial.state = ContactState::Locked;
	// Anchors a little apart in the tangent plane: a pre-stretched shear spring.
	const Vector3 tangent = c.geometry.normal.unitOrthogonal();
	c.trial.anchorI = c.geometry.pointI + 1e-3 * tangent;
	c.trial.anchorJ = c.geometry.pointJ;

	Matrix24 K;
	Vector24 F;
	ASSERT_TRUE(contactTerms(c, bi, bj, K, F));
	EXPECT_NEAR((K - K.transpose()).norm(), 0.0, 1e-9 * K.norm());

	// Gradient: F = -dE/dD at D = 0; Hessian: K = d2E/dD2 at D = 0.
	const double h = 1e-6;
	Vector24 gradient;
	Matrix24 hessian;
	for (int a = 0; a < 24; ++a) {
		Vector24 e = Vector24::Zero();
		e(a) = h;
		gradient(a) = (lockedEnergy(c, bi, bj, e) - lockedEnergy(c, bi, bj, -e)) / (2 * h);
		for (int b = 0; b < 24; ++b) {
			Vector24 f = Vector24::Zero();
			f(b) = h;
			hessian(a, b) = (lockedEnergy(c, bi, bj, e + f) - lockedEnergy(c, bi, bj, e - f) -
			                 lockedEnergy(c, bi, bj, -e + f) + lockedEnergy(c, bi, bj, -e - f)) /
			                (4 * h * h);
		}
	}
	EXPECT_LT((F + gradient).norm(), 1e-6 * gradient.norm());
	EXPECT_LT((K - hessian).norm(), 1e-6 * hessian.norm());
}

TEST(ContactMechanics, SlidingFrictionOpposesTheRelativeMotionWithTanPhiTimesN) {
	const double phi = 0.4;
	const Block bi = blockAt(Vector3(0, 0, 1), 1e7, 1.0, phi);
	const Block bj = blockAt(Vector3(0, 0, -1), 1e7, 1.0, phi);
	Contact c = closedVertexFaceContact(bi, bj);
	c.trial.state = ContactState::Sliding;
	const Vector3 l = c.geometry.normal.unitOrthogonal();
	c.trial.slidingDirection = l;
	c.trial.normalForce = 1234.5;
	Matrix24 K;
	Vector24 F;
	ASSERT_TRUE(contactTerms(c, bi, bj, K, F));
	// The friction part of F, with the normal spring part removed (d0 = 0, so it is 0).
	const Vector3 onBlockI = F.head<3>(), onBlockJ = F.segment<3>(12);
	EXPECT_LT((onBlockI + std::tan(phi) * 1234.5 * l).norm(), 1e-9 * 1234.5);
	EXPECT_LT((onBlockI + onBlockJ).norm(), 1e-9 * 1234.5);  // action and reaction
	// Sliding adds the normal spring only: rank one along e.
	const Vector24 e = (Vector24() << c.normal.ei, c.normal.ej).finished();
	EXPECT_LT((K - c.normalStiffness * e * e.transpose()).norm(), 1e-12 * K.norm());
}

TEST(ContactMechanics, OpenCloseRules) {
	const double phi = 0.5;
	const Block bi = blockAt(Vector3(0, 0, 1), 1e7, 1.0, phi);
	const Block bj = blockAt(Vector3(0, 0, -1), 1e7, 1.0, phi);
	Contact c = closedVertexFaceContact(bi, bj);
	const Vector3 n = c.geometry.normal;
	const Vector3 t = n.unitOrthogonal();
	Vector12 Di = Vector12::Zero();
	const Vector12 Dj = Vector12::Zero();
	Matrix24 K;
	Vector24 F;

	// Open: no terms; it closes (locked, as there is friction) when the gap goes negative.
	c.trial = ContactHistory();
	EXPECT_FALSE(contactTerms(c, bi, bj, K, F));
	Di.head<3>() = 1e-4 * n;  // moving apart: stays open
	EXPECT_FALSE(updateContactState(c, bi, bj, Di, Dj, 0));
	Di.head<3>() = -1e-4 * n;  // into the face
	EXPECT_TRUE(updateContactState(c, bi, bj, Di, Dj, 0));
	EXPECT_EQ(c.trial.state, ContactState::Locked);
	EXPECT_NEAR(c.trial.normalForce, c.normalStiffness * 1e-4, 1e-9 * c.normalStiffness * 1e-4);

	// Locked: a tangential motion whose spring force exceeds tan(phi) N slides.
	const double N = c.normalStiffness * 1e-4;
	const double slip = 1.01 * std::tan(phi) * N / c.shearStiffness;
	Di.head<3>() = -1e-4 * n + slip * t;
	EXPECT_TRUE(updateContactState(c, bi, bj, Di, Dj, 0));
	EXPECT_EQ(c.trial.state, ContactState::Sliding);
	EXPECT_LT((c.trial.slidingDirection - t).norm(), 1e-12);
	// ... and below it stays locked.
	c.trial.state = ContactState::Locked;
	Di.head<3>() = -1e-4 * n + 0.99 * slip * t;
	EXPECT_FALSE(updateContactState(c, bi, bj, Di, Dj, 0));

	// Sliding: keeps sliding along the motion; locks when the motion reverses.
	c.trial.state = ContactState::Sliding;
	c.trial.slidingDirection = t;
	Di.head<3>() = -1e-4 * n + 1e-3 * t;
	EXPECT_FALSE(updateContactState(c, bi, bj, Di, Dj, 0));
	Di.head<3>() = -1e-4 * n - 1e-3 * t;
	EXPECT_TRUE(updateContactState(c, bi, bj, Di, Dj, 0));
	EXPECT_EQ(c.trial.state, ContactState::Locked);

	// Closed: opens only above the tolerance.
	Di.head<3>() = 1e-9 * n;
	EXPECT_FALSE(updateContactState(c, bi, bj, Di, Dj, 2e-9));
	EXPECT_TRUE(updateContactState(c, bi, bj, Di, Dj, 0.5e-9));
	EXPECT_EQ(c.trial.state, ContactState::Open);
	EXPECT_EQ(c.trial.normalForce, 0.0);
}

TEST(ContactMechanics, FrictionlessContactsSlideAndCarryNoFrictionTerms) {
	const Block bi = blockAt(Vector3(0, 0, 1), 1e7, 1.0, 0.0);
	const Block bj = blockAt(Vector3(0, 0, -1), 1e7, 1.0, 0.3);
	Contact c = closedVertexFaceContact(bi, bj);
	EXPECT_EQ(c.frictionTangent, 0.0);  // the smaller friction angle of the two blocks
	c.isNew = true;
	c.normal.d0 = -1e-6;  // already penetrating: starts closed
	startTrial(c, false);
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
