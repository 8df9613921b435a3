// BaseMotion (solver/BaseMotion.hpp): the closed-form kinematics of a
// prescribed translation history, against the integrals of the piecewise
// linear table worked out by hand, over intervals that start and end
// anywhere (inside pieces, across several, before the start, past the end),
// additivity over any split (what a cut step relies on), the velocity and
// acceleration read back, and the refusals of bad tables.
#include "dda/core/Errors.hpp"
#include "dda/core/StateStream.hpp"
#include "dda/solver/BaseMotion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace {

using dda::BaseMotion;
using dda::Vector3;

// x(t) of a piecewise linear acceleration a(t) through (t_k, a_k), from rest
// at t_0, by the exact integral of each piece (a scalar reference).
double referenceDisplacement(const std::vector<double>& t, const std::vector<double>& a, double at) {
	double v = 0, x = 0;
	for (std::size_t k = 0; k + 1 < t.size(); ++k) {
		if (at <= t[k]) return x;
		const double h = std::min(at, t[k + 1]) - t[k];
		const double j = (a[k + 1] - a[k]) / (t[k + 1] - t[k]);
		x += v * h + a[k] * h * h / 2 + j * h * h * h / 6;
		v += a[k] * h + j * h * h / 2;
		if (at <= t[k + 1]) return x;
	}
	return x + v * (at - t.back());  // no acceleration after the table
}

TEST(BaseMotion, AccelerationTableIntegratesExactlyOverAnyInterval) {
	const std::vector<double> t = {0.1, 0.3, 0.35, 0.8, 1.0};
	const std::vector<double> a = {2.0, -1.0, 4.0, 0.5, -3.0};
	std::vector<Vector3> values;
	for (double x : a) values.emplace_back(x, -2 * x, 0.0);
	const double start = 5.0;
	const BaseMotion motion(BaseMotion::Kind::Acceleration, t, values, start);
	std::mt19937 random(7);
	std::uniform_real_distribution<double> time(-0.2, 1.5);
	for (int trial = 0; trial < 200; ++trial) {
		double t0 = time(random), t1 = time(random);
		if (t1 < t0) std::swap(t0, t1);
		const double expected = referenceDisplacement(t, a, std::max(t1, 0.0)) -
		                        referenceDisplacement(t, a, std::max(t0, 0.0));
		const Vector3 u = motion.displacement(start + t0, start + t1);
		EXPECT_NEAR(u.x(), expected, 1e-14) << t0 << " " << t1;
		EXPECT_NEAR(u.y(), -2 * expected, 2e-14);
		EXPECT_EQ(u.z(), 0.0);
		// Split anywhere (a cut step): the parts add up.
		const double mid = t0 + 0.37 * (t1 - t0);
		const Vector3 parts = motion.displacement(start + t0, start + mid) + motion.displacement(start + mid, start + t1);
		EXPECT_NEAR(parts.x(), u.x(), 1e-14);
	}
	EXPECT_EQ(motion.displacement(start - 1, start + 0.1).norm(), 0.0);  // at rest before the first time
	EXPECT_EQ(motion.velocity(start + 0.05).norm(), 0.0);
	EXPECT_NEAR(motion.acceleration(start + 0.2).x(), 0.5, 1e-13);   // halfway from 2 to -1 (t - start: round-off)
	EXPECT_EQ(motion.acceleration(start + 2.0).norm(), 0.0);          // past the table
	const double h = 1e-6;  // velocity = d displacement / dt
	EXPECT_NEAR(motion.velocity(start + 0.6).x(), motion.displacement(start + 0.6 - h, start + 0.6 + h).x() / (2 * h),
	            1e-9);
}

TEST(BaseMotion, VelocityTableHoldsItsLastValue) {
	const BaseMotion motion(BaseMotion::Kind::Velocity, {0.0, 0.5}, {Vector3(0, 0, 0), Vector3(0, 1, 0)}, 0.0);
	EXPECT_NEAR(motion.displacementAt(0.5).y(), 0.25, 1e-15);       // ramp: v t^2 / (2 t_ramp)
	EXPECT_NEAR(motion.displacementAt(2.0).y(), 0.25 + 1.5, 1e-15);  // then 1 m/s
	EXPECT_NEAR(motion.acceleration(0.25).y(), 2.0, 1e-15);
	EXPECT_EQ(motion.acceleration(1.0).y(), 0.0);
	const BaseMotion constant(BaseMotion::Kind::Velocity, {0.0}, {Vector3(0.5, 0, 0)}, 1.0);
	EXPECT_EQ(constant.displacement(0.0, 1.0).norm(), 0.0);
	EXPECT_NEAR(constant.displacement(0.5, 3.0).x(), 1.0, 1e-15);
}

TEST(BaseMotion, SavedAndReadBack) {
	const BaseMotion motion(BaseMotion::Kind::Acceleration, {0.0, 1.0, 2.0},
	                        {Vector3(1, 0, 0), Vector3(-1, 2, 0), Vector3(0, 0, 3)}, 0.25);
	dda::StateWriter out;
	motion.writeState(out);
	dda::StateReader in(out.bytes());
	const BaseMotion read = BaseMotion::readState(in);
	EXPECT_TRUE(in.atEnd());
	for (double t : {0.3, 1.1, 2.9}) EXPECT_EQ(read.displacement(0.0, t), motion.displacement(0.0, t));
}

TEST(BaseMotion, BadTablesAreRefusedByName) {
	using Kind = BaseMotion::Kind;
	const auto refused = [](Kind kind, std::vector<double> t, std::vector<Vector3> v, double start, const char* what) {
		try {
			BaseMotion(kind, std::move(t), std::move(v), start);
			ADD_FAILURE() << what << " was accepted";
		} catch (const dda::InputError& error) {
			EXPECT_NE(std::string(error.what()).find(what), std::string::npos) << error.what();
		}
	};
	const Vector3 one(1, 0, 0);
	refused(Kind::Velocity, {}, {}, 0, "one length");
	refused(Kind::Acceleration, {0.0}, {one}, 0, "at least two rows");
	refused(Kind::Velocity, {0.0, 0.0}, {one, one}, 0, "increase strictly: row 1");
	refused(Kind::Velocity, {-0.1}, {one}, 0, "first time must be >= 0");
	refused(Kind::Velocity, {0.0, 1.0}, {one, Vector3(NAN, 0, 0)}, 0, "row 1");
	refused(Kind::Velocity, {0.0}, {one}, INFINITY, "start time must be finite");
}

}  // namespace
