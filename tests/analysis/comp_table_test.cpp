// Compensation tables against hand calculations, and each writer against text written out by
// hand.
//
// The measured axis: targets 0, 100, 200 mm; mean deviations up 0, 2, 4 um and down 4, 6, 8
// um (a scale error of 20 um/m and 4 um of lost motion). On a grid 0, 50, ..., 200 mm:
//   bidirectional mean 2, 3, 4, 5, 6 um -> corrections -0.002 .. -0.006 mm;
//   backlash mean(down - up) = 4 um = 0.004 mm;
//   forward (up) 0, 1, 2, 3, 4 um, reverse (down) 4, 5, 6, 7, 8 um.
#include "cal/analysis/comp_table.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::comptable;

std::vector<cal::iso230_2::TargetStats> measured() {
  std::vector<cal::iso230_2::TargetStats> t(3);
  for (int i = 0; i < 3; ++i) {
    t[static_cast<std::size_t>(i)].target_mm = 100.0 * i;
    t[static_cast<std::size_t>(i)].runs_up = t[static_cast<std::size_t>(i)].runs_down = 5;
    t[static_cast<std::size_t>(i)].mean_up_um = 2.0 * i;
    t[static_cast<std::size_t>(i)].mean_down_um = 4.0 + 2.0 * i;
  }
  return t;
}

Spec grid() { return Spec{.axis = "X", .start_mm = 0, .interval_mm = 50, .points = 5}; }

TEST(CompTable, OneTablePlusBacklashByHand) {
  const auto t = positioning(grid(), measured());
  ASSERT_EQ(t.forward.size(), 5u);
  const double want[] = {-0.002, -0.003, -0.004, -0.005, -0.006};
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(t.forward[static_cast<std::size_t>(i)], want[i], 1e-12);
  EXPECT_NEAR(t.backlash, 0.004, 1e-12);
}

TEST(CompTable, SeparateTablesErrorSignMicrometres) {
  auto s = grid();
  s.bidirectional = true;
  s.sign = Sign::error;
  s.units = Units::um;
  s.resolution = 0.1;
  const auto t = positioning(s, measured());
  EXPECT_EQ(t.forward, (std::vector<double>{0, 1, 2, 3, 4}));
  EXPECT_EQ(t.reverse, (std::vector<double>{4, 5, 6, 7, 8}));
}

TEST(CompTable, IncrementalAndRounding) {
  auto s = grid();
  s.incremental = true;
  const auto t = positioning(s, measured());
  EXPECT_NEAR(t.forward[0], -0.002, 1e-12);
  for (int i = 1; i < 5; ++i) EXPECT_NEAR(t.forward[static_cast<std::size_t>(i)], -0.001, 1e-12);
  s.incremental = false;
  s.resolution = 0.005;  // -0.003 rounds to -0.005 (round half away: -0.6 steps -> -1)
  EXPECT_NEAR(positioning(s, measured()).forward[1], -0.005, 1e-12);
  s.units = Units::inch;  // 2 um = 0.0000787 in
  s.resolution = 0.00001;
  EXPECT_NEAR(positioning(s, measured()).forward[0], -0.00008, 1e-12);
}

TEST(CompTable, OutsideTheMeasuredRangeIsRefusedOrHeld) {
  auto s = grid();
  s.start_mm = -50;
  try {
    positioning(s, measured());
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("grid point -50 mm is outside the measured range 0 .. 200 mm"),
        std::string::npos)
        << e.what();
  }
  s.outside = Outside::hold;
  EXPECT_NEAR(positioning(s, measured()).forward[0], -0.002, 1e-12);
  EXPECT_THROW(positioning({.interval_mm = 0}, measured()), cal::InputError);
  EXPECT_THROW(positioning({.points = 1}, measured()), cal::InputError);
}

TEST(CompTable, CrossCompensationWithAndWithoutTheSlope) {
  // Y straightness along X: 0, 1, 4 um at 0, 100, 200 (LSQ slope 20 um/m, intercept -1/3).
  const std::vector<double> x{0, 100, 200}, d{0, 1, 4};
  auto s = Spec{.axis = "X",
                .start_mm = 0,
                .interval_mm = 100,
                .points = 3,
                .units = Units::um,
                .resolution = 0.001};
  EXPECT_EQ(cross(s, x, d, false).forward, (std::vector<double>{0, -1, -4}));
  // Slope removed: residuals 1/3, -2/3, 1/3 plus the intercept -1/3 -> 0, -1, 0; negated.
  const auto flat = cross(s, x, d, true).forward;
  EXPECT_NEAR(flat[0], 0.0, 1e-9);
  EXPECT_NEAR(flat[1], 1.0, 1e-9);
  EXPECT_NEAR(flat[2], 0.0, 1e-9);
}

TEST(CompTableWriters, Csv) {
  const auto t = positioning(grid(), measured());
  EXPECT_EQ(
      write_csv(t),
      "# caldaq compensation table: axis X, correction values in mm, absolute, backlash 0.0040\n"
      "point,position_mm,value\n"
      "0,0.0000,-0.0020\n1,50.0000,-0.0030\n2,100.0000,-0.0040\n3,150.0000,-0.0050\n4,200.0000,-0."
      "0060\n");
}

