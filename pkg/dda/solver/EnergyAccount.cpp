// The energy account of a World (World::energy, World::accountStep; the
// terms are EnergyAccount's in IntegratorSettings.hpp).
#include "World.hpp"

#include "StepClock.hpp"

namespace dda {

EnergyAccount World::energy() const {
	EnergyAccount account = energy_;
	account.kinetic = account.gravity = account.gravityChange = account.strain = 0;
	for (const Block& block : blocks_) {
		if (block.fixed) continue;
		account.gravity -= block.mass * gravity_.dot(block.centroid);
		account.gravityChange -= block.mass * gravity_.dot(block.centroid - block.initialCentroid);
		account.kinetic += kineticEnergy(block, block.velocity);
		if (!block.rigid && !block.stress.isZero())
			// W = V0/2 tau^T E^-1 tau, tau = (V / V0) sigma (BlockEquations.hpp).
			account.strain += 0.5 * (block.volume * block.volume / block.referenceVolume()) *
			                  block.stress.dot(block.elasticity().ldlt().solve(block.stress));
	}
	return account;
}

void World::accountStep(const IntegratorSettings& settings, double dt) {
	// Blocks. Shi's scheme (v1 = 2D/dt - v0, (2/dt^2) M D = (2/dt) M v0 + F(D))
	// gives 1/2 v1^T M v1 - 1/2 v0^T M v0 = F(D) . D exactly: the kinetic
	// energy changes by the work of the end-of-step forces over D. Gravity's
	// work is minus the change of its potential exactly (the centroid moves
	// by D's translation). The elastic force -V0 (tau0 + E eps) has the
	// potential V0 (tau0 . eps + eps^T E eps / 2) (the change of the strain
	// energy, at any strain: BlockEquations.hpp, "Finite strain") and the
	// Bregman divergence V0/2 eps^T E eps: the damping. Point
	// loads and fixed-point springs (end-of-step force) do the work F . u.
	// Every member of Newmark's family with beta = gamma/2 moves the blocks
	// by the trapezoidal rule, D = dt (v0 + v1)/2, so exactly
	//   dKE = ((1 - gamma) F_s(0) + gamma F_s(D)) . D + G . D,
	// F_s the blocks' own forces (a0 = M^-1 F_s(0)) and G the contacts'
	// mean force (ContactEquations.hpp). F_s is affine in D: the elastic
	// force's work is minus the change of the strain energy minus (2 gamma
	// - 1) times its Bregman divergence (the damping; 0 for average
	// acceleration), a fixed point's F(0) (1 - gamma) + F(D) gamma.
	// Each block's damping terms are computed on any thread, then added in
	// block order (the loads' terms, few, in the same pass).
	const double gamma = settings.newmarkGamma;
	const std::vector<int>& moving = openClose_.moving();
	const int n = static_cast<int>(moving.size());
	blockEnergies_.resize(moving.size());
#pragma omp parallel for schedule(static) if (n >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k) {
		const Block& block = blocks_[moving[k]];
		const Vector12& D = openClose_.solution(k);
		BlockStepEnergy& e = blockEnergies_[k];
		// Velocities scaled by velocityRatio at the step's start: the
		// kinetic energy removed is damping.
		const double ratio = settings.velocityRatio;
		e.scaling = ratio < 1 ? (1 - ratio * ratio) * kineticEnergy(block, block.velocity) : 0;
		e.strained = !block.rigid;
		if (e.strained) {
			// (2 gamma - 1) times the Bregman divergence, plus the strain
			// viscosity's work (eta/dt) V0 eps^T E eps (BlockEquations.hpp).
			const Vector6 strain = D.segment<6>(6);
			const double elastic = block.referenceVolume() * strain.dot(block.elasticity() * strain);
			e.strain = (2 * gamma - 1) * 0.5 * elastic;
			if (settings.strainDamping > 0)
				e.strain += strainViscosity(block, settings.strainDamping) / dt * elastic;
		}
		e.loaded = !block.loads.empty() || !block.fixedPoints.empty();
	}
	for (int k = 0; k < n; ++k) {
		const BlockStepEnergy& e = blockEnergies_[k];
		if (settings.velocityRatio < 1) energy_.damping += e.scaling;
		if (e.strained) energy_.damping += e.strain;
		if (!e.loaded) continue;
		const Block& block = blocks_[moving[k]];
		const Vector12& D = openClose_.solution(k);
		for (const PointLoad& load : block.loads)
			energy_.loads += load.force.dot(displacementAt(load.position - block.centroid, D));
		for (const FixedPoint& point : block.fixedPoints) {
			const double stiffness = fixedPointStiffness(point, block, settings);
			const Vector3 u = displacementAt(point.position - block.centroid, D);
			energy_.loads += stiffness * (point.anchor - point.position - gamma * u).dot(u);
		}
	}
	accountContacts(gamma);
}

void World::accountContacts(double gamma) {
	// Contacts: their springs' energy at the start of this step in the
	// accepted states against what the last step ended with. Each contact's
	// terms are computed on any thread, then summed in contact order.
	const std::vector<Contact>& contacts = store_.contacts();
	const int contactCount = static_cast<int>(contacts.size());
	const bool shaking = this->shaking();
	contactEnergies_.resize(contacts.size());
#pragma omp parallel for schedule(static) if (contactCount >= kMinContactsForThreads)
	for (int c = 0; c < contactCount; ++c) {
		const Contact& contact = contacts[c];
		const int bi = contact.bodyI, bj = contact.bodyJ;
		contactEnergies_[c] = contactStepEnergy(contact, blocks_[bi], blocks_[bj], openClose_.solutionOf(bi),
		                                        openClose_.solutionOf(bj));
		// A prescribed motion's work through the contact (PrescribedMotion.cpp).
		if (shaking) contactEnergies_[c].boundary = boundaryWork(contact, gamma);
	}
	double start = 0, end = 0;
	for (const ContactStepEnergy& e : contactEnergies_) {
		start += e.start;
		end += e.end;
		energy_.damping += e.damping;
		energy_.friction += e.friction;
		energy_.boundaryWork += e.boundary;
	}
	energy_.contactChanges += start - energy_.contact;
	energy_.contact = end;
}

}  // namespace dda
