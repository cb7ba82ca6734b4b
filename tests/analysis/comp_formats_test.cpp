// The cross-axis, volumetric, FANUC and HEIDENHAIN writers, each on a small table whose text is
// written out by hand here from the document the writer follows (docs/compensation-tables.md).
#include "cal/analysis/comp_formats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::comptable;
using cal::InputError;
namespace kin = cal::kinematics;

// Y corrected as a function of X: 0, +1.2, -2.5 um at X = 0, 100, 200 mm.
CrossAxisTable x_to_y() { return {"X", "Y", 0.0, 100.0, {0.0, 0.0012, -0.0025}}; }

TEST(CrossFormats, Csv) {
  const std::vector<CrossAxisTable> t{x_to_y()};
  EXPECT_EQ(write_cross_csv(t),
            "# caldaq cross-axis compensation: correction of the output axis (what the control "
            "adds), mm, as a function of the input axis position\n"
            "input,output,point,position_mm,correction_mm\n"
            "X,Y,0,0.0000,0.000000\nX,Y,1,100.0000,0.001200\nX,Y,2,200.0000,-0.002500\n");
}

// SINUMERIK CEC as in the function manual's example (K3, interpolatory compensation, "sag
// compensation"): values in mm, input (basic) and output (compensation) axis as (AXn), step,
// min, max, direction 0 (both directions), no table multiplication, no modulo, M17.
TEST(CrossFormats, SinumerikCec) {
  const std::vector<CrossAxisTable> t{x_to_y()};
  const std::string text = write_sinumerik_cec(t, {{"X", 1}, {"Y", 2}, {"Z", 3}}, 0);
  EXPECT_EQ(text.substr(0, text.find('\n')), "%_N_NC_CEC_INI");
  const std::string body = text.substr(text.find("CHANDATA(1)"));
  EXPECT_EQ(body,
            "CHANDATA(1)\n"
            "$AN_CEC[0,0]=0.0000\n$AN_CEC[0,1]=0.0012\n$AN_CEC[0,2]=-0.0025\n"
            "$AN_CEC_INPUT_AXIS[0]=(AX1)\n$AN_CEC_OUTPUT_AXIS[0]=(AX2)\n"
            "$AN_CEC_STEP[0]=100.0000\n$AN_CEC_MIN[0]=0.0000\n$AN_CEC_MAX[0]=200.0000\n"
            "$AN_CEC_DIRECTION[0]=0\n$AN_CEC_MULT_BY_TABLE[0]=0\n$AN_CEC_IS_MODULO[0]=0\nM17\n");
  // The set-up comments name the machine data to size and enable.
  EXPECT_NE(text.find("$MN_MM_CEC_MAX_POINTS[0] >= 3"), std::string::npos) << text;
  // Every line outside comments is a program line in capitals and digits: no exponent (1e-05),
  // no nan or inf.
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind(';', 0) != 0) {
      EXPECT_EQ(line.find_first_of("eni"), std::string::npos) << line;
    }
  EXPECT_THROW(write_sinumerik_cec(t, {{"X", 1}}, 0), InputError);  // no number for Y
}

// ISG cross compensation list of the slave axis Y (logical number 2) on master X (1), in
// 0.1 um: X at 0, 1000000 (100 mm), 2000000; corrections 0, 12, -25.
TEST(CrossFormats, IsgCrossCompensation) {
  const std::string isg = write_isg_cross(x_to_y(), 2, 1);
  EXPECT_TRUE(
      isg.starts_with("# ISG/TwinCAT CNC cross compensation of axis Y as a function of "
                      "axis X, written by caldaq\n# TwinCAT CNC (ISG) cross"))
      << isg;
  EXPECT_NE(isg.find("# VERIFY BEFORE TRUSTING"), std::string::npos) << isg;  // sign not stated
  EXPECT_EQ(isg.substr(isg.find("kopf.achs_nr")),
            "kopf.achs_nr 2\nkopf.log_achs_name Y\nkw.crosscomp.last_index 2\n"
            "kw.crosscomp.master_ax_nr 1\nkw.crosscomp.unit 1\n"
            "kw.crosscomp.table[0].setpoint 0\nkw.crosscomp.table[0].correction 0\n"
            "kw.crosscomp.table[1].setpoint 1000000\nkw.crosscomp.table[1].correction 12\n"
            "kw.crosscomp.table[2].setpoint 2000000\nkw.crosscomp.table[2].correction -25\n");
  EXPECT_THROW(write_isg_cross(x_to_y(), 1, 1), InputError);
}

