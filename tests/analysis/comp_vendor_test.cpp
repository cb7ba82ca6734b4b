// Issue 26: each controller format's values mean what its vendor says (comp_meaning.cpp), the
// residual is what the written file leaves, and the compensation loop tells a table the control
// applied otherwise (sign, units, reference) from one it applied as meant.
//
// The case of the SINUMERIK K3 sentence: an axis that goes too far, deviation = measured -
// target = +4 um at 400 mm (0 at 0 mm), both directions alike.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "cal/analysis/comp_formats.hpp"
#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/comp_table.hpp"
#include "cal/analysis/comp_verify.hpp"
#include "cal/analysis/error.hpp"

namespace {

using namespace cal::comptable;
using cal::iso230_2::TargetStats;

std::vector<TargetStats> stats(std::vector<double> x, std::vector<double> up,
                               std::vector<double> down) {
  std::vector<TargetStats> t;
  for (std::size_t i = 0; i < x.size(); ++i)
    t.push_back({.target_mm = x[i],
                 .runs_up = 5,
                 .runs_down = 5,
                 .mean_up_um = up[i],
                 .mean_down_um = down[i]});
  return t;
}

// +4 um at 400 mm, in the sign of `format`, on the grid 0, 400 mm.
Table k3_case(std::string_view format, bool bidirectional = false) {
  const Spec s{.axis = "X",
               .start_mm = 0,
               .interval_mm = 400,
               .points = 2,
               .bidirectional = bidirectional,
               .sign = format_meaning(format).written};
  return positioning(s, stats({0, 400}, {0, 4}, {0, 4}));
}

TEST(VendorSemantics, SinumerikLecWritesTheErrorAsTheK3SentenceRequires) {
  // "A positive compensation value causes the corresponding machine axis to move in the
  // negative direction": the axis 4 um too far needs +0.004 (caldaq wrote -0.0040 before).
  const std::string text = write_siemens(k3_case("siemens"), 1);
  EXPECT_NE(text.find("$AA_ENC_COMP[0,1,AX1]=0.0040\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("=-0.0040"), std::string::npos) << text;
  EXPECT_NE(text.find("; Sign: stated by the vendor"), std::string::npos) << text;
  // Read back as SINUMERIK applies it, the table takes the 4 um off.
  const Applied a = read_applied("siemens", text);
  EXPECT_NEAR(a.forward_um.back(), -4.0, 1e-9);
  EXPECT_NEAR(predict(a, stats({0, 400}, {0, 4}, {0, 4})).after_max_um, 0.0, 1e-9);
}

TEST(VendorSemantics, EveryFormatRemovesTheK3CaseAsItsVendorReadsIt) {
  // LinuxCNC type 1: the trim added to the command, -0.004; HEIDENHAIN's error curve +0.004;
  // the ISG list's error in 0.1 um, +40.
  EXPECT_NE(write_linuxcnc(k3_case("linuxcnc")).find("400.0000 -0.0040 -0.0040\n"),
            std::string::npos);
  EXPECT_NE(write_heidenhain_com(k3_case("heidenhain")).find("400.0000 0.0040\n"),
            std::string::npos);
  EXPECT_NE(write_isg(k3_case("isg")).find("kw.ssfk.table[1].pos 40\nkw.ssfk.table[1].neg 40\n"),
            std::string::npos);
  for (const char* f : {"siemens", "linuxcnc", "isg", "heidenhain"}) {
    const Table t = k3_case(f);
    const std::string text = std::string(f) == "siemens"    ? write_siemens(t)
                             : std::string(f) == "linuxcnc" ? write_linuxcnc(t)
                             : std::string(f) == "isg"      ? write_isg(t)
                                                            : write_heidenhain_com(t);
    // The file read back by its text alone, as the vendor reads it, adds -4 um at 400 mm; with
    // the other sign it would add +4 and double the error.
    EXPECT_NEAR(read_applied(f, text).forward_um.back(), -4.0, 1e-9) << f;
    EXPECT_NEAR(read_applied(f, text, true).forward_um.back(), 4.0, 1e-9) << f;
    // What the writer says the file does is what the file's text does.
    const bool both = std::string(f) != "siemens";
    const Applied a = applied(t, both);
    const Applied r = read_applied(f, text);
    ASSERT_EQ(a.forward_um.size(), r.forward_um.size()) << f;
    for (std::size_t i = 0; i < a.forward_um.size(); ++i) {
      EXPECT_NEAR(a.forward_um[i], r.forward_um[i], 1e-9) << f << " point " << i;
      EXPECT_NEAR(a.reverse_um[i], r.reverse_um[i], 1e-9) << f << " point " << i;
    }
  }
}

TEST(VendorSemantics, IsgWorkedExampleOfTheLeadscrewList) {
  // Beckhoff TF5200, example of a compensation value list, the third gauged position:
  // programmed 19866.7 um, measured 19856.5 um moving positive and 19874.7 um moving negative;
  // "calculated compensation value" -102 and 80 x 0.1 um (actual - set).
  const Spec s{.axis = "Y",
               .start_mm = 0,
               .interval_mm = 19.8667,
               .points = 2,
               .bidirectional = true,
               .sign = format_meaning("isg").written,
               .units = Units::um,
               .resolution = 0.1};
  const auto t =
      positioning(s, stats({0, 19.8667}, {0, 19856.5 - 19866.7}, {0, 19874.7 - 19866.7}));
  const std::string text = write_isg(t);
  EXPECT_NE(text.find("kw.ssfk.table[1].setpoint 198667\nkw.ssfk.table[1].pos -102\n"
                      "kw.ssfk.table[1].neg 80\n"),
            std::string::npos)
      << text;
}

TEST(VendorSemantics, NoNegativeZeroInAnyFile) {
  // Errors of -0.03 um round to zero at 0.1 um: every format prints 0, never -0.
  const auto t = [](std::string_view f) {
    const Spec s{.axis = "X",
                 .start_mm = 0,
                 .interval_mm = 100,
                 .points = 2,
                 .sign = format_meaning(f).written};
    return positioning(s, stats({0, 100}, {-0.03, -0.04}, {-0.03, -0.04}));
  };
  for (const std::string& text :
       {write_siemens(t("siemens")), write_linuxcnc(t("linuxcnc")), write_isg(t("isg")),
        write_heidenhain_com(t("heidenhain")), write_csv(t("csv")),
        write_fanuc_pitch(t("fanuc"), FanucOptions{})}) {
    EXPECT_EQ(text.find("-0.0000"), std::string::npos) << text;
    EXPECT_EQ(text.find(" -0\n"), std::string::npos) << text;
  }
}

TEST(VendorSemantics, FanucResidualIncludesTheConstantAtTheReferencePosition) {
  // Errors 5 um + 10 um/m: the correction is -5 .. -9 um. FANUC's table is zero at the
  // reference position (0 mm): it holds -0, -1, ..., -4 um and leaves the 5 um everywhere. The
  // residual by the model's intent would be 0; as written it is 5 um.
  const Spec s{.axis = "X", .start_mm = 0, .interval_mm = 100, .points = 5};
  const auto m = stats({0, 100, 200, 300, 400}, {5, 6, 7, 8, 9}, {5, 6, 7, 8, 9});
  const auto t = positioning(s, m);
  const FanucOptions o{};
  const Applied a = fanuc_applied(t, o);
  EXPECT_EQ(a.forward_um, (std::vector<double>{0, -1, -2, -3, -4}));
  const auto p = predict(a, m);
  EXPECT_NEAR(p.after_max_um, 5.0, 1e-9);
  EXPECT_NEAR(predict(applied(t, false), m).after_max_um, 0.0, 1e-9);  // the intent
  // The listing says what it cannot hold, and the control reading it back agrees.
  const std::string text = write_fanuc_pitch(t, o);
  EXPECT_NE(text.find("Not in this table: the correction at the reference position, -5.000 um"),
            std::string::npos)
      << text;
  EXPECT_EQ(read_applied("fanuc", text).forward_um, a.forward_um);
}

TEST(VendorSemantics, EveryFormatNamesItsEvidence) {
  EXPECT_EQ(format_meaning("siemens").evidence, Evidence::stated);
  EXPECT_EQ(format_meaning("siemens").written, Sign::error);
  EXPECT_EQ(format_meaning("linuxcnc").written, Sign::correction);
  EXPECT_EQ(format_meaning("siemens-cec").evidence, Evidence::not_found);
  EXPECT_EQ(format_meaning("isg-cross").evidence, Evidence::not_found);
  for (const auto& m : format_meanings()) {
    EXPECT_FALSE(m.source.empty()) << m.format;
    if (m.evidence != Evidence::stated) {
      EXPECT_NE(meaning_header(m, "# ").find("VERIFY BEFORE TRUSTING"), std::string::npos);
    }
  }
  EXPECT_THROW(format_meaning("haas"), cal::InputError);
}

// The loop: the source error e(x) = 2 + 0.02 x + 3 sin(x / 60) um over 0 .. 500 mm (so no finding
// can be mistaken for another), a correction -e, and the as-left run for each way a control can
// apply it; 0.1 um of noise.
struct Loop {
  VerifyInput in;
  explicit Loop(double scale, double offset_um = 0.0, double shift_mm = 0.0) {
    for (int i = 0; i <= 20; ++i) {
      const double x = 25.0 * i;
      in.table_position_mm.push_back(x);
      in.table_applied_um.push_back(-error(x));
    }
    for (int i = 0; i <= 10; ++i) {
      const double x = 50.0 * i, noise = 0.1 * std::sin(7.0 * i);
      in.target_mm.push_back(x);
      in.before_um.push_back(error(x));
      in.applied_um.push_back(-error(x));
      // A shifted table holds its end values beyond its grid, as the controls do.
      const double at = std::clamp(x - shift_mm, 0.0, 500.0);
      in.after_um.push_back(error(x) - scale * error(at) + offset_um + noise);
    }
    in.noise_um = 0.1;
  }
  static double error(double x) { return 2.0 + 0.02 * x + 3.0 * std::sin(x / 60.0); }
};

TEST(CompensationLoop, TellsEachWayAControlCanApplyATable) {
  EXPECT_EQ(verify(Loop(1.0).in).finding, Finding::as_predicted);
  const auto inverted = verify(Loop(-1.0).in);
  EXPECT_EQ(inverted.finding, Finding::inverted_sign);
  EXPECT_NEAR(inverted.measured_max_um, 2 * Loop::error(500), 0.2);  // about twice the error
  EXPECT_EQ(verify(Loop(0.0).in).finding, Finding::not_applied);
  const auto mm_for_um = verify(Loop(1000.0).in);
  EXPECT_EQ(mm_for_um.finding, Finding::unit_scale);
  EXPECT_DOUBLE_EQ(mm_for_um.scale, 1000.0);
  const auto inch = verify(Loop(25.4).in);
  EXPECT_EQ(inch.finding, Finding::unit_scale);
  EXPECT_DOUBLE_EQ(inch.scale, 25.4);
  const auto reference = verify(Loop(1.0, 3.0).in);
  EXPECT_EQ(reference.finding, Finding::constant_shift);
  EXPECT_NEAR(reference.offset_um, 3.0, 0.1);
  const auto shifted = verify(Loop(1.0, 0.0, 12.5).in);
  EXPECT_EQ(shifted.finding, Finding::position_shift);
  EXPECT_NEAR(shifted.shift_mm, 12.5, 1.25);
  // A machine that changed (half the error came back otherwise) is not explained away.
  Loop drift(1.0);
  for (std::size_t i = 0; i < drift.in.after_um.size(); ++i)
    drift.in.after_um[i] += 4.0 * std::cos(static_cast<double>(i));
  EXPECT_EQ(verify(drift.in).finding, Finding::unexplained);
}

TEST(CompensationLoop, RefusesInputsItCannotCompare) {
  Loop l(1.0);
  l.in.after_um.pop_back();
  EXPECT_THROW(verify(l.in), cal::InputError);
  Loop n(1.0);
  n.in.before_um[3] = std::nan("");
  EXPECT_THROW(verify(n.in), cal::InputError);
}

}  // namespace
