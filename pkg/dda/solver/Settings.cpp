// validateSettings: the range checks generated from Settings.def, then the
// rules between settings.
#include "Settings.hpp"

#include "IntegratorSettings.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"  // InputError

#include <climits>
#include <cmath>
#include <cstring>
#include <sstream>

namespace dda {

std::string Range::text(bool integer) const {
	std::ostringstream out;
	if (integer) {
		const long long first = low > -kInfinity ? static_cast<long long>(lowOpen ? std::floor(low) + 1 : std::ceil(low)) : INT_MIN;
		const long long last = high < kInfinity ? static_cast<long long>(highOpen ? std::ceil(high) - 1 : std::floor(high)) : INT_MAX;
		out << '[' << first << ", " << last << ']';
	} else {
		out << (lowOpen ? '(' : '[') << low << ", " << high << (highOpen ? ')' : ']');
	}
	return out.str();
}

namespace {

// "maxTimeStep (DDAIntegrator's dt)" where the engine calls it otherwise.
std::string label(const char* name, const char* engineName) {
	return std::strcmp(name, engineName) == 0 ? name : std::string(name) + " (DDAIntegrator's " + engineName + ")";
}

// " s" after a value; nothing for a ratio ("-") or a count ("").
std::string unitSuffix(const char* unit) {
	return *unit == 0 || std::strcmp(unit, "-") == 0 ? "" : std::string(" ") + unit;
}

void check(const std::string& name, double value, const Range& range, const char* unit) {
	if (range.contains(value)) return;
	std::ostringstream message;
	message << name << " must be finite and in " << range.text() << ", got " << value << unitSuffix(unit);
	throw InputError(message.str());
}

void check(const std::string& name, int value, const Range& range, const char*) {
	if (range.contains(value)) return;
	std::ostringstream message;
	message << name << " must be an integer in " << range.text(true) << ", got " << value;
	throw InputError(message.str());
}

void check(const std::string& name, const Vector3& value, const Range& range, const char* unit) {
	if (range.contains(value.x()) && range.contains(value.y()) && range.contains(value.z())) return;
	std::ostringstream message;
	message << name << " must have finite components in " << range.text() << ", got (" << value.x() << ", "
	        << value.y() << ", " << value.z() << ")" << unitSuffix(unit);
	throw InputError(message.str());
}

void check(const std::string&, bool, const Range&, const char*) {}

}  // namespace

void validateSettings(const IntegratorSettings& s) {
#define DDA_SETTING(type, name, engineName, value, range, unit, doc) check(label(#name, #engineName), s.name, range, unit);
#include "dda/solver/Settings.def"
	std::ostringstream message;
	if (!(std::abs(s.newmarkBeta - 0.5 * s.newmarkGamma) <= 1e-12))
		message << "newmarkBeta must be newmarkGamma / 2 (the members whose positions follow the trapezoidal rule, "
		        << "for which no member creates energy; Shi's scheme is 1/2 and 1, average acceleration 1/4 and "
		        << "1/2), got " << s.newmarkBeta << " with newmarkGamma " << s.newmarkGamma;
	else if (!(s.minTimeStepShrink <= s.maxTimeStepShrink))
		message << "minTimeStepShrink must be <= maxTimeStepShrink, got " << s.minTimeStepShrink << " and "
		        << s.maxTimeStepShrink;
	else
		return;
	throw InputError(message.str());
}

}  // namespace dda
