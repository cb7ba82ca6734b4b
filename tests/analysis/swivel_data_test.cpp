// SINUMERIK CYCLE800 swivel data (kinematics type P) from the fitted axis lines.
//
// The small case by hand (`trunnion` below): a C table on an A cradle, in home (machine)
// coordinates, mm and um:
//   C: pivot (10, 20, -300), E_X0C = 12, E_Y0C = -5 um   -> its line's point (10.012, 19.995, -300)
//   A: pivot (0, 25, -280),  E_Y0A = 7,  E_Z0A = -15 um  -> its line's point (0, 25.007, -280.015)
// The 1st rotary axis is the cradle A (it carries C: "Rotary axis 2 is based on rotary axis 1"):
//   I2 = A's point                       = (0, 25.007, -280.015)
//   I3 = C's point - A's point           = (10.012, -5.012, -19.985)
//   I4 = -(I2 + I3) = -(C's point)       = (-10.012, -19.995, 300)
//   V1 = Rz(E_C0A) x, E_C0A = 30 urad    = (cos 30e-6, sin 30e-6, 0) = (1.000000000, 0.000030000,
//   0) V2 = Ry(E_B0C) Rx(E_A0C) z, E_A0C = 20, E_B0C = -8 urad
//      = (cos a sin b, -sin a, cos a cos b) = (-0.000008000, -0.000020000, 1.000000000)
// The chain the record describes, as the Commissioning Manual's vectors compose (the machine
// reference point to the 1st pivot, to the 2nd, back: I4 = -(I2 + I3)): a point x of the table
// is at p = I2 + R1 (I3 + R2 (I4 + x)), R the rotation by the axis's angle about V, "counted
// positively for clockwise rotation facing the direction of the rotation vector" (W1), i.e.
// right-handed. `chain` below writes that out (Rodrigues); it is checked against the W1 worked
// example (a 15 mm I4 along Z turned 45 deg about B moves the zero point by X 10.607 = 15 sin 45,
// Z -4.393 = -15 (1 - cos 45)) and then against the model's actual machine.
#include "cal/analysis/swivel_data.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "rotary_fixtures.hpp"

namespace {

using namespace cal::kinematics;

using cal::test::table_axis;
using cal::test::turn;

// The small trunnion (rotary_fixtures.hpp) with the orientation errors of the head comment: C
// E_A0C = 20, E_B0C = -8 urad; A E_C0A = 30 urad, or B E_A0B = 11 urad.
FiveAxisMachine trunnion(RotaryLetter cradle = RotaryLetter::a) {
  return cal::test::small_trunnion(cradle, {20, -8, 0},
                                   cradle == RotaryLetter::a ? Vec3{0, 0, 30} : Vec3{11, 0, 0});
}

Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }

// p = I2 + R1 (I3 + R2 (I4 + x)): R2 about the line through I2 + I3, then R1 about I2.
Vec3 chain(const SwivelRecord& r, const Vec3& x, double a1_deg, double a2_deg) {
  const Vec3 pivot2 = add(r.i2_mm, r.i3_mm);
  Vec3 p = x;
  if (r.v2 != Vec3{}) p = turn(p, pivot2, r.v2, a2_deg);
  return turn(p, r.i2_mm, r.v1, a1_deg);
}

TEST(SwivelData, TheChainAsReadReproducesTheW1Example) {
  // W1 (08/2005) 4.1: type P, I3 = 0, I4 = (0, 0, 15), axes A and B, B at 45 deg; V2 = +Y
  // assumed (the B axis; the page with the example's V values was not readable). The closure
  // gives I2 = -I4.
  SwivelRecord r;
  r.i4_mm = {0, 0, 15};
  r.i2_mm = {0, 0, -15};
  r.v1 = {1, 0, 0};
  r.v2 = {0, 1, 0};
  const Vec3 zero = chain(r, {0, 0, 0}, 0.0, 45.0);
  EXPECT_NEAR(zero[0], 10.607, 5e-4);  // "X10.607 [= 15 * sin(45)]"
  EXPECT_NEAR(zero[1], 0.0, 1e-12);
  EXPECT_NEAR(zero[2], -4.393, 5e-4);  // "Z-4.393 [= -15 * (1. - cos(45))]"
}