// HEIDENHAIN: one .COM per input axis, AXISPOS then a column per dependent axis. The columns
// hold the error curve (comp_meaning.cpp): minus the corrections given.
TEST(CrossFormats, HeidenhainComOfOneInputAxis) {
  const std::vector<CrossAxisTable> t{{"Y", "Y", -90.0, 5.0, {0.001, 0.0, -0.0015}},
                                      {"Y", "Z", -90.0, 5.0, {0.0, 0.002, 0.004}}};
  EXPECT_EQ(write_heidenhain_com(t),
            "AXISPOS Y Z\n-90.0000 -0.0010 0.0000\n-85.0000 0.0000 -0.0020\n"
            "-80.0000 0.0015 -0.0040\n");
  const std::vector<CrossAxisTable> mixed{{"Y", "Y", -90.0, 5.0, {0.0, 0.0}},
                                          {"X", "Z", -90.0, 5.0, {0.0, 0.0}}};
  EXPECT_THROW(write_heidenhain_com(mixed), InputError);
}

// The axis of comp_table_test.cpp: corrections -0.002 .. -0.006 mm at 0 .. 200 mm, backlash
// 0.004 mm; as a table plus backlash each direction gets half of it (as for LinuxCNC):
// positive direction -0.000 .. -0.004, negative (BACKLASH column) -0.004 .. -0.008.
Table measured_axis() {
  Table t;
  t.spec = Spec{.axis = "X", .start_mm = 0, .interval_mm = 50, .points = 5};
  t.position_mm = {0, 50, 100, 150, 200};
  t.forward = {-0.002, -0.003, -0.004, -0.005, -0.006};
  t.backlash = 0.004;
  return t;
}

// The same axis as errors (HEIDENHAIN's columns hold the error curve): 2 .. 6 um, each direction
// -+ half the backlash: positive direction 0.000 .. 0.004, negative (BACKLASH) 0.004 .. 0.008.
TEST(PositioningFormats, HeidenhainCom) {
  Table e = measured_axis();
  e.spec.sign = Sign::error;
  for (auto& v : e.forward) v = -v;
  EXPECT_EQ(write_heidenhain_com(e),
            "AXISPOS X BACKLASH\n0.0000 0.0000 0.0040\n50.0000 0.0010 0.0050\n"
            "100.0000 0.0020 0.0060\n150.0000 0.0030 0.0070\n200.0000 0.0040 0.0080\n");
  EXPECT_THROW(write_heidenhain_com(measured_axis()), InputError);  // corrections: refused
  Table um = e;
  um.spec.units = Units::um;
  EXPECT_THROW(write_heidenhain_com(um), InputError);
}

// FANUC: reference position 0 mm = the first point (number 0); absolute compensation relative
// to it 0, -1, -2, -3, -4 um; increments per section 0, -1, -1, -1, -1 in 1 um units.
TEST(PositioningFormats, FanucPitchErrorCompensation) {
  const std::string text = write_fanuc_pitch(measured_axis(), FanucOptions{});
  EXPECT_NE(text.find("3620 = 0 "), std::string::npos) << text;
  EXPECT_NE(text.find("3621 = 0 "), std::string::npos) << text;
  EXPECT_NE(text.find("3622 = 4 "), std::string::npos) << text;
  EXPECT_NE(text.find("3623 = 1 "), std::string::npos) << text;
  EXPECT_NE(text.find("3624 = 50.0000 "), std::string::npos) << text;
  EXPECT_NE(text.find("point position_mm value\n0 0.0000 0\n1 50.0000 -1\n2 100.0000 -1\n"
                      "3 150.0000 -1\n4 200.0000 -1\n"),
            std::string::npos)
      << text;
}

