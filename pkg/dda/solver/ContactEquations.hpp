// Contact mechanics of one sub-contact: its energy, the Newton model of its
// force that the step's equations take, and its state at a trial solution.
//
// Unknowns: D = (D_i, D_j), 24 of them (D of a fixed block is zero). A point x
// of block b moves by T_b(x) D_b (dda::displacementMatrix about b's centroid).
//
// The step minimises one convex function of D (World::step): the blocks'
// inertia, elasticity and loads plus, for every sub-contact within d0, the
// energy of its springs:
//
// Normal penalty spring, compression only. With the linearised gap
//   d(D) = d0 + e_i . D_i + e_j . D_j          (Linearization.hpp)
// its energy is kn/2 min(0, d)^2: no force while apart, kn |d| when
// penetrating, never tension. A bonded contact (below) holds tension: kn/2 d^2.
//
// Tangential spring with Coulomb's limit (elastoplastic, as Cundall and
// Strack's DEM contact). The anchors a_i (a material point of block i) and
// a_j (of block j) carry the spring's stretch from step to step; their
// separation in the tangent plane P = I - n n^T (n the start-of-step
// normal) is
//   s(D) = P ((a_i - a_j) + G D),   G = [T_i(a_i), -T_j(a_j)]   (3 x 24).
// The spring pushes back with ks s up to the limit L = tan(phi) N (+ c A
// while bonded), N the normal force; beyond it the contact slips and the
// force is L s/|s|. With N held, this is the gradient of the convex
// function psi(s) = ks/2 |s|^2 for ks |s| <= L, L |s| - L^2/(2 ks) beyond.
// After a slipping step the anchors are moved so that the stretch is L/ks
// along the slip: the spring keeps the friction force it carried, so a
// contact that stops slipping holds on with that force instead of starting
// again from an unloaded spring.
//
// State at a trial solution D (evaluateContact): open when d > 0 (bonded:
// when kn d exceeds the tensile strength T A, which breaks the bond);
// otherwise closed, with N = -kn d, and locked (stick: ks |s| <= L) or
// sliding (slip). A closed frictionless contact without a bond is sliding
// with L = 0.
//
// Newton model at the state (contactTerms), the exact second-order
// expansion of the energy about the trial solution:
//   closed: K += kn e e^T, F -= kn d0 e   (e = (e_i, e_j));
//   locked: K += ks G^T P G, F -= ks G^T P (a_i - a_j);
//   sliding with L > 0, at the trial stretch s_k (unit l = s_k/|s_k|):
//     the force L l + C (s - s_k), C = (L/|s_k|)(P - l l^T) (C s_k = 0):
//     K += G^T C G, F -= G^T (L l + C (a_i - a_j)).
// N (hence L) is that of the trial solution before: the step iterates
// until states and forces settle (World::step).
//
// Bonded joints (cohesion c and tensile strength T of the materials, the
// smaller of the two blocks; A the contact's share of its pair's contact
// area): contacts closed when the scene starts are bonded. A bonded contact
// holds tension while kn d <= T A, and stays locked while ks |s| <= tan(phi)
// max(N, 0) + c A; exceeding either breaks the bond for good (then the rules
// above apply: no tension, pure Coulomb friction).
#pragma once

#include "IntegratorSettings.hpp"
#include "dda/block/Block.hpp"
#include "dda/contact/Contact.hpp"

#include <Eigen/Core>

#include <algorithm>

