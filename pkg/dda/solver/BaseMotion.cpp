// Prescribed motion of fixed blocks: the history's closed-form kinematics
// (BaseMotion.hpp).
#include "BaseMotion.hpp"

#include "dda/core/Errors.hpp"
#include "dda/core/StateStream.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace dda {

namespace {
const char* valueName(BaseMotion::Kind kind) { return kind == BaseMotion::Kind::Acceleration ? "acceleration" : "velocity"; }
}  // namespace

BaseMotion::BaseMotion(Kind kind, std::vector<double> times, std::vector<Vector3> values, double start)
    : kind_(kind), times_(std::move(times)), values_(std::move(values)), start_(start) {
	const std::size_t n = times_.size();
	std::ostringstream message;
	if (n == 0 || n != values_.size()) {
		message << "a base motion needs a table of times and " << valueName(kind_) << "s of one length, got "
		        << n << " times and " << values_.size() << " values";
		throw InputError(message.str());
	}
	if (kind_ == Kind::Acceleration && n < 2)
		throw InputError("an acceleration table needs at least two rows (it is linear between them), got one");
	if (!std::isfinite(start_)) {
		message << "a base motion's start time must be finite, got " << start_;
		throw InputError(message.str());
	}
	for (std::size_t k = 0; k < n; ++k) {
		if (!std::isfinite(times_[k]) || !values_[k].allFinite()) {
			message << "row " << k << " of the base motion's table is not finite: time " << times_[k] << " s, "
			        << valueName(kind_) << " (" << values_[k].transpose() << ")";
			throw InputError(message.str());
		}
		if (k == 0 && times_[0] < 0) {
			message << "the base motion's first time must be >= 0 s (its time 0 is the start), got " << times_[0];
			throw InputError(message.str());
		}
		if (k > 0 && !(times_[k] > times_[k - 1])) {
			message << "the base motion's times must increase strictly: row " << k << " has " << times_[k]
			        << " s after " << times_[k - 1] << " s";
			throw InputError(message.str());
		}
	}
	pieces_.resize(n);
	Vector3 v = Vector3::Zero();  // an acceleration table starts at rest
	for (std::size_t p = 0; p < n; ++p) {
		Piece& piece = pieces_[p];
		const bool last = p + 1 == n;
		const double h = last ? 0 : times_[p + 1] - times_[p];
		if (kind_ == Kind::Velocity) {
			piece.velocity = values_[p];
			piece.acceleration = last ? Vector3::Zero() : Vector3((values_[p + 1] - values_[p]) / h);
			piece.jerk = Vector3::Zero();
		} else {
			piece.velocity = v;
			piece.acceleration = last ? Vector3::Zero() : values_[p];
			piece.jerk = last ? Vector3::Zero() : Vector3((values_[p + 1] - values_[p]) / h);
			if (!last) v += piece.acceleration * h + piece.jerk * (h * h / 2);
		}
	}
}

int BaseMotion::pieceAt(double tau) const {
	if (tau < times_.front()) return -1;
	return static_cast<int>(std::upper_bound(times_.begin(), times_.end(), tau) - times_.begin()) - 1;
}

Vector3 BaseMotion::pieceDisplacement(int p, double s0, double s1) const {
	const Piece& piece = pieces_[p];
	const Vector3 v = piece.velocity + s0 * piece.acceleration + (s0 * s0 / 2) * piece.jerk;
	const Vector3 a = piece.acceleration + s0 * piece.jerk;
	const double d = s1 - s0;
	return d * v + (d * d / 2) * a + (d * d * d / 6) * piece.jerk;
}

Vector3 BaseMotion::displacement(double t0, double t1) const {
	Vector3 sum = Vector3::Zero();
	double from = std::max(t0 - start_, times_.front());
	const double to = t1 - start_;
	if (!(to > from)) return sum;
	const int n = static_cast<int>(times_.size());
	for (int p = pieceAt(from); p < n; ++p) {
		const double end = p + 1 < n ? times_[p + 1] : std::numeric_limits<double>::infinity();
		const double until = std::min(to, end);
		sum += pieceDisplacement(p, from - times_[p], until - times_[p]);
		if (until >= to) break;
		from = end;
	}
	return sum;
}

Vector3 BaseMotion::velocity(double t) const {
	const int p = pieceAt(t - start_);
	if (p < 0) return Vector3::Zero();
	const double s = t - start_ - times_[p];
	const Piece& piece = pieces_[p];
	return piece.velocity + s * piece.acceleration + (s * s / 2) * piece.jerk;
}

Vector3 BaseMotion::acceleration(double t) const {
	const int p = pieceAt(t - start_);
	if (p < 0) return Vector3::Zero();
	return pieces_[p].acceleration + (t - start_ - times_[p]) * pieces_[p].jerk;
}

void BaseMotion::writeState(StateWriter& out) const {
	out.pod(static_cast<int>(kind_));
	out.pod(start_);
	out.podVector(times_);
	out.matrixVector(values_);
}

BaseMotion BaseMotion::readState(StateReader& in) {
	const int kind = in.pod<int>();
	if (kind != static_cast<int>(Kind::Acceleration) && kind != static_cast<int>(Kind::Velocity))
		in.fail("base motion kind " + std::to_string(kind));
	const double start = in.pod<double>();
	std::vector<double> times;
	std::vector<Vector3> values;
	in.podVector(times, "base motion times");
	in.matrixVector(values, "base motion values");
	try {
		return BaseMotion(static_cast<Kind>(kind), std::move(times), std::move(values), start);
	} catch (const InputError& error) {
		in.fail(error.what());
	}
}

}  // namespace dda
