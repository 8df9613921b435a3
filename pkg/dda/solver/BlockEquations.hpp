// The equations of one block for one time step, without contacts, and the
// update of its state once the step is accepted.
//
// Newmark's family (IntegratorSettings::newmarkBeta, newmarkGamma):
//   D = v0 dt + dt^2 ((1/2 - beta) a0 + beta a1),
//   v1 = v0 + dt ((1 - gamma) a0 + gamma a1),
// with a1 the end-of-step acceleration, M a1 = F(D). Solving the first for
// a1 makes the inertia force -M a1 contribute
//   (1 / (beta dt^2)) M D = M (v0 / (beta dt) + (1 / (2 beta) - 1) a0) + F(D),
// M the consistent mass matrix (Displacement.hpp). Shi's scheme is beta =
// 1/2, gamma = 1 (a constant acceleration over the step): (2/dt^2) M D =
// (2/dt) M v0 + F(D), v1 = 2 D / dt - v0, and a0 drops out. Further terms of
// F, each the derivative of a potential energy with respect to D:
//   elastic strain energy     V0/2 eps^T E eps       -> K_ee += V0 E
//   stress of the last step   V sigma^T eps          -> F_e  -= V sigma
//   gravity                   -m g . t               -> F_t  += m g
//   fixed point (penalty k)   k/2 |x + T(x)D - a|^2  -> K += k T^T T, F += k T^T (a - x)
//   point load f at x         -f . T(x) D            -> F += T^T f
// Shi's scheme is exact for a constant acceleration (free fall) and, being
// Newmark with gamma = 1, dissipates high frequencies: it never creates
// energy. Average acceleration (1/4, 1/2) keeps a linear system's energy.
//
// Finite strain. A block's state carries the Cauchy stress sigma and its
// volume V; V0 = Block::referenceVolume() is its volume at creation and
// tau = (V / V0) sigma its Kirchhoff stress. The step's strain unknowns eps
// are a strain increment in the block's start frame; the step moves a point
// by x -> c' + R (I + eps)(x - c) (strain, then the exact rotation R), and
// the stress follows
//   tau1 = R (tau0 + E eps) R^T,
// an increment of E eps per unit reference volume (Hencky's law for
// increments: summed over many steps eps is the logarithmic strain). The
// strain energy is the state function W = V0/2 tau^T E^-1 tau (E isotropic,
// so turning tau leaves W unchanged), and the step's elastic force
// -V0 (tau0 + E eps) = -(V sigma0 + V0 E eps) is exactly -dW/d(eps): the
// stored energy changes by exactly the work of the step's elastic force
// (no energy from nowhere, however large the strain). Earlier versions used
// V E and sigma1 = R sigma0 R^T + E eps: the elastic force V sigma then falls
// as a compressed block's volume shrinks (it peaks near a strain of -1), so a
// heavily loaded soft block had no equilibrium and was crushed flat, and the
// account drifted by (V1 - V0)/2 sigma1^T E^-1 sigma1 each step.
#pragma once

#include "IntegratorSettings.hpp"
#include "dda/block/Block.hpp"

