// Contact mechanics of one sub-contact: its terms in the equations of the two
// blocks and the open-close rule that updates its state after a solve.
//
// Unknowns: D = (D_i, D_j), 24 of them (D of a fixed block is zero). A point x
// of block b moves by T_b(x) D_b (dda::displacementMatrix about b's centroid).
//
// Normal spring (closed contacts). With the linearised gap
//   d_n(D) = d0 + e_i . D_i + e_j . D_j       (Linearization.hpp)
// the energy kn/2 d_n^2 adds  K += kn e e^T,  F -= kn d0 e  (e = (e_i, e_j)).
// Both normal and shear springs push only while the contact is closed; an
// open contact adds nothing (no tension).
//
// Shear spring (locked contacts). The contact's anchors a_i (a material point of
// block i) and a_j (of block j) coincided when the contact locked; their
// relative displacement is
//   delta(D) = (a_i - a_j) + G D,   G = [T_i(a_i), -T_j(a_j)]   (3 x 24)
// and the spring acts in the tangent plane, P = I - n n^T (n the start-of-step
// normal): energy ks/2 |P delta|^2, so  K += ks G^T P G,  F -= ks G^T P (a_i - a_j).
//
// Friction (sliding contacts). A force of magnitude tan(phi) N opposes l, the
// direction of block i's motion relative to block j (N the normal force of
// the previous iteration); it is a load: F += H^T (-tan(phi) N l), with
// H = [T_i(p_i), -T_j(p_j)] at the contact points.
//
// Open-close rule after a solve (Shi), with u = H D the relative motion:
//   closed and d_n > tolerance       -> open
//   open and d_n < 0                 -> closed: locked (sliding if frictionless)
//   locked and ks |P delta| > tan(phi) N   -> sliding along P delta
//   sliding and (P u) . l <= 0       -> locked (the motion reversed or stopped)
// A closed contact with zero normal force (gap within the opening band) keeps
// its locked or sliding state. A frictionless contact that is closed is always
// sliding, with no friction terms assembled at all.
//
// Bonded joints (cohesion c and tensile strength T of the materials, the
// smaller of the two blocks; A the contact's share of its pair's contact
// area): contacts closed when the scene starts are bonded. A bonded contact
// stays closed in tension while kn d_n <= T A, and stays locked while
// ks |P delta| <= tan(phi) max(N, 0) + c A; exceeding either breaks the bond
// for good (then the rules above apply: no tension, pure Coulomb friction).
#pragma once

#include "IntegratorSettings.hpp"
#include "dda/block/Block.hpp"
#include "dda/contact/Contact.hpp"

#include <Eigen/Core>

namespace dda {

using Vector24 = Eigen::Matrix<double, 24, 1>;
using Matrix24 = Eigen::Matrix<double, 24, 24>;

// Sets the contact's stiffnesses, friction and start-of-step linearisation
// from the two blocks (block i owns the vertex or first edge).
void prepareContact(Contact& contact, const Block& blockI, const Block& blockJ, const IntegratorSettings& settings);

// The contact's 24x24 stiffness and 24 force terms for its trial state;
// false (nothing to add) when the trial state is open.
bool contactTerms(const Contact& contact, const Block& blockI, const Block& blockJ, Matrix24& stiffness,
                  Vector24& force);

// Which tangential term contactTerms adds for the contact's trial state: the
// shear spring of a locked contact, the friction load of a sliding one with
// friction and a compressive normal force, or none (open, or frictionless
// sliding). World counts these (StepStatistics::frictionTerms).
enum class TangentialTerm { None, ShearSpring, FrictionLoad };
TangentialTerm tangentialTerm(const Contact& contact);

// The trial state the solution implies; true when the state changed.
// `openTolerance` [m] is the gap above which a closed contact opens.
bool updateContactState(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di,
                        const Vector12& Dj, double openTolerance);

// Linearised gap for the unknowns [m].
double contactGap(const Contact& contact, const Vector12& Di, const Vector12& Dj);

// Closes the step for the contact: forces from the accepted solution into the
// trial state; call before the blocks move (then moveAnchors).
void finishContact(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Di, const Vector12& Dj);

// A trial state for the start of a step's iteration: the history, or for a
// new contact closed (locked, or sliding if nothing can lock it) when it
// already touches or penetrates, open otherwise. With `formBonds` (the scene's
// first step) a new closed contact between blocks with bond strength is a
// bonded joint.
void startTrial(Contact& contact, bool formBonds);

// A new contact that startTrial locked, between blocks whose start rates Vi,
// Vj [m/s, rad/s, 1/s] move its points apart tangentially, starts sliding
// along that motion instead when its shear spring would exceed the friction
// capacity within the step: ks |v_t| dt > tan(phi) N (always, for a contact
// that only touches: N = 0). A locked spring on a block arriving with
// tangential speed holds the whole step's slip (a 1 m cube sliding at 2 m/s
// lost 40% of its speed in its first step, tipped by the spring, and hopped).
// Bonded contacts stay locked.
void startSlidingIfMoving(Contact& contact, const Block& blockI, const Block& blockJ, const Vector12& Vi,
                          const Vector12& Vj, double dt);

}  // namespace dda