TEST(SwivelData, AcRecordByHand) {
  const SwivelRecord r = sinumerik_swivel_record(trunnion());
  EXPECT_EQ(r.axis1, "A");
  EXPECT_EQ(r.axis2, "C");
  EXPECT_EQ(r.kind, 'P');
  const auto near = [](const Vec3& got, const Vec3& want, double tol, const char* what) {
    for (std::size_t k = 0; k < 3; ++k)
      EXPECT_NEAR(got[k], want[k], tol) << what << "[" << k << "]";
  };
  near(r.i1_mm, {0, 0, 0}, 0.0, "I1");
  near(r.i2_mm, {0, 25.007, -280.015}, 1e-12, "I2");
  near(r.i3_mm, {10.012, -5.012, -19.985}, 1e-12, "I3");
  near(r.i4_mm, {-10.012, -19.995, 300}, 1e-12, "I4");
  near(r.v1, {std::cos(30e-6), std::sin(30e-6), 0}, 1e-15, "V1");
  near(r.v2,
       {std::cos(20e-6) * std::sin(-8e-6), -std::sin(20e-6), std::cos(20e-6) * std::cos(-8e-6)},
       1e-15, "V2");
  const std::string p = sinumerik_swivel_program(r, "SIMULATED");
  for (const char* line : {"$TC_CARR1[1]=0.000000\n",
                           "$TC_CARR4[1]=0.000000\n",
                           "$TC_CARR5[1]=25.007000\n",
                           "$TC_CARR6[1]=-280.015000\n",
                           "$TC_CARR7[1]=1.000000000\n",
                           "$TC_CARR8[1]=0.000030000\n",
                           "$TC_CARR9[1]=0.000000000\n",
                           "$TC_CARR10[1]=-0.000008000\n",
                           "$TC_CARR11[1]=-0.000020000\n",
                           "$TC_CARR12[1]=1.000000000\n",
                           "$TC_CARR15[1]=10.012000\n",
                           "$TC_CARR16[1]=-5.012000\n",
                           "$TC_CARR17[1]=-19.985000\n",
                           "$TC_CARR18[1]=-10.012000\n",
                           "$TC_CARR19[1]=-19.995000\n",
                           "$TC_CARR20[1]=300.000000\n",
                           "$TC_CARR21[1]=A\n",
                           "$TC_CARR22[1]=C\n",
                           "$TC_CARR23[1]=\"P\"\n",
                           "$TC_CARR44[1]=0\n",
                           "$TC_CARR60[1]=0\n",
                           "\nM30\n",
                           "; SIMULATED\n"})
    EXPECT_NE(p.find(line), std::string::npos) << line << "\n" << p;
  EXPECT_EQ(p.find("\n$TC_CARR13["), std::string::npos) << p;  // angles: from the axes
  // Record number and reversed angles: V negated, the I vectors unchanged.
  const SwivelRecord rev =
      sinumerik_swivel_record(trunnion(), {.number = 3, .reverse_angles = true});
  EXPECT_EQ(rev.v2[2], -r.v2[2]);
  EXPECT_EQ(rev.v1[0], -r.v1[0]);
  EXPECT_EQ(rev.i3_mm, r.i3_mm);
  EXPECT_NE(sinumerik_swivel_program(rev, "").find("$TC_CARR12[3]=-1.000000000\n"),
            std::string::npos);
}

