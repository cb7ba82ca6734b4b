// Reading cross-axis and volumetric compensation files back as their controls apply them
// (comp_read.hpp, issue 26): what the simulated shop's control loads and what `daq verify`
// predicts with. Each reader knows only the file's text; each test checks it against what the
// writer was given.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cal/analysis/comp_formats.hpp"
#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/volumetric_comp.hpp"

namespace {

using namespace cal::comptable;
namespace kin = cal::kinematics;

const std::map<std::string, int> kNumbers{{"X", 1}, {"Y", 2}, {"Z", 3}};

// Y corrected over X: +4 um at 400 mm (what the control adds), -2.5 um at 100 mm.
CrossAxisTable y_over_x() {
  return {"X", "Y", 0.0, 100.0, {0.0, -0.0025, 0.001, 0.003, 0.004, 0.002}};
}

double y_at(const CrossApplied& a, double x) { return cross_correction_um(a, {x, 0, 0})[1]; }

TEST(CrossRead, SinumerikCecAddsItsValuesToTheOutputAxis) {
  const std::vector<CrossAxisTable> t{y_over_x()};
  const std::vector<std::string> file{write_sinumerik_cec(t, kNumbers)};
  const auto a = read_cross_applied("siemens-cec", file, kNumbers);
  ASSERT_EQ(a.tables.size(), 1u);
  EXPECT_EQ(a.tables[0].input, "X");
  EXPECT_EQ(a.tables[0].output, "Y");
  EXPECT_NEAR(y_at(a, 400), 4.0, 1e-9);
  EXPECT_NEAR(y_at(a, 150), (-2.5 + 1.0) / 2, 1e-9);  // linear between points
  EXPECT_NEAR(y_at(a, 900), 2.0, 1e-9);               // the end value held
  EXPECT_NEAR(cross_correction_um(a, {400, 0, 0})[0], 0.0, 1e-12);
  // The other sign: a control that reads the values the other way.
  EXPECT_NEAR(y_at(read_cross_applied("siemens-cec", file, kNumbers, true), 400), -4.0, 1e-9);
  // Axis numbers as the control knows them: AX2 over AX1 is Y over X only with that map.
  const auto swapped = read_cross_applied("siemens-cec", file, {{"Y", 1}, {"X", 2}, {"Z", 3}});
  EXPECT_EQ(swapped.tables[0].output, "X");
}

TEST(CrossRead, IsgCrossListInTenthsOfAMicrometre) {
  const std::vector<std::string> file{write_isg_cross(y_over_x(), 2, 1)};
  const auto a = read_cross_applied("isg-cross", file, kNumbers);
  ASSERT_EQ(a.tables.size(), 1u);
  EXPECT_EQ(a.tables[0].input, "X");
  EXPECT_NEAR(y_at(a, 400), 4.0, 1e-9);
  EXPECT_NEAR(y_at(a, 100), -2.5, 1e-9);
  // A leadscrew list beside it (daq model compensate -f isg-cross) is a positioning table.
  Table pitch;
  pitch.spec = {.axis = "Y", .start_mm = 0, .interval_mm = 100, .points = 2, .sign = Sign::error};
  pitch.position_mm = {0, 100};
  pitch.forward = {0.0, 0.001};
  const std::vector<std::string> two{file[0], write_isg(pitch)};
  EXPECT_EQ(read_cross_applied("isg-cross", two, kNumbers).tables.size(), 1u);
}

TEST(CrossRead, MatrixkinsCarriesTheSquarenessLinearly) {
  const kin::Squareness s{.c0y_urad = 15.0, .b0z_urad = -10.0, .a0z_urad = 8.0};
  const std::vector<std::string> file{write_linuxcnc_matrixkins(s, {})};
  const auto a = read_cross_applied("linuxcnc-matrixkins", file, kNumbers);
  // Default carriers: C_xy = +E_C0Y (X gets it over Y), C_xz = -E_B0Z, C_yz = +E_A0Z.
  const kin::Vec3 p{100, 200, 300};
  const auto c = cross_correction_um(a, p);
  EXPECT_NEAR(c[0], 15e-6 * 200e3 + 10e-6 * 300e3, 1e-6);
  EXPECT_NEAR(c[1], 8e-6 * 300e3, 1e-6);
  EXPECT_NEAR(c[2], 0.0, 1e-9);
  // The same as the model's own squareness correction with these carriers.
  kin::Machine m;
  m.squareness = s;
  const auto model = cal::volcomp::correction_um(m, p);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(c[k], model[k], 1e-6) << k;
}

TEST(CrossRead, IsgVolumetricIsTheModelsCorrection) {
  for (const auto t : {kin::Topology::fxyz, kin::Topology::yfxz, kin::Topology::xyfz}) {
    kin::Machine m;
    m.topology = t;
    m.squareness = {.c0y_urad = 12.0, .b0z_urad = -6.0, .a0z_urad = 4.0};
    kin::component(m, kin::Component::E_YX) = kin::ErrorFunction::polynomial({0.0, 0.01});
    kin::component(m, kin::Component::E_CX) = kin::ErrorFunction::polynomial({0.0, 0.02});
    kin::component(m, kin::Component::E_ZY) = kin::ErrorFunction::polynomial({0.0, -0.005});
    const std::array<cal::volcomp::AxisGrid, 3> g{{{0, 50, 11}, {0, 50, 9}, {0, 50, 7}}};
    const std::vector<std::string> files{write_isg_volumetric_list(t, kNumbers, "volcomp.csv"),
                                         write_isg_volumetric_csv(m, g)};
    const auto a = read_cross_applied("isg-volumetric", files, kNumbers);
    ASSERT_TRUE(a.volumetric.has_value());
    EXPECT_EQ(a.volumetric->topology, t);
    const kin::Vec3 p{250, 200, 150};
    const auto got = cross_correction_um(a, p), want = cal::volcomp::correction_um(m, p);
    for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 1e-6) << kin::to_string(t);
    const auto inv =
        cross_correction_um(read_cross_applied("isg-volumetric", files, kNumbers, true), p);
    EXPECT_NEAR(inv[1], -want[1], 1e-6);
  }
}

