// Settings.def: every default passes validateSettings, and every setting is
// refused just outside its range (and at NaN and +-inf) with an InputError
// that names it; then the rules between settings. The checks are made from
// the same rows, so a row added later is tested too.
#include "dda/geometry/ConvexPolyhedron.hpp"
#include "dda/solver/IntegratorSettings.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

using dda::IntegratorSettings;
using dda::Range;
using dda::Vector3;

constexpr double kInf = std::numeric_limits<double>::infinity();

template <class T>
void expectRefused(const char* name, T IntegratorSettings::*member, T value) {
	IntegratorSettings settings;
	settings.*member = value;
	try {
		dda::validateSettings(settings);
		ADD_FAILURE() << name << " = " << value << " was accepted";
	} catch (const dda::InputError& error) {
		const std::string message = error.what();
		EXPECT_NE(message.find(name), std::string::npos) << message;
		EXPECT_NE(message.find("got"), std::string::npos) << message;
	}
}

void expectRangeChecked(const char* name, double IntegratorSettings::*member, const Range& range) {
	for (double value : {std::nan(""), kInf, -kInf}) expectRefused(name, member, value);
	if (range.low > -kInf) expectRefused(name, member, range.lowOpen ? range.low : std::nextafter(range.low, -kInf));
	if (range.high < kInf) expectRefused(name, member, range.highOpen ? range.high : std::nextafter(range.high, kInf));
}

void expectRangeChecked(const char* name, int IntegratorSettings::*member, const Range& range) {
	if (range.low > -kInf) expectRefused(name, member, static_cast<int>(std::ceil(range.low)) - 1);
	if (range.high < kInf) expectRefused(name, member, static_cast<int>(std::floor(range.high)) + 1);
}

void expectRangeChecked(const char* name, Vector3 IntegratorSettings::*member, const Range&) {
	expectRefused(name, member, Vector3(0, std::nan(""), 0));
	expectRefused(name, member, Vector3(-kInf, 0, 0));
}

void expectRangeChecked(const char*, bool IntegratorSettings::*, const Range&) {}

TEST(Settings, DefaultsAreValid) { EXPECT_NO_THROW(dda::validateSettings(IntegratorSettings{})); }

TEST(Settings, EverySettingIsRefusedOutsideItsRange) {
#define DDA_SETTING(type, name, engineName, value, range, unit, doc) \
	expectRangeChecked(#name, &IntegratorSettings::name, range);
#include "dda/solver/Settings.def"
}

TEST(Settings, RangesPrintAsIntervals) {
	EXPECT_EQ(Range::above(0).text(), "(0, inf)");
	EXPECT_EQ(Range::leftOpen(0, 1).text(), "(0, 1]");
	EXPECT_EQ(Range::closed(0.25, 0.5).text(), "[0.25, 0.5]");
	EXPECT_EQ(Range::atLeast(1).text(true), "[1, 2147483647]");
}

TEST(Settings, MessageNamesTheSettingTheRangeAndTheValue) {
	IntegratorSettings settings;
	settings.maxTimeStep = -1e-3;
	try {
		dda::validateSettings(settings);
		FAIL() << "a negative time step was accepted";
	} catch (const dda::InputError& error) {
		EXPECT_STREQ(error.what(), "maxTimeStep (DDAIntegrator's dt) must be finite and in (0, inf), got -0.001 s");
	}
}

TEST(Settings, RulesBetweenSettings) {
	IntegratorSettings settings;
	settings.newmarkBeta = 0.3;  // in its range, but not newmarkGamma / 2
	EXPECT_THROW(dda::validateSettings(settings), dda::InputError);
	settings.newmarkGamma = 0.6;
	EXPECT_NO_THROW(dda::validateSettings(settings));
	settings.minTimeStepShrink = 0.5;
	settings.maxTimeStepShrink = 0.4;
	try {
		dda::validateSettings(settings);
		FAIL() << "minTimeStepShrink > maxTimeStepShrink was accepted";
	} catch (const dda::InputError& error) {
		EXPECT_STREQ(error.what(), "minTimeStepShrink must be <= maxTimeStepShrink, got 0.5 and 0.4");
	}
}

}  // namespace