TEST(SwivelData, BcRecordByHand) {
  // B: pivot (-4, 0, -280), E_X0B = 9, E_Z0B = -15 um -> (-3.991, 0, -280.015); E_A0B = 11 urad:
  // V1 = Rx(11e-6) y = (0, cos, sin).
  const SwivelRecord r = sinumerik_swivel_record(trunnion(RotaryLetter::b));
  EXPECT_EQ(r.axis1, "B");
  EXPECT_NEAR(r.i2_mm[0], -3.991, 1e-12);
  EXPECT_NEAR(r.i2_mm[2], -280.015, 1e-12);
  EXPECT_NEAR(r.i3_mm[0], 10.012 + 3.991, 1e-12);
  EXPECT_NEAR(r.i3_mm[2], -300 + 280.015, 1e-12);
  EXPECT_NEAR(r.v1[1], std::cos(11e-6), 1e-15);
  EXPECT_NEAR(r.v1[2], std::sin(11e-6), 1e-15);
}

// The record's chain turns a table point exactly as the model's actual machine does (the lines
// with their tilts), for both cradles, and so the control holding the record predicts the
// truth's probed centres.
TEST(SwivelData, TheRecordsChainIsTheModelsActualMachine) {
  for (RotaryLetter cradle : {RotaryLetter::a, RotaryLetter::b}) {
    const FiveAxisMachine m = trunnion(cradle);
    const SwivelRecord r = sinumerik_swivel_record(m);
    const Vec3 w{60, -40, -230};
    for (const auto& [c, t] : {std::pair{0.0, 0.0}, {90.0, 0.0}, {0.0, 45.0}, {215.0, -70.0}}) {
      const Vec3 want = chain(r, w, t, c);
      const std::vector angles{c, t};
      const Vec3 got = probed_centre_mm(m, w, angles);
      for (std::size_t k = 0; k < 3; ++k)
        EXPECT_NEAR(got[k], want[k], 1e-9) << to_string(cradle) << " " << c << ", " << t;
    }
  }
}

// A single table axis: the 1st axis, I3 = 0, V2 = 0.
TEST(SwivelData, OneTableAxis) {
  FiveAxisMachine m;
  m.linear.topology = Topology::xyfz;
  m.rotary.push_back(table_axis(RotaryLetter::c, {100, 50, -200}, {4, 6, 0}, {0, 0, 0}));
  const SwivelRecord r = sinumerik_swivel_record(m);
  EXPECT_EQ(r.axis1, "C");
  EXPECT_EQ(r.axis2, "");
  EXPECT_NEAR(r.i2_mm[0], 100.004, 1e-12);
  EXPECT_EQ(r.i3_mm, (Vec3{0, 0, 0}));
  EXPECT_EQ(r.v2, (Vec3{0, 0, 0}));
  const std::string p = sinumerik_swivel_program(r, "");
  EXPECT_NE(p.find("$TC_CARR22[1]=0\n"), std::string::npos) << p;
  const SwivelRecord back = parse_sinumerik_swivel_program(p, "c.mpf");
  const FiveAxisMachine control = swivel_control_machine(back, m);
  const Vec3 w{130, 20, -180};
  const std::vector angles{123.0};
  const Vec3 a = probed_centre_mm(control, w, angles), b = probed_centre_mm(m, w, angles);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 2e-6);
}