// Reference in the middle, rounding: corrections 2, 1, 0, -1.5, -4 um at -100 .. 100 mm,
// reference 0 mm (point 12 of 10..14). Rounded absolute values 2, 1, 0, -2, -4 (llround rounds
// -1.5 away from zero); increments 0, -1, -1, -2, -2: summed from the reference they give the
// rounded absolutes back (-2 - 2 = -4 at point 14; -(-1 - 1) = 2 at point 10), no drift.
TEST(PositioningFormats, FanucReferenceInTheMiddleAndLimits) {
  Table t;
  t.spec = Spec{.axis = "Y", .start_mm = -100, .interval_mm = 50, .points = 5};
  t.position_mm = {-100, -50, 0, 50, 100};
  t.forward = {0.002, 0.001, 0.0, -0.0015, -0.004};
  FanucOptions o;
  o.first_point = 10;
  const std::string text = write_fanuc_pitch(t, o);
  EXPECT_NE(text.find("3620 = 12 "), std::string::npos) << text;
  EXPECT_NE(text.find("10 -100.0000 0\n11 -50.0000 -1\n12 0.0000 -1\n13 50.0000 -2\n"
                      "14 100.0000 -2\n"),
            std::string::npos)
      << text;
  o.reference_mm = 10.0;  // not a grid point
  EXPECT_THROW(write_fanuc_pitch(t, o), InputError);
  o.reference_mm = 0.0;
  o.max_step = 1;  // -2 per section is too much: the message says what to change
  try {
    write_fanuc_pitch(t, o);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("magnification"), std::string::npos) << e.what();
  }
  t.forward[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_fanuc_pitch(t, FanucOptions{}), InputError);
}

// matrixkins: E_C0Y = 12, E_B0Z = 20, E_A0Z = -5 urad. Default carriers (Y, Z, Z):
// C_xy = +12e-6, C_xz = -20e-6, C_yz = -5e-6; on X, X, Y: C_yx, C_zx, C_zy instead.
TEST(SquarenessFormats, LinuxCncMatrixkins) {
  const kin::Squareness s{12.0, 20.0, -5.0};
  const std::string d = write_linuxcnc_matrixkins(s, {});
  EXPECT_NE(d.find("setp matrixkins.C_xx 1.000000000000\n"), std::string::npos) << d;
  EXPECT_NE(d.find("setp matrixkins.C_xy 0.000012000000\n"), std::string::npos) << d;
  EXPECT_NE(d.find("setp matrixkins.C_xz -0.000020000000\n"), std::string::npos) << d;
  EXPECT_NE(d.find("setp matrixkins.C_yz -0.000005000000\n"), std::string::npos) << d;
  EXPECT_NE(d.find("setp matrixkins.C_yx 0.000000000000\n"), std::string::npos) << d;
  cal::volcomp::Carriers c;
  c.xy = kin::X;
  c.xz = kin::X;
  c.yz = kin::Y;
  const std::string o = write_linuxcnc_matrixkins(s, c);
  EXPECT_NE(o.find("setp matrixkins.C_yx 0.000012000000\n"), std::string::npos) << o;
  EXPECT_NE(o.find("setp matrixkins.C_zx -0.000020000000\n"), std::string::npos) << o;
  EXPECT_NE(o.find("setp matrixkins.C_zy -0.000005000000\n"), std::string::npos) << o;
  EXPECT_NE(o.find("setp matrixkins.C_xy 0.000000000000\n"), std::string::npos) << o;
}

