// The one fixed-notation writer (fixed_text.hpp), on hand-written cases: no negative zero, the
// rounding at the last place (half away from zero where the value is a decimal tie),
// non-finite values shown as words on a display and refused for a controller or part program.
#include "cal/analysis/fixed_text.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "cal/analysis/error.hpp"
#include "cal/analysis/trt_kins.hpp"

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(FixedText, AValueThatRoundsToZeroHasNoSign) {
  EXPECT_EQ(cal::fixed_text(-0.00004, 4), "0.0000");  // |v| under half the last place
  EXPECT_EQ(cal::fixed_text(-0.0, 3), "0.000");
  EXPECT_EQ(cal::fixed_text(-0.0004, 3), "0.000");
  EXPECT_EQ(cal::fixed_text(-0.4, 0), "0");
  EXPECT_EQ(cal::fixed_text(-0.0006, 3), "-0.001");  // over half: the sign stays
  EXPECT_EQ(cal::fixed_text(-1.5, 3), "-1.500");
}

TEST(FixedText, TheFifthDecimalRoundsTheFourth) {
  EXPECT_EQ(cal::fixed_text(1e-5, 4), "0.0000");  // 0.00001: under half of 0.0001
  EXPECT_EQ(cal::fixed_text(4e-5, 4), "0.0000");  // 0.00004
  EXPECT_EQ(cal::fixed_text(5e-5, 4), "0.0001");  // 0.00005: half, away from zero
  EXPECT_EQ(cal::fixed_text(-5e-5, 4), "-0.0001");
  EXPECT_EQ(cal::fixed_text(6e-5, 4), "0.0001");
  EXPECT_EQ(cal::fixed_text(1.00005, 4), "1.0001");
  EXPECT_EQ(cal::fixed_text(12.34564, 4), "12.3456");
}

TEST(FixedText, HalfRoundsAwayFromZeroOnTheDecimalNotItsBinaryDigits) {
  // printf("%.0f", 2.5) is "2" (the tie to even), and printf("%.3f", 0.0045) is "0.004"
  // (0.0045 is stored a little under 9/2000): a table of decimal data rounds them up.
  EXPECT_EQ(cal::fixed_text(2.5, 0), "3");
  EXPECT_EQ(cal::fixed_text(-2.5, 0), "-3");
  EXPECT_EQ(cal::fixed_text(3.5, 0), "4");
  EXPECT_EQ(cal::fixed_text(2.5, 1), "2.5");
  EXPECT_EQ(cal::fixed_text(0.0625, 3), "0.063");  // an exact binary tie
  EXPECT_EQ(cal::fixed_text(0.0045, 3), "0.005");  // stored under the tie
  EXPECT_EQ(cal::fixed_text(0.0035, 3), "0.004");  // stored over it
  EXPECT_EQ(cal::fixed_text(-0.00125, 4), "-0.0013");
  EXPECT_EQ(cal::fixed_text(2.4999, 0), "2");
}

TEST(FixedText, ManyDecimalsAndLargeValues) {
  EXPECT_EQ(cal::fixed_text(1.5e-7, 6), "0.000000");  // 0.00000015: under half of 1e-6
  EXPECT_EQ(cal::fixed_text(0.123456789, 9), "0.123456789");
  EXPECT_EQ(cal::fixed_text(123456.5, 0), "123457");
  EXPECT_EQ(cal::fixed_text(1e20, 3), "100000000000000000000.000");         // 1e23 is not a double
  EXPECT_EQ(cal::fixed_text(4503599627370495.5, 1), "4503599627370495.5");  // 2^52 - 0.5
  // 1e300 x 1e4 overflows the double: the value is whole anyway and written as it is.
  const std::string huge = cal::fixed_text(-1e300, 4);
  EXPECT_EQ(huge.substr(0, 5), "-1000");
  EXPECT_EQ(huge.size(), 1 + 301 + 5u);  // sign, 301 digits, ".0000"
  EXPECT_THROW(cal::fixed_text(1.0, -1), cal::InputError);
}

TEST(FixedText, ADisplayShowsANonFiniteValueAsAWord) {
  EXPECT_EQ(cal::fixed_text(kNan, 3), "nan");
  EXPECT_EQ(cal::fixed_text(-kNan, 3), "nan");
  EXPECT_EQ(cal::fixed_text(kInf, 3), "inf");
  EXPECT_EQ(cal::fixed_text(-kInf, 3), "-inf");
}

TEST(FixedText, AControllerValueThatIsNotFiniteIsRefusedByItsRole) {
  EXPECT_EQ(cal::control_text(-0.00004, 4, "the X word"), "0.0000");
  EXPECT_EQ(cal::control_text(-12.34566, 4, "the X word"), "-12.3457");
  for (const double bad : {kNan, kInf, -kInf}) {
    try {
      cal::control_text(bad, 4, "the X word");
      ADD_FAILURE() << bad << " was written";
    } catch (const cal::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("the X word is "), std::string::npos) << what;
      EXPECT_NE(what.find("nothing non-finite goes into a controller table"), std::string::npos)
          << what;
    }
  }
}

TEST(FixedText, LinuxCncPinsRefuseANonFiniteValue) {
  cal::kinematics::TrtPins p;
  p.module = "xyzac-trt-kins";
  p.x_rot_point_mm = -0.0000004;  // rounds to zero at 6 places: no "-0.000000"
  EXPECT_NE(cal::kinematics::linuxcnc_trt_hal(p, "").find("setp xyzac-trt-kins.x-rot-point "
                                                          "0.000000\n"),
            std::string::npos);
  p.y_offset_mm = kNan;  // was written as "setp xyzac-trt-kins.y-offset nan"
  try {
    cal::kinematics::linuxcnc_trt_hal(p, "");
    ADD_FAILURE() << "a nan pin was written";
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("xyzac-trt-kins.y-offset is nan"), std::string::npos)
        << e.what();
  }
}

// The value a verdict compares with its limit is the one printed: 0.0045 is stored just under
// 9/2000 yet prints "0.005", so 0.0045 against a limit of 0.004 must fail as the reader sees;
// the central store's tie, 2.0624999999999996 (printed "2.062"), is within 2.062.
TEST(FixedText, FixedValueIsThePrintedNumber) {
  EXPECT_EQ(cal::fixed_value(0.0045, 3), 0.005);
  EXPECT_EQ(cal::fixed_value(2.0624999999999996, 3), 2.062);
  EXPECT_EQ(cal::fixed_value(-2.5, 0), -3.0);                // half away from zero, as "-3"
  EXPECT_FALSE(std::signbit(cal::fixed_value(-0.0004, 3)));  // "0.000", no sign
  EXPECT_EQ(cal::fixed_value(1e20, 3), 1e20);                // past 2^52: as it is
  EXPECT_THROW(cal::fixed_value(1.0, -1), cal::InputError);
}

}  // namespace
