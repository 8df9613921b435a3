#include "ContactEquations.hpp"

#include <algorithm>
#include <cmath>

namespace dda {

namespace {

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

// Friction or an intact bond can hold a contact locked.
bool canLock(const Contact& contact) { return contact.frictionTangent > 0 || contact.trial.bonded; }

// State a contact takes when it closes: locked, unless nothing can lock it.
void close(Contact& contact) {
	ContactHistory& trial = contact.trial;
	trial.state = canLock(contact) ? ContactState::Locked : ContactState::Sliding;
	trial.anchorI = contact.geometry.pointI;
	trial.anchorJ = contact.geometry.pointJ;
	trial.slidingDirection.setZero();
}

// The shear spring's stretch: where block i's anchor ends minus where block j's does [m].
Vector3 anchorSeparation(const ContactHistory& trial, const Block& blockI, const Block& blockJ, const Vector12& Di,
                         const Vector12& Dj) {
	return (trial.anchorI + displacementAt(trial.anchorI - blockI.centroid, Di)) -
	       (trial.anchorJ + displacementAt(trial.anchorJ - blockJ.centroid, Dj));
}

// Normal force of a closed contact at linearised gap `gap` [N]: compressive
// > 0; tension only while bonded.
double normalForce(const Contact& contact, double gap) {
	const double force = -contact.normalStiffness * gap;
	return contact.trial.bonded ? force : std::max(0.0, force);
}

}  // namespace

void prepareContact(Contact& contact, const Block& blockI, const Block& blockJ, const IntegratorSettings& settings) {
	const double stiffnessI = blockI.material.young * blockI.size;
	const double stiffnessJ = blockJ.material.young * blockJ.size;
	contact.normalStiffness = settings.contactPenaltyFactor * std::min(stiffnessI, stiffnessJ);
	contact.shearStiffness = settings.shearStiffnessRatio * contact.normalStiffness;
	contact.frictionTangent = std::tan(std::min(blockI.material.frictionAngle, blockJ.material.frictionAngle));
	contact.cohesionForce = std::min(blockI.material.cohesion, blockJ.material.cohesion) * contact.area;
	contact.tensileForce = std::min(blockI.material.tensileStrength, blockJ.material.tensileStrength) * contact.area;
	contact.normal = linearizeNormalDistance(contact.geometry.stencil, blockI.centroid, blockJ.centroid);
}

void startTrial(Contact& contact, bool formBonds) {
	if (!contact.isNew) {
		contact.trial = contact.history;
	} else {
		contact.trial = ContactHistory();
		if (contact.normal.valid && contact.normal.d0 <= 0) {
			contact.trial.bonded = formBonds && (contact.cohesionForce > 0 || contact.tensileForce > 0);
			close(contact);
			contact.trial.normalForce = -contact.normalStiffness * contact.normal.d0;
		}
	}
	if (!contact.normal.valid) contact.trial.state = ContactState::Open;
}

void startSlidingIfMoving(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Vi,
                          const Vector12& Vj, double dt) {
	ContactHistory& trial = contact.trial;
	if (!contact.isNew || trial.state != ContactState::Locked || trial.bonded) return;
	const Vector3 velocity = displacementAt(contact.geometry.pointI - blockI.centroid, Vi) -
	                         displacementAt(contact.geometry.pointJ - blockJ.centroid, Vj);
	const Vector3 tangential = tangentProjector(contact.geometry.normal) * velocity;
	const double speed = tangential.norm();
	if (!(contact.shearStiffness * speed * dt > contact.frictionTangent * std::max(0.0, trial.normalForce))) return;
	trial.state = ContactState::Sliding;
	trial.slidingDirection = tangential / speed;
}

double contactGap(const Contact& contact, const Vector12& Di, const Vector12& Dj) {
	return contact.normal.d0 + contact.normal.ei.dot(Di) + contact.normal.ej.dot(Dj);
}

TangentialTerm tangentialTerm(const Contact& contact) {
	const ContactHistory& trial = contact.trial;
	if (trial.state == ContactState::Locked) return TangentialTerm::ShearSpring;
	if (trial.state == ContactState::Sliding && contact.frictionTangent > 0 && trial.normalForce > 0)
		return TangentialTerm::FrictionLoad;  // sliding: never bonded
	return TangentialTerm::None;
}

bool contactTerms(const Contact& contact, const Block& blockI, const Block& blockJ, Matrix24& stiffness,
                  Vector24& force) {
	const ContactHistory& trial = contact.trial;
	if (!closed(trial.state)) return false;
	const Vector24 e = stacked(contact.normal.ei, contact.normal.ej);
	const double kn = contact.normalStiffness;
	stiffness.noalias() = kn * e * e.transpose();
	force.noalias() = -kn * contact.normal.d0 * e;

	const Vector3& n = contact.geometry.normal;
	const TangentialTerm tangential = tangentialTerm(contact);
	if (tangential == TangentialTerm::ShearSpring) {
		const Eigen::Matrix<double, 3, 24> G = relativeDisplacementMatrix(blockI, trial.anchorI, blockJ, trial.anchorJ);
		const Matrix3 P = tangentProjector(n);
		const double ks = contact.shearStiffness;
		stiffness.noalias() += ks * G.transpose() * P * G;
		force.noalias() -= ks * G.transpose() * (P * (trial.anchorI - trial.anchorJ));
	} else if (tangential == TangentialTerm::FrictionLoad) {
		const Eigen::Matrix<double, 3, 24> H =
		    relativeDisplacementMatrix(blockI, contact.geometry.pointI, blockJ, contact.geometry.pointJ);
		force.noalias() -= H.transpose() * (contact.frictionTangent * trial.normalForce * trial.slidingDirection);
	}
	return true;
}

bool updateContactState(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di,
                        const Vector12& Dj, double openTolerance) {
	ContactHistory& trial = contact.trial;
	const ContactState before = trial.state;
	if (!contact.normal.valid) {
		trial.state = ContactState::Open;
		return before != trial.state;
	}
	const double gap = contactGap(contact, Di, Dj);
	const Vector3& n = contact.geometry.normal;

	if (!closed(before)) {
		if (!(gap < 0)) return false;
		// A contact that closes is locked (sliding if nothing can lock it)
		// for the next solve, whatever this solve's tangential motion: its
		// normal force and shear are known only from a solve with it closed.
		// Judged now, against -kn x the gap of a solve without the contact (a
		// fictitious force, easily 100 x the weight), that force drove a
		// friction load that lifted the block open again, and the iteration
		// cycled (near-parallel edges, tests/py/test_hard_cases.py).
		close(contact);
		trial.normalForce = normalForce(contact, gap);
		return true;
	}
	if (gap > openTolerance) {
		// A bond holds in tension up to its strength; beyond, it breaks.
		if (!(trial.bonded && contact.normalStiffness * gap <= contact.tensileForce)) {
			trial.state = ContactState::Open;
			trial.bonded = false;
		}
	}
	if (!closed(trial.state)) {
		trial.normalForce = 0;
		return before != trial.state;
	}
	trial.normalForce = normalForce(contact, gap);
	if (!canLock(contact)) {
		trial.state = ContactState::Sliding;
		return before != trial.state;
	}

	// An unbonded closed contact without normal force (its gap inside the
	// opening band) has no friction capacity to compare with: it keeps its
	// state rather than flip on round-off of a vanishing shear.
	if (!trial.bonded && trial.normalForce <= 0) return before != trial.state;
	const Matrix3 P = tangentProjector(n);
	if (trial.state == ContactState::Locked) {
		const Vector3 delta = anchorSeparation(trial, blockI, blockJ, Di, Dj);
		const Vector3 shear = P * delta;
		const double shearNorm = shear.norm();
		const double strength = contact.frictionTangent * std::max(0.0, trial.normalForce) +
		                        (trial.bonded ? contact.cohesionForce : 0.0);
		if (contact.shearStiffness * shearNorm > strength && shearNorm > 0) {
			trial.state = ContactState::Sliding;
			trial.slidingDirection = shear / shearNorm;
			trial.bonded = false;
		}
	} else {
		const Vector3 motion = displacementAt(contact.geometry.pointI - blockI.centroid, Di) -
		                       displacementAt(contact.geometry.pointJ - blockJ.centroid, Dj);
		const Vector3 tangential = P * motion;
		if (tangential.dot(trial.slidingDirection) > 0) {
			trial.slidingDirection = tangential.normalized();
		} else {
			trial.state = ContactState::Locked;
			trial.anchorI = contact.geometry.pointI;
			trial.anchorJ = contact.geometry.pointJ;
		}
	}
	return before != trial.state;
}

void finishContact(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di, const Vector12& Dj) {
	ContactHistory& trial = contact.trial;
	trial.shearForce.setZero();
	if (!closed(trial.state) || !contact.normal.valid) {
		trial.normalForce = 0;
		return;
	}
	const double gap = contactGap(contact, Di, Dj);
	trial.normalForce = normalForce(contact, gap);
	const Matrix3 P = tangentProjector(contact.geometry.normal);
	if (trial.state == ContactState::Locked) {
		const Vector3 delta = anchorSeparation(trial, blockI, blockJ, Di, Dj);
		trial.shearForce = -contact.shearStiffness * (P * delta);
	} else {
		trial.shearForce = -contact.frictionTangent * trial.normalForce * trial.slidingDirection;
	}
}

}  // namespace dda