TEST(CompTableWriters, LinuxCncType1) {
  // nominal, forward trim, reverse trim: the single table +- half the backlash, which gives
  // back the separate tables' corrections -(0..4) um and -(4..8) um.
  EXPECT_EQ(write_linuxcnc(positioning(grid(), measured())),
            "0.0000 0.0000 -0.0040\n50.0000 -0.0010 -0.0050\n100.0000 -0.0020 -0.0060\n"
            "150.0000 -0.0030 -0.0070\n200.0000 -0.0040 -0.0080\n");
  auto s = grid();
  s.incremental = true;
  EXPECT_THROW(write_linuxcnc(positioning(s, measured())), cal::InputError);
}

// SINUMERIK LEC values are the measured errors (comp_meaning.cpp: "A positive compensation value
// causes the corresponding machine axis to move in the negative direction"): the bidirectional
// mean 2 .. 6 um is written +0.0020 .. +0.0060 mm.
TEST(CompTableWriters, SiemensLec) {
  auto s = grid();
  s.sign = Sign::error;
  const std::string out = write_siemens(positioning(s, measured()), 1);
  EXPECT_TRUE(out.starts_with("; LEC for axis X (1), written by caldaq\n; SINUMERIK")) << out;
  EXPECT_NE(out.find("; backlash (MD32450) 0.0040 mm\nCHANDATA(1)\n"
                     "$AA_ENC_COMP[0,0,AX1]=0.0020\n$AA_ENC_COMP[0,1,AX1]=0.0030\n"
                     "$AA_ENC_COMP[0,2,AX1]=0.0040\n$AA_ENC_COMP[0,3,AX1]=0.0050\n"
                     "$AA_ENC_COMP[0,4,AX1]=0.0060\n$AA_ENC_COMP_STEP[0,AX1]=50.0000\n"
                     "$AA_ENC_COMP_MIN[0,AX1]=0.0000\n$AA_ENC_COMP_MAX[0,AX1]=200.0000\n"
                     "$AA_ENC_COMP_IS_MODULO[0,AX1]=0\nM17\n"),
            std::string::npos)
      << out;
  // A table of corrections is refused: the sign is Siemens', not a choice.
  EXPECT_THROW(write_siemens(positioning(grid(), measured()), 1), cal::InputError);
}

// ISG leadscrew lists hold errors (actual - set), per direction, in 0.1 um: forward (up)
// 0, 1, 2, 3, 4 um, reverse (down) 4 .. 8 um from the single table +- half the backlash.
TEST(CompTableWriters, IsgSsfk) {
  auto s = grid();
  s.sign = Sign::error;
  const std::string out = write_isg(positioning(s, measured()));
  EXPECT_NE(out.find("kw.ssfk.interval 500000\n"), std::string::npos) << out;
  EXPECT_NE(
      out.find(
          "kw.ssfk.table[1].setpoint 500000\nkw.ssfk.table[1].pos 10\nkw.ssfk.table[1].neg 50\n"),
      std::string::npos)
      << out;
  EXPECT_NE(out.find("kw.ssfk.table[4].pos 40\nkw.ssfk.table[4].neg 80\n"), std::string::npos)
      << out;
  EXPECT_THROW(write_isg(positioning(grid(), measured())), cal::InputError);
}

// Issue 15: nothing non-finite, absurd or outside the table's syntax reaches a controller.
TEST(CompTable, RefusesWhatNoControllerTableCanHold) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  auto with = [](auto change) {
    auto s = grid();
    change(s);
    return s;
  };
  // --start-mm nan wrote "nan" positions; --resolution 1e-320 wrote $AA_ENC_COMP[...]=inf.
  EXPECT_THROW(positioning(with([&](Spec& s) { s.start_mm = nan; }), measured()), cal::InputError);
  EXPECT_THROW(positioning(with([](Spec& s) { s.resolution = 1e-320; }), measured()),
               cal::InputError);
  EXPECT_THROW(positioning(with([](Spec& s) { s.resolution = 2; }), measured()), cal::InputError);
  EXPECT_THROW(positioning(with([](Spec& s) { s.interval_mm = 1e300; }), measured()),
               cal::InputError);
  EXPECT_THROW(positioning(with([](Spec& s) { s.points = 2'000'000'000; }), measured()),
               cal::InputError);  // --points 2e9: gigabytes, now refused before any allocation
  EXPECT_THROW(positioning(with([](Spec& s) { s.start_mm = 1e9; }), measured()), cal::InputError);
  // Axis names are written into the tables' text: "X\nM30" would add a block.
  for (const char* axis : {"X\nM30", "", "X Y", "1X", "X;", "XYZXYZXYZ", "X\r"})
    EXPECT_THROW(positioning(with([&](Spec& s) { s.axis = axis; }), measured()), cal::InputError)
        << axis;
  EXPECT_NO_THROW(positioning(with([](Spec& s) { s.axis = "AX2"; }), measured()));
  // A table built by hand with a non-finite value is refused by every writer.
  auto t = positioning(grid(), measured());
  t.forward[2] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(write_csv(t), cal::InputError);
  EXPECT_THROW(write_linuxcnc(t), cal::InputError);
  t.spec.sign = Sign::error;
  EXPECT_THROW(write_siemens(t), cal::InputError);
  EXPECT_THROW(write_isg(t), cal::InputError);
  auto e = grid();
  e.sign = Sign::error;
  t = positioning(e, measured());
  t.spec.axis = "X\nM30";
  EXPECT_THROW(write_siemens(t), cal::InputError);
  EXPECT_THROW(write_siemens(positioning(e, measured()), 0), cal::InputError);
}

}  // namespace
