// LinuxCNC's trunnion kinematics pins from the fitted axis lines: a small case by hand, and the
// lines the pins describe (as LinuxCNC's trtfuncs.c places them: C at (x-rot-point,
// y-rot-point), A at (y-rot-point + y-offset, z-rot-point + z-offset), B at (x-rot-point +
// x-offset, z-rot-point + z-offset), tool-offset 0) turn a table point exactly as the model's
// actual machine does.
#include "cal/analysis/trt_kins.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "rotary_fixtures.hpp"

namespace {

using namespace cal::kinematics;

// The small trunnion (rotary_fixtures.hpp) with the C axis's orientation errors `c_orient` and
// E_C0A (E_C0B) = `cradle_c0_urad`.
FiveAxisMachine trunnion(RotaryLetter cradle, const Vec3& c_orient = {},
                         double cradle_c0_urad = 30.0) {
  return cal::test::small_trunnion(cradle, c_orient, {0, 0, cradle_c0_urad});
}

TEST(TrtKins, XyzacPinsByHand) {
  const auto p = linuxcnc_trt_pins(trunnion(RotaryLetter::a, {20, -8, 0}));
  EXPECT_EQ(p.module, "xyzac-trt-kins");
  EXPECT_NEAR(p.x_rot_point_mm, 10.012, 1e-12);         // 10 mm + E_X0C 12 um
  EXPECT_NEAR(p.y_rot_point_mm, 19.995, 1e-12);         // 20 mm + E_Y0C -5 um
  EXPECT_NEAR(p.z_rot_point_mm, -300.0, 1e-12);         // the C pivot's height
  EXPECT_NEAR(p.y_offset_mm, 25.007 - 19.995, 1e-12);   // A at y = 25 mm + E_Y0A 7 um
  EXPECT_NEAR(p.z_offset_mm, -280.015 + 300.0, 1e-12);  // A at z = -280 mm + E_Z0A -15 um
  EXPECT_EQ(p.x_offset_mm, 0.0);
  ASSERT_EQ(p.not_represented.size(), 4u);
  EXPECT_EQ(p.not_represented[0], "E_A0C 20 urad");
  EXPECT_EQ(p.not_represented[1], "E_B0C -8 urad");
  EXPECT_EQ(p.not_represented[3], "E_C0A 30 urad");
  const std::string hal = linuxcnc_trt_hal(p, "SIMULATED");
  EXPECT_NE(hal.find("setp xyzac-trt-kins.x-rot-point 10.012000\n"), std::string::npos) << hal;
  EXPECT_NE(hal.find("setp xyzac-trt-kins.y-offset 5.012000\n"), std::string::npos) << hal;
  EXPECT_NE(hal.find("setp xyzac-trt-kins.z-offset 19.985000\n"), std::string::npos) << hal;
  EXPECT_EQ(hal.find("x-offset"), std::string::npos) << hal;  // not a pin xyzac uses
  EXPECT_NE(hal.find("E_C0A 30 urad"), std::string::npos) << hal;
}

TEST(TrtKins, XyzbcPinsByHand) {
  const auto p = linuxcnc_trt_pins(trunnion(RotaryLetter::b));
  EXPECT_EQ(p.module, "xyzbc-trt-kins");
  EXPECT_NEAR(p.x_offset_mm, -3.991 - 10.012, 1e-12);  // B at x = -4 mm + E_X0B 9 um
  EXPECT_NEAR(p.z_offset_mm, 19.985, 1e-12);
  EXPECT_EQ(p.y_offset_mm, 0.0);
  const std::string hal = linuxcnc_trt_hal(p, "");
  EXPECT_NE(hal.find("setp xyzbc-trt-kins.x-offset -14.003000\n"), std::string::npos) << hal;
}

// v turned by `deg` about the line through q along the unit axis of index `dir`.
Vec3 turn(const Vec3& v, const Vec3& q, std::size_t dir, double deg) {
  Vec3 u{};
  u[dir] = 1.0;
  return cal::test::turn(v, q, u, deg);
}

// The lines the pins describe turn a point W of the C table (first about C, then the cradle
// about its own line) to where the model's actual machine must bring the tool to touch it.
TEST(TrtKins, ThePinsLinesAreTheModelsActualLines) {
  for (RotaryLetter cradle : {RotaryLetter::a, RotaryLetter::b}) {
    // Position errors only: what the module can hold.
    const FiveAxisMachine m = trunnion(cradle, {0, 0, 0}, 0.0);
    const auto p = linuxcnc_trt_pins(m);
    const Vec3 c_point{p.x_rot_point_mm, p.y_rot_point_mm, 0.0};
    const Vec3 tilt_point =
        cradle == RotaryLetter::a
            ? Vec3{0.0, p.y_rot_point_mm + p.y_offset_mm, p.z_rot_point_mm + p.z_offset_mm}
            : Vec3{p.x_rot_point_mm + p.x_offset_mm, 0.0, p.z_rot_point_mm + p.z_offset_mm};
    const Vec3 w{60, -40, -230};
    for (const auto& [c, t] : {std::pair{0.0, 0.0}, {90.0, 0.0}, {0.0, 45.0}, {215.0, -70.0}}) {
      const Vec3 want = turn(turn(w, c_point, 2, c), tilt_point, direction_index(cradle), t);
      const std::vector angles{c, t};
      const Vec3 got = probed_centre_mm(m, w, angles);
      for (std::size_t k = 0; k < 3; ++k)
        EXPECT_NEAR(got[k], want[k], 1e-9) << to_string(cradle) << " " << c << ", " << t;
    }
  }
}

// The HAL lines read back give the pins (to their 6 decimals), and the simulated control made
// from them predicts the probed centres of the truth (position errors only) to that rounding.
TEST(TrtKins, TheHalReadBackMakesTheControl) {
  const FiveAxisMachine truth = trunnion(RotaryLetter::a, {0, 0, 0}, 0.0);
  const auto pins = linuxcnc_trt_pins(truth);
  const auto back = parse_linuxcnc_trt_hal(linuxcnc_trt_hal(pins, "test"), "t.hal");
  EXPECT_EQ(back.module, "xyzac-trt-kins");
  EXPECT_NEAR(back.y_offset_mm, pins.y_offset_mm, 5e-7);
  EXPECT_NEAR(back.z_offset_mm, pins.z_offset_mm, 5e-7);
  FiveAxisMachine nominal = truth;
  for (auto& r : nominal.rotary) r.location_position_um = {};
  const FiveAxisMachine control = trt_control_machine(back, nominal);
  const Vec3 w{60, -40, -230};
  for (const auto& [c, t] : {std::pair{90.0, 0.0}, {0.0, 45.0}, {215.0, -70.0}}) {
    const std::vector angles{c, t};
    const Vec3 want = probed_centre_mm(truth, w, angles);
    const Vec3 got = probed_centre_mm(control, w, angles);
    for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 2e-6) << c << ", " << t;
  }
  // The nominal control (no pins) is off by the location errors: the test can fail.
  const std::vector turned{180.0, 0.0};
  EXPECT_GT(
      std::abs(probed_centre_mm(nominal, w, turned)[0] - probed_centre_mm(truth, w, turned)[0]),
      0.02);
  // Refusals, with the file and the line.
  const auto refused = [](const std::string& hal, const std::string& what) {
    try {
      parse_linuxcnc_trt_hal(hal, "t.hal");
      ADD_FAILURE() << "not refused: " << hal;
    } catch (const cal::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused("loadrt xyzac-trt-kins\n", "t.hal:1: 'loadrt'");
  refused("# c\nsetp xyzac-trt-kins.x-rot-point 1\nsetp xyzbc-trt-kins.x-offset 1\n",
          "t.hal:3: xyzbc-trt-kins after xyzac-trt-kins");
  refused("setp xyzac-trt-kins.tool-offset 1\n", "'tool-offset' is not a pivot pin");
  refused("setp xyzac-trt-kins.y-offset 1\nsetp xyzac-trt-kins.y-offset 2\n",
          "t.hal:2: y-offset given twice");
  refused("setp xyzac-trt-kins.y-offset 1mm\n", "'1mm' is not a value in mm");
  refused("setp xyzac-trt-kins.y-offset nan\n", "'nan' is not a value in mm");
  refused("setp xyzac-trt-kins.y-offset\n", "expected setp MODULE.PIN VALUE");
  refused("# nothing\n", "no setp line");
  // Pins of the other module than the model's trunnion.
  auto b = back;
  b.module = "xyzbc-trt-kins";
  EXPECT_THROW(trt_control_machine(b, nominal), cal::InputError);
}

TEST(TrtKins, OtherMachinesAreRefused) {
  FiveAxisMachine m = trunnion(RotaryLetter::a);
  std::swap(m.rotary[0], m.rotary[1]);  // A carries the workpiece: not a trt
  EXPECT_THROW(linuxcnc_trt_pins(m), cal::InputError);
  m = trunnion(RotaryLetter::a);
  m.rotary[1].side = Side::spindle;  // table C, head A
  EXPECT_THROW(linuxcnc_trt_pins(m), cal::InputError);
  m.rotary.pop_back();
  EXPECT_THROW(linuxcnc_trt_pins(m), cal::InputError);
}

}  // namespace