namespace dda {

// Strain viscosity (IntegratorSettings::strainDamping, zeta). A deformable
// block's strain rates carry the Kelvin-Voigt stress eta E d(eps)/dt. Over a
// step the mean strain rate is eps/dt (the trapezoidal rule), so the step's
// mean viscous force is G_v = -(eta/dt) V0 E eps: in the system (normalised
// by gamma, as the contacts' mean forces) K_ee += (eta / (gamma dt)) V0 E.
// Its work D . G_v = -(eta/dt) V0 eps^T E eps <= 0 is dissipated and booked
// as damping (World::accountStep): it never creates energy, and it adds a
// convex quadratic to the step's energy (line search and passes unchanged).
// eta = 2 zeta / omega_ref [s], omega_ref = sqrt(2 G / (rho j)) with G the
// shear modulus, rho the current density and j the largest eigenvalue of
// the second moments per unit volume: for boxes of any proportions and
// Poisson's ratio the block's lowest elastic (free-free strain) frequency
// is 1 to 1.22 omega_ref, so that mode is damped at zeta to 1.22 zeta and
// higher ones more. It acts on strain rates only: rigid motion and steady
// strain (a block sliding or at rest) feel nothing, and quasi-static results
// are those without it.
//
// Why: a DDA block is one constant-strain element, and on contact springs
// with Coulomb friction its strain modes and the friction form a flutter
// (mode-coupling) instability while it slides. The friction's pull at the
// base stretches the block (E_xx) where the front and back normal forces
// differ, Poisson's ratio turns the stretch into a height change that moves
// every normal force, and the total friction's moment about the centroid
// turns the base again: a loop that is not symmetric (the friction force
// follows the normal displacement, not the tangential), so two modes merge
// into a growing pair. Without Poisson coupling, with rigid blocks or
// without friction there is none. A linear analysis of a sliding box
// (12 unknowns, four corner springs, friction along the slip) finds growth
// rates up to 0.3 omega_ref at friction 40 deg, and viscosity removes
// them at zeta 0.41 (worst of random boxes 0.3..3 m, Poisson 0..0.45,
// friction 5..40 deg, contactPenaltyFactor 40). Shi's scheme damps a mode
// of frequency omega at a rate of about omega^2 dt / 2, so it hid the
// instability at dt 1e-2 s and lost it as dt fell: a pushed block rocked
// on its corners at dt 1e-4 and 1e-5 s and ran 29 % and 66 % ahead of
// Coulomb's closed form.
double strainViscosity(const Block& block, double zeta);

struct BlockSystem {
	Matrix12 stiffness;
	Vector12 force;
};

// A fixed point's penalty stiffness [N/m]: its own, else the settings' default
// (fixedPointPenaltyFactor x E x block size).
inline double fixedPointStiffness(const FixedPoint& point, const Block& block, const IntegratorSettings& settings) {
	return point.stiffness > 0 ? point.stiffness : settings.fixedPointPenaltyFactor * block.material.young * block.size;
}

// Kinetic energy 1/2 v^T M v [J] of the rates v with the block's consistent
// mass matrix (6 x 6 for a rigid block: translation and rotation only).
inline double kineticEnergy(const Block& block, const Vector12& v) {
	if (block.rigid) {
		const Vector6 r = v.head<6>();
		return 0.5 * r.dot(rigidMassMatrix(block.density(), block.volume, block.secondMoment) * r);
	}
	return 0.5 * v.dot(massMatrix(block.density(), block.volume, block.secondMoment) * v);
}

// Start-of-step velocity: the carried velocity scaled by Shi's dynamic coefficient.
inline Vector12 startVelocity(const Block& block, const IntegratorSettings& settings) {
	return settings.velocityRatio * block.velocity;
}

// The block's own forces at D = 0 without inertia [N, N m, N m]: gravity,
// the stress of the last step, fixed-point springs and point loads.
Vector12 restForce(const Block& block, const IntegratorSettings& settings);
// The acceleration M^-1 f of a force f on the block [m/s^2, rad/s^2, 1/s^2]
// (a rigid block's strain part is zero).
Vector12 accelerationOf(const Block& block, const Vector12& force);

// The block's system for the step: inertia (Newmark's, above, from the start
// velocity startVelocity(block, settings) and the start acceleration a0,
// which Shi's scheme does not read) and its own forces.
void assembleBlock(const Block& block, const IntegratorSettings& settings, double dt, const Vector12& a0,
                   BlockSystem& system);
// A rigid block's system (assembleBlock calls it): inertia, gravity, fixed
// points and loads in the 6 translation-rotation unknowns only, computed as
// 6x6 (rigidMassMatrix, T's first 6 columns); no elastic or stress term. The
// strain rows and columns of `system` are left zero.
void assembleRigidBlock(const Block& block, const IntegratorSettings& settings, double dt, const Vector12& a0,
                        BlockSystem& system);

// End-of-step velocity of the step's D from the start velocity v0, in the
// start configuration: v1 = 2 D / dt - v0 for every member with beta =
// gamma/2, the only ones World accepts (their positions follow the
// trapezoidal rule, D = dt (v0 + v1)/2).
Vector12 endVelocity(const Vector12& D, const Vector12& v0, double dt);

// Solves the block's system. Without fixed points the translations decouple
// (the first moments about the centroid vanish), leaving a 3x3 diagonal and a
// 9x9 system; otherwise the full 12x12 one. Both by Cholesky (K is SPD). A
// rigid block: 3 + 3 (diagonal and rotation 3x3), or 6x6 with fixed points;
// its strain unknowns are returned exactly zero.
Vector12 solveBlock(const Block& block, const BlockSystem& system);

// Largest displacement of a vertex for the unknowns D [m]; +inf when D or a
// displacement is not finite.
double largestVertexDisplacement(const Block& block, const Vector12& D);
// The same for vertices of a block whose centroid is `centroid` (the other
// parts of a concave block, Block::body) [m].
double largestVertexDisplacement(const std::vector<Vector3>& vertices, const Vector3& centroid, const Vector12& D);

// The volume ratio det(I + S) a step's strain increment S gives a deformable
// block (1 for a rigid block) [-]. The step maps the block by R (I + S).
inline double stepJacobian(const Block& block, const Vector12& D) {
	return block.rigid ? 1.0 : (Matrix3::Identity() + strainTensor(D.segment<6>(6))).determinant();
}

// The map of one block's points over a step: x -> c' + (I + S) R (x - c), an
// exact rotation about the centroid c followed by the strain S, then the
// translation (c' = c + t). Vertices, supports, loads and contact anchors all
// move by it.
struct BlockMotion {
	Vector3 oldCentroid, newCentroid;
	Matrix3 rotation, deformation;  // R and R (I + S)
	Vector3 operator()(const Vector3& x) const { return newCentroid + deformation * (x - oldCentroid); }
};
BlockMotion blockMotion(const Block& block, const Vector12& D);

// Applies an accepted step: the strain in the block's start frame, then the
// exact rotation about the centroid, to vertices, supports, loads and mass
// properties; new velocity; stress update (see "Finite strain" above).
// A rigid block: rotation and translation only; volume kept, second moments
// turned (R J R^T), stress, strain and strain rates left exactly zero.
// `velocity` is the end velocity (endVelocity) in the start configuration.
void applyStep(Block& block, const Vector12& D, const Vector12& velocity);

// A later part of a concave block (Block::body) over its body's accepted
// step: its corners and centroid by the body's motion `move` (taken before
// applyStep moved the body), its own volume and second moments as applyStep
// moves the body's, its rotation the body's new one (call after applyStep).
void movePart(Block& part, const Block& body, const BlockMotion& move, const Vector12& D);

// A deformable block's rates (velocity: translation, spin, strain rates in the
// step's start frame) carried through the step's stretch U = I + S and
// rotation R to the new configuration so that their kinetic energy is
// unchanged (the proof is at the definition). A rigid block's spin is turned
// by R, the same rule with U = I.
Vector12 transportedRates(const Vector12& velocity, const Matrix3& rotation, const Matrix3& stretch);

}  // namespace dda