// Written, read back and applied to the simulated control: it predicts the truth's probed
// centres to the file's rounding (6 decimals of mm, 9 of V over ~300 mm), where the nominal
// control is off by tens of um.
TEST(SwivelData, TheProgramReadBackMakesTheControl) {
  for (const bool reverse : {false, true}) {
    const FiveAxisMachine truth = trunnion();
    FiveAxisMachine nominal = truth;
    for (auto& r : nominal.rotary) r.location_position_um = r.location_orientation_urad = {};
    const std::string text = sinumerik_swivel_program(
        sinumerik_swivel_record(truth, {.number = 2, .reverse_angles = reverse}), "test");
    const SwivelRecord back = parse_sinumerik_swivel_program(text, "t.mpf");
    EXPECT_EQ(back.number, 2);
    const FiveAxisMachine control = swivel_control_machine(back, nominal);
    const Vec3 w{60, -40, -230};
    for (const auto& [c, t] : {std::pair{90.0, 0.0}, {0.0, 45.0}, {215.0, -70.0}}) {
      const std::vector angles{c, t};
      const Vec3 want = probed_centre_mm(truth, w, angles);
      const Vec3 got = probed_centre_mm(control, w, angles);
      for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 2e-6) << c << ", " << t;
    }
    const std::vector turned{180.0, 0.0};
    EXPECT_GT(
        std::abs(probed_centre_mm(nominal, w, turned)[0] - probed_centre_mm(truth, w, turned)[0]),
        0.02);
  }
}

TEST(SwivelData, NonFiniteValuesAreRefused) {
  for (std::size_t slot : {0u, 1u}) {
    FiveAxisMachine m = trunnion();
    if (slot == 0)
      m.rotary[0].location_position_um[0] = std::numeric_limits<double>::quiet_NaN();
    else
      m.rotary[1].location_orientation_urad[2] = std::numeric_limits<double>::infinity();
    try {
      sinumerik_swivel_record(m);
      ADD_FAILURE() << "a non-finite fit was written";
    } catch (const cal::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("nothing non-finite"), std::string::npos) << e.what();
    }
  }
  SwivelRecord r = sinumerik_swivel_record(trunnion());
  r.i3_mm[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(sinumerik_swivel_program(r, ""), cal::InputError);
}

TEST(SwivelData, BadProgramsAndMachinesAreRefused) {
  const auto refused = [](const std::string& text, const std::string& what) {
    try {
      parse_sinumerik_swivel_program(text, "t.mpf");
      ADD_FAILURE() << "not refused: " << text;
    } catch (const cal::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused("G01 X10\n", "t.mpf:1: 'G01X10': expected $TC_CARRk[n]=value");
  refused("; c\n$TC_CARR4[1]=1\n$TC_CARR5[2]=1\n", "t.mpf:3: record 2 after record 1");
  refused("$TC_CARR4[1]=1\n$TC_CARR4[1]=2\n", "t.mpf:2: $TC_CARR4 given twice");
  refused("$TC_CARR4[1]=1mm\n", "$TC_CARR4: '1mm' is not a finite number");
  refused("$TC_CARR4[1]=nan\n", "'nan' is not a finite number");
  refused("$TC_CARR23[1]=\"T\"\n", "only kinematics type \"P\"");
  refused("$TC_CARR21[1]=X\n", "'X' is not a rotary axis");
  refused("$TC_CARR44[1]=0.1\n", "a fine offset other than 0");
  refused("$TC_CARR24[1]=5\n", "$TC_CARR24 is not a variable");
  refused("; nothing\nM30\n", "no $TC_CARR assignment");
  // Machines that are not a swivel table.
  FiveAxisMachine m = trunnion();
  m.rotary[1].side = Side::spindle;  // table C, head A
  EXPECT_THROW(sinumerik_swivel_record(m), cal::InputError);
  m.rotary.clear();
  EXPECT_THROW(sinumerik_swivel_record(m), cal::InputError);
  // A record whose V is far off the axis, or whose axes are not the model's.
  SwivelRecord r = sinumerik_swivel_record(trunnion());
  r.v2 = {0.1, 0, 1};
  EXPECT_THROW(swivel_control_machine(r, trunnion()), cal::InputError);
  r = sinumerik_swivel_record(trunnion());
  EXPECT_THROW(swivel_control_machine(r, trunnion(RotaryLetter::b)), cal::InputError);
  r.v1 = {};
  EXPECT_THROW(swivel_control_machine(r, trunnion()), cal::InputError);
  EXPECT_FALSE(heidenhain_not_written_reason().empty());
}

}  // namespace