TEST(CrossRead, ScaledFilesKeepTheirNotationAndNoNegativeZero) {
  const std::vector<CrossAxisTable> t{y_over_x()};
  const std::string cec = write_sinumerik_cec(t, kNumbers);
  const std::string negated = scale_cross_values("siemens-cec", cec, -1.0);
  EXPECT_NE(negated.find("$AN_CEC[0,4]=-0.0040\n"), std::string::npos) << negated;
  EXPECT_NE(negated.find("$AN_CEC[0,0]=0.0000\n"), std::string::npos);  // not -0.0000
  EXPECT_NE(negated.find("$AN_CEC_MIN[0]=0.0000\n"), std::string::npos);
  // Undoing a unit error (a control that applies it 25.4 times as large) keeps the precision.
  EXPECT_NE(scale_cross_values("siemens-cec", cec, 1 / 25.4).find("$AN_CEC[0,4]=0.000157\n"),
            std::string::npos);
  const std::vector<std::string> one{negated};
  EXPECT_NEAR(y_at(read_cross_applied("siemens-cec", one, kNumbers), 400), -4.0, 1e-9);
  const std::string isg = scale_cross_values("isg-cross", write_isg_cross(y_over_x(), 2, 1), -1.0);
  EXPECT_NE(isg.find("kw.crosscomp.table[4].correction -40\n"), std::string::npos) << isg;
  EXPECT_NE(isg.find("kw.crosscomp.table[4].setpoint 4000000\n"), std::string::npos);
  const std::string mk = scale_cross_values("linuxcnc-matrixkins",
                                            write_linuxcnc_matrixkins({.c0y_urad = 15}, {}), -1.0);
  EXPECT_NE(mk.find("setp matrixkins.C_xy -0.000015000000\n"), std::string::npos) << mk;
  EXPECT_NE(mk.find("setp matrixkins.C_xx 1.000000000000\n"), std::string::npos);
}