namespace dda {

using Vector24 = Eigen::Matrix<double, 24, 1>;
using Matrix24 = Eigen::Matrix<double, 24, 24>;

// Sets the contact's stiffnesses, friction and start-of-step linearisation
// from the two blocks (block i owns the vertex or first edge).
void prepareContact(Contact& contact, const Block& blockI, const Block& blockJ, const IntegratorSettings& settings);

// The contact's terms in the step's equations, its Newton model at its
// trial state (see above): the stiffness K = sum_r weight[r] v[r] v[r]^T,
// at most three terms of rank one (the normal spring's e; the stick
// spring's G^T t1 and G^T t2, t1 and t2 an orthonormal basis of the tangent
// plane, since P = t1 t1^T + t2 t2^T; the slip's G^T m), and the force F.
// Kept as vectors rather than as the 24x24 K: a sixth of the memory, and
// the assembly adds each term's 12x12 outer products straight into the
// coupled system's blocks instead of copying blocks out of K.
struct ContactTerms {
	int rank = 0;
	double weight[3] = {0, 0, 0};
	Vector24 vector[3];
	Vector24 force;
	// K as a matrix (for tests and checks).
	Matrix24 stiffness() const;
};

// The contact's terms (above); false (nothing to add) when it is open.
bool contactTerms(const Contact& contact, const Block& blockI, const Block& blockJ, ContactTerms& terms);

// The same as the 24x24 stiffness and the 24 force.
bool contactTerms(const Contact& contact, const Block& blockI, const Block& blockJ, Matrix24& stiffness,
                  Vector24& force);

// An orthonormal basis (t1, t2) of the plane normal to the unit `normal`.
void tangentBasis(const Vector3& normal, Vector3& t1, Vector3& t2);

// Which tangential term contactTerms adds for the contact's trial state: the
// stick spring of a locked contact, the slip force of a sliding one with a
// positive limit, or none (open, or frictionless). World counts these
// (StepStatistics::frictionTerms).
enum class TangentialTerm { None, ShearSpring, FrictionLoad };
TangentialTerm tangentialTerm(const Contact& contact);

// Sets the contact's trial state from the trial solution (Di, Dj): open or
// closed and its normal force, its stretch and whether it slips past its
// (fixed) limit; breaks a bond in tension or shear beyond its strength. True
// when open/closed, stick/slip or the bond changed.
bool evaluateContact(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di,
                     const Vector12& Dj);

// Moves the contact's friction limit to tan(phi) max(N, 0) (+ c A while
// bonded) for its normal force now, halfway where the limit swings back (a
// change opposite to its last: a limit that follows N and an N that follows
// the friction can swap between two values); returns |target - limit|
// before the move [N]. Without `apply` only returns it.
double updateFrictionLimit(Contact& contact, bool apply);

// How far the contact's tangential force at its trial state exceeds what
// Coulomb allows at its normal force now [N]: min(ks |s|, L) - min(ks |s|,
// L') when positive, L' = tan(phi) max(N, 0) (+ c A while bonded); 0 for a
// contact whose force its new limit would keep or raise. (No limit yet: 0.)
double limitExcess(const Contact& contact);

// Lowers the contact's friction limit to tan(phi) max(N, 0) (+ c A while
// bonded) for its normal force now, when that is below it; never raises it.
void lowerFrictionLimit(Contact& contact);

// Sets the contact's friction limit to tan(phi) max(N, 0) (+ c A while bonded)
// for its normal force now, up or down.
void setFrictionLimit(Contact& contact);

// The tangential force the contact may carry at its trial state [N]: the
// larger of Coulomb's limit at its normal force now, tan(phi) max(N, 0)
// (+ c A while bonded), and the force its spring carries, min(ks |s|, L).
// (Not the limit L itself: an open contact keeps the limit of a normal force
// that has gone for the rest of its pass.)
double forceScale(const Contact& contact);

// A contact that slips with static friction's limit (Contact::staticFriction
// > 1) goes over to Coulomb's: its friction tangent loses the factor. The
// limit follows at the next pass (measureLimits, startPasses).
void dropStaticFriction(Contact& contact);

// How far the contact's tangential force at its trial state would move [N]
// if its limit went to tan(phi) max(N, 0) (+ c A) for its normal force now.
// The force is min(ks |s|, L) along the stretch, so a contact inside both
// cones (ks |s| <= min(L, L')) keeps its force exactly, and any other moves
// by |min(ks |s|, L') - min(ks |s|, L)| <= |L' - L|. A contact with no limit
// yet, or bonded (the new limit may break its bond), counts |L' - L|.
double limitForceChange(const Contact& contact);

// Whether the contact is closed in its trial state.
inline bool isClosed(const Contact& contact) { return contact.trial.state != ContactState::Open; }

// The tangential force on block i [N] at the trial solution (Di, Dj) by the
// Newton model the last contactTerms used (locked: -ks s; sliding: -(L l +
// C (s - s_k))), and by the exact law at the state now evaluated; World
// compares the two to know when the iteration has settled.
Vector3 tangentialForce(const Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di,
                        const Vector12& Dj);

// Linearised gap for the unknowns [m].
double contactGap(const Contact& contact, const Vector12& Di, const Vector12& Dj);

// The normal spring's energy U(d) [J]: kn/2 min(0, d)^2, bonded kn/2 d^2.
double normalSpringEnergy(bool bonded, double kn, double d);
// The secant slope h(d) = (U(d) - U(d0)) / (d - d0) of U from the start gap
// d0 [N] (U'(d0) at d = d0), and its derivative h'(d) >= 0 [N/m]. A force
// -h(d) e over the step does work -(U(d) - U(d0)) exactly (d is linear in
// D): the discrete gradient that makes a contact conserve energy under the
// trapezoidal rule (Gonzalez; Laursen and Chawla for frictionless contact).
// h is non-decreasing in d (U convex), so its integral, the secant's
// energy, is convex: the step stays one convex minimisation.
struct NormalSecant {
	double value, slope;
};
NormalSecant normalSecant(bool bonded, double kn, double d0, double d);
// Whether the contact's normal force enters the step's equations: closed
// at the trial solution, or (secant weight > 0) compressed at the start.
bool hasNormalTerms(const Contact& contact);
// The physical normal force by which the secant's Newton model at the last
// trial gap misses the secant force at (Di, Dj) [N]; 0 for Shi's scheme.
double normalModelError(const Contact& contact, const Vector12& Di, const Vector12& Dj);

// The derivative of the contact's energy (normal and tangential, at the
// limit of its trial state) along D = D_k + t Delta at t, for the step's line
// search: `line` holds the gap and stretch at t = 0 and their rates.
struct ContactLine {
	double gap = 0, gapRate = 0;   // d(D_k) [m], e . Delta [m]
	double startGap = 0;           // d(0) [m]
	double springWeight = 1, secantWeight = 0, tangentialWeight = 1;  // the scheme's (Contact)
	Vector3 stretch = Vector3::Zero(), stretchRate = Vector3::Zero();  // s(D_k), P G Delta [m]
	double normalStiffness = 0, shearStiffness = 0;  // [N/m]
	double limit = 0;      // L [N]; 0: no tangential force
	bool bonded = false;   // holds tension
	bool tangential = false;
	// Inline: the line search sums it over a group's lines some 40 times a solve.
	double derivative(double t) const {
		const double gapAt = gap + t * gapRate;
		double value = springWeight * normalStiffness * (bonded ? gapAt : std::min(0.0, gapAt)) * gapRate;
		if (secantWeight > 0)
			value += secantWeight * normalSecant(bonded, normalStiffness, startGap, gapAt).value * gapRate;
		if (tangential) {
			const Vector3 s = stretch + t * stretchRate;
			const double norm = s.norm();
			if (shearStiffness * norm <= limit)
				value += tangentialWeight * shearStiffness * s.dot(stretchRate);
			else
				value += tangentialWeight * limit * s.dot(stretchRate) / norm;
		}
		return value;
	}
};

// The step along a line that the line search takes for one group: the
// derivative of the group's energy along D_k + t Delta is
//   phi'(t) = slope + t curvature + sum of the lines' derivative(t),
// summed in that order; phi is convex, so phi' rises with t. Returns 1 when
// phi'(1) is not positive, else the bisection's estimate of the root of phi'
// in (0, 1): the midpoint of the bracket halved while wider than 1e-12, each
// half chosen by the sign of phi' (as computed) at its midpoint.
//
// With `certified`, midpoints whose sign is certain are not evaluated, and
// the result is bitwise the same: phi' as computed differs from the exact
// phi' of the stored coefficients (monotone) by at most a bound E on
// [0, 1] (rounding of each term and of the sum, a generous multiple of the
// standard bounds), so a computed value below -2E at p makes every computed
// value at t <= p negative, and one above 2E every value at t >= p positive.
// A few evaluations placed by regula falsi near the root give such points,
// and the bisection then evaluates only the midpoints between the closest
// two (about 15 evaluations instead of 40 on a stiff pile). `evaluations`,
// when given, counts the evaluations of phi'.
double searchLine(const ContactLine* begin, const ContactLine* end, double slope, double curvature, bool certified,
                  long* evaluations = nullptr);

ContactLine contactLine(const Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di,
                        const Vector12& Dj, const Vector12& deltaI, const Vector12& deltaJ);

// Closes the step for the contact: forces from the accepted solution into the
// trial state, and a slipping contact's anchor i moved so that its stretch is
// L/ks along the slip; call before the blocks move.
void finishContact(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di, const Vector12& Dj);

// A trial state for the start of a step's iteration: the history; the
// anchors of a contact that was open (or is new) are its two points now. With
// `formBonds` (the scene's first step) a new contact that touches or
// penetrates between blocks with bond strength is a bonded joint.
// evaluateContact at D = 0 then sets its state.
void startTrial(Contact& contact, bool formBonds);

// A contact's share of the energy account of an accepted step (World's
// EnergyAccount), in its accepted (trial) state and the step's solution
// [J]. Shi's scheme makes the change of the kinetic energy over a step
// exactly the work of the end-of-step forces over the step's displacement
// (F(D) . D, see World::accountStep). For a force with a convex potential U,
// F(D) . D = -(U(D) - U(0)) - B, B = U(0) - U(D) - grad U(D) . (0 - D) >= 0,
// the Bregman divergence: the energy the scheme's numerical damping takes.
//   - normal spring of an unbonded closed contact: U = kn/2 min(0, d)^2, d
//     the linearised gap (compression only; an unbonded contact has no
//     tension), so start = U(d0), end = U(d1), damping = B;
//   - bonded contact: U = kn/2 d^2 (it holds tension);
//   - tangential spring: U = ks/2 |s|^2 of the stretch s while locked. A
//     sliding contact ends with the stretch r l (r = L/ks), stores ks/2 r^2,
//     and its slip |s1| - r dissipates L (|s1| - r) by friction; the
//     rest of the force's work, ks/2 |r l - s0|^2, is the scheme's damping
//     (the three add up to L l . (s1 - s0), the force's work).
// These are exact only when the forces the solve used are these gradients:
// an unconverged step, or tension in an unbonded contact, breaks the
// identity, and the account shows it.
struct ContactStepEnergy {
	double start = 0;     // spring energy at D = 0 in the accepted state [J]
	double end = 0;       // spring energy at the step's solution [J]
	double damping = 0;   // the springs' Bregman divergence (>= 0) [J]
	double friction = 0;  // dissipated by slip [J]
	double boundary = 0;  // work of a prescribed motion of its fixed side on the moving side [J] (World)
};
ContactStepEnergy contactStepEnergy(const Contact& contact, const Block& blockI, const Block& blockJ,
                                    const Vector12& Di, const Vector12& Dj);

}  // namespace dda