// ISG volumetric compensation: the chain letters without F and the number of table axes;
// the CSV in mm and rad: E_XX = 0.01 um/mm is 0.0005000 mm at 50 mm, E_CX = 20 urad is
// 0.0000200000 rad, E_C0Y = 30 urad 0.0000300000.
TEST(VolumetricFormats, IsgVolumetricCompensation) {
  const std::string list =
      write_isg_volumetric_list(kin::Topology::yfxz, {{"X", 1}, {"Y", 2}, {"Z", 3}}, "vc.csv");
  EXPECT_NE(list.find("chain            YXZ\n"), std::string::npos) << list;
  EXPECT_NE(list.find("workpiece_axes   1\n"), std::string::npos) << list;
  EXPECT_NE(list.find("file_format[0]   ISG_CSV\n"), std::string::npos) << list;
  EXPECT_THROW(
      write_isg_volumetric_list(kin::Topology::fxyz, {{"X", 1}, {"Y", 2}, {"Z", 3}}, "a b.csv"),
      InputError);
  kin::Machine m;
  m.axes[kin::X].ex_um = kin::ErrorFunction::polynomial({0.0, 0.01});
  m.axes[kin::X].ec_urad = kin::ErrorFunction::polynomial({20.0});
  m.squareness.c0y_urad = 30.0;
  const std::array<cal::volcomp::AxisGrid, 3> g{cal::volcomp::AxisGrid{0.0, 50.0, 3},
                                                cal::volcomp::AxisGrid{0.0, 100.0, 2},
                                                cal::volcomp::AxisGrid{-100.0, 100.0, 2}};
  const std::string csv = write_isg_volumetric_csv(m, g);
  EXPECT_NE(csv.find("C0Y B0Z A0Z\n0.0000300000 0.0000000000 0.0000000000\n#\nX EXX EYX EZX EAX "
                     "EBX ECX\n0.0000 0.0000000 0.0000000 0.0000000 0.0000000000 0.0000000000 "
                     "0.0000200000\n50.0000 0.0005000 "),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find("#\nZ EXZ EYZ EZZ EAZ EBZ ECZ\n-100.0000 "), std::string::npos) << csv;
}

TEST(CrossFormats, ValidationRefusesWhatMustNotBeWritten) {
  CrossAxisTable t = x_to_y();
  t.correction_mm[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(validate(t), InputError);
  t = x_to_y();
  t.correction_mm[1] = 6.0;  // 6 mm: wrong units
  EXPECT_THROW(validate(t), InputError);
  t = x_to_y();
  t.output = "Y1";
  EXPECT_THROW(validate(t), InputError);
  t = x_to_y();
  t.interval_mm = -1.0;
  EXPECT_THROW(validate(t), InputError);
  const std::vector<CrossAxisTable> bad{t};
  EXPECT_THROW(write_sinumerik_cec(bad, {{"X", 1}, {"Y", 2}}), InputError);
  EXPECT_THROW(write_cross_csv(bad), InputError);
}

// The straightness fix: a straightness of X measured in Y (0, 1, 0 um at 0, 100, 200 mm) is a
// correction of Y as a function of X, -1 um in the middle: never X's own table.
TEST(CrossFormats, StraightnessBecomesACrossAxisTable) {
  const std::vector<double> x{0, 100, 200}, d{0, 1, 0};
  const Spec g{.axis = "X", .start_mm = 0, .interval_mm = 100, .points = 3, .resolution = 0.0001};
  const CrossAxisTable t = from_straightness("X", "Y", g, x, d, false);
  EXPECT_EQ(t.input, "X");
  EXPECT_EQ(t.output, "Y");
  ASSERT_EQ(t.correction_mm.size(), 3u);
  EXPECT_NEAR(t.correction_mm[1], -0.001, 1e-12);
  EXPECT_THROW(from_straightness("X", "X", g, x, d, false), InputError);
}

}  // namespace
