// Prescribed motion of fixed blocks (ground shaking, a shaking table, a
// moving boundary): a translation history given as a table of accelerations
// [m/s^2] or velocities [m/s] against time [s], applied to a group of fixed
// blocks. A fixed block keeps no unknowns; its displacement over a step is
// known, so in every contact with a moving block it enters the step's
// equations as a known gap and stretch change (OpenCloseAssembly.cpp,
// doc/DESIGN.md "Prescribed motion of fixed blocks").
//
// Kinematics, exact within a step: the table is piecewise linear, so an
// acceleration table gives a piecewise quadratic velocity and a piecewise
// cubic displacement, a velocity table a piecewise quadratic displacement.
// displacement(t0, t1) integrates them in closed form over [t0, t1], piece
// by piece, whatever the step: no sampling at step ends.
//
// Time: the history's time 0 is the scene's time `start` [s]. Before it the
// blocks are at rest. An acceleration table has zero acceleration outside
// its times (after its last time the blocks keep the velocity it reached); a
// velocity table prescribes the velocity from its first time on (at rest
// before it) and holds its last value after its last time.
#pragma once

#include "dda/core/Types.hpp"

#include <vector>

namespace dda {

class StateWriter;
class StateReader;

class BaseMotion {
public:
	enum class Kind { Acceleration = 0, Velocity = 1 };
	// Throws InputError naming the row and value: an empty table, an
	// acceleration table of one row, times not strictly increasing, a
	// negative first time, a non-finite value or start.
	BaseMotion(Kind kind, std::vector<double> times, std::vector<Vector3> values, double start);

	Kind kind() const { return kind_; }
	double start() const { return start_; }
	const std::vector<double>& times() const { return times_; }
	const std::vector<Vector3>& values() const { return values_; }

	// The translation of the blocks between the scene times t0 <= t1 [m].
	Vector3 displacement(double t0, double t1) const;
	// Since the start, at scene time t [m]; velocity [m/s] and acceleration
	// [m/s^2] at t (the right limit at a jump).
	Vector3 displacementAt(double t) const { return displacement(start_, t); }
	Vector3 velocity(double t) const;
	Vector3 acceleration(double t) const;

	void writeState(StateWriter& out) const;
	static BaseMotion readState(StateReader& in);

private:
	// Piece p of the velocity: on [times_[p], times_[p + 1]) (the last piece
	// from the last time on), v(s) = v0 + a0 s + j s^2 / 2, s the time into
	// the piece. Before the first time: at rest.
	struct Piece {
		Vector3 velocity, acceleration, jerk;
	};
	// The piece holding history time tau, -1 before the first time.
	int pieceAt(double tau) const;
	// The displacement over [s0, s1] within piece p (s: time into it) [m].
	Vector3 pieceDisplacement(int p, double s0, double s1) const;
	Kind kind_;
	std::vector<double> times_;
	std::vector<Vector3> values_;
	double start_;
	std::vector<Piece> pieces_;
};

}  // namespace dda