// HEIDENHAIN: a *.COM holds no input axis; the *.CMA names it ("[Axis in column from *.com] =
// F(Axis in column from *.cma, in which *.com is entered)"). The columns hold the error curve
// (comp_meaning.cpp): the control adds minus each value. Before, a HEIDENHAIN compensation was
// not read back at all (is_cross_format said no).
TEST(CrossRead, HeidenhainComIsReadWithItsCmaAssignment) {
  const std::vector<CrossAxisTable> t{y_over_x()};
  const std::vector<CompFile> files{{"TNC:\\table\\x.com", write_heidenhain_com(t)},
                                    {"config.cma", write_heidenhain_cma({{"X", "X.COM"}})}};
  EXPECT_EQ(files[1].text, "ACTIVE X\n* X.COM\n");
  EXPECT_NE(files[0].text.find("400.0000 -0.0040\n"), std::string::npos) << files[0].text;
  const auto a = read_cross_applied("heidenhain", files, kNumbers);
  ASSERT_EQ(a.tables.size(), 1u);
  EXPECT_EQ(a.tables[0].input, "X");
  EXPECT_EQ(a.tables[0].output, "Y");
  EXPECT_NEAR(y_at(a, 400), 4.0, 1e-9);
  EXPECT_NEAR(y_at(a, 100), -2.5, 1e-9);
  EXPECT_NEAR(y_at(read_cross_applied("heidenhain", files, kNumbers, true), 400), -4.0, 1e-9);
  // The same *.COM assigned to the Z column acts over Z.
  const std::vector<CompFile> over_z{files[0], {"c.cma", "NR ACTIVE X Z\n0 - - -\n1 * - X.COM\n"}};
  const auto z = read_cross_applied("heidenhain", over_z, kNumbers);
  EXPECT_EQ(z.tables.at(0).input, "Z");
  EXPECT_NEAR(cross_correction_um(z, {0, 0, 400})[1], 4.0, 1e-9);
  // Without the *.CMA, or a *.COM it does not name, the input axis is unknown: refused.
  const std::vector<CompFile> alone{files[0]};
  EXPECT_THROW(read_cross_applied("heidenhain", alone, kNumbers), cal::InputError);
  const std::vector<CompFile> other{{"Y.COM", files[0].text}, files[1]};
  EXPECT_THROW(read_cross_applied("heidenhain", other, kNumbers), cal::InputError);
  const std::vector<CompFile> two_active{files[0], {"c.cma", "ACTIVE X\n* X.COM\n* X.COM\n"}};
  EXPECT_THROW(read_cross_applied("heidenhain", two_active, kNumbers), cal::InputError);
  // Negated for an inverted sign: the values, not the positions.
  const std::string negated = scale_cross_values("heidenhain", files[0].text, -1.0);
  EXPECT_NE(negated.find("400.0000 0.0040\n"), std::string::npos) << negated;
  EXPECT_NE(negated.find("0.0000 0.0000\n"), std::string::npos) << negated;  // no -0
}

// A position shift undone (the control applied the table at x - 25 mm): each format's table of
// Y over X moved by -25 mm, so that the control that shifts applies the values where they were
// meant. Before, --corrected refused a cross table's position shift.
TEST(CrossRead, PositionShiftMovesTheTablesPositions) {
  const std::vector<CrossAxisTable> t{y_over_x()};
  const auto shifted_right = [](const CrossApplied& a, double x) { return y_at(a, x - 25.0); };
  const auto check = [&](const std::string& format, const std::vector<CompFile>& files) {
    const auto moved = shift_cross_positions(format, files, "X", "Y", 25.0, kNumbers);
    ASSERT_EQ(moved.size(), files.size()) << format;
    const auto a = read_cross_applied(format, moved, kNumbers);
    const auto orig = read_cross_applied(format, files, kNumbers);
    for (const double x : {100.0, 237.5, 400.0})
      EXPECT_NEAR(shifted_right(a, x), y_at(orig, x), 1e-9) << format << " at " << x;
  };
  check("siemens-cec", {{"", write_sinumerik_cec(t, kNumbers)}});
  check("isg-cross", {{"", write_isg_cross(y_over_x(), 2, 1)}});
  check("csv", {{"", write_cross_csv(t)}});
  check("heidenhain", {{"X.COM", write_heidenhain_com(t)},
                       {"config.cma", write_heidenhain_cma({{"X", "X.COM"}})}});
  const std::vector<CompFile> one{{"", write_sinumerik_cec(t, kNumbers)}};
  const auto cec = shift_cross_positions("siemens-cec", one, "X", "Y", 25.0, kNumbers);
  EXPECT_NE(cec[0].text.find("$AN_CEC_MIN[0]=-25.0000\n"), std::string::npos) << cec[0].text;
  // A table of another pair, matrixkins and volumetric: nothing to shift, said.
  EXPECT_THROW(shift_cross_positions("siemens-cec", one, "Z", "Y", 25.0, kNumbers),
               cal::InputError);
  const std::vector<CompFile> mk{{"", write_linuxcnc_matrixkins({.c0y_urad = 15}, {})}};
  EXPECT_THROW(shift_cross_positions("linuxcnc-matrixkins", mk, "Y", "X", 25.0, kNumbers),
               cal::InputError);
}

TEST(CrossRead, RefusesWhatItCannotRead) {
  const std::vector<std::string> none{"M17\n"};
  EXPECT_THROW(read_cross_applied("siemens-cec", none, kNumbers), cal::InputError);
  EXPECT_THROW(read_cross_applied("fanuc", none, kNumbers), cal::InputError);
  const std::vector<std::string> bad{"$AN_CEC[0,0]=abc\n"};
  try {
    read_cross_applied("siemens-cec", bad, kNumbers);
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 1"), std::string::npos) << e.what();
  }
  const std::vector<std::string> unknown_axis{write_isg_cross(y_over_x(), 7, 1)};
  EXPECT_NO_THROW(read_cross_applied("isg-cross", unknown_axis, kNumbers));  // slave by name
  const std::vector<std::string> unknown_master{write_isg_cross(y_over_x(), 2, 9)};
  EXPECT_THROW(read_cross_applied("isg-cross", unknown_master, kNumbers), cal::InputError);
}

}  // namespace
