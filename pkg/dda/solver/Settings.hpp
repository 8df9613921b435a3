// The valid values of a setting (the range column of Settings.def) and the
// check of a whole IntegratorSettings against Settings.def.
#pragma once

#include <limits>
#include <string>

namespace dda {

struct IntegratorSettings;

// An interval with open or closed ends; an infinite end is always open, so
// every range refuses NaN and +-inf. An integer setting's unbounded end is
// the largest int.
struct Range {
	static constexpr double kInfinity = std::numeric_limits<double>::infinity();
	double low = -kInfinity;
	double high = kInfinity;
	bool lowOpen = true;
	bool highOpen = true;

	static constexpr Range closed(double low, double high) { return {low, high, false, false}; }     // [low, high]
	static constexpr Range open(double low, double high) { return {low, high, true, true}; }         // (low, high)
	static constexpr Range leftOpen(double low, double high) { return {low, high, true, false}; }    // (low, high]
	static constexpr Range above(double low) { return {low, kInfinity, true, true}; }                // (low, inf)
	static constexpr Range atLeast(double low) { return {low, kInfinity, false, true}; }             // [low, inf)
	static constexpr Range any() { return {}; }                                                       // finite

	bool contains(double x) const {
		return (lowOpen ? x > low : x >= low) && (highOpen ? x < high : x <= high) && x > -kInfinity &&
		       x < kInfinity;
	}
	// "(0, 1]", "[1, inf)"; for an integer setting "[0, 2147483647]".
	std::string text(bool integer = false) const;
};

// Refuses, with an InputError naming the setting, its value and its range, a
// value outside its row's range in Settings.def, and then the rules between
// settings: newmarkBeta = newmarkGamma / 2 and minTimeStepShrink <=
// maxTimeStepShrink. World::step calls it before each step.
void validateSettings(const IntegratorSettings& settings);

}  // namespace dda
