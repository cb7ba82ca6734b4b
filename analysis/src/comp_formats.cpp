// Controller formats for cross-axis and volumetric compensation (see comp_formats.hpp and
// docs/compensation-tables.md for the documents each follows and what they leave open).
#include "cal/analysis/comp_formats.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/error.hpp"

namespace cal::comptable {
namespace {

namespace kin = cal::kinematics;
constexpr std::array kAxisNames{"X", "Y", "Z"};

std::string where(const CrossAxisTable& t) {
  return fmt::format("compensation table {} -> {}", t.input, t.output);
}

bool axis_name_ok(const std::string& s) { return s.size() == 1 && s[0] >= 'A' && s[0] <= 'Z'; }

int axis_number(const std::map<std::string, int>& numbers, const std::string& axis) {
  const auto it = numbers.find(axis);
  if (it == numbers.end() || it->second < 1)
    throw InputError(fmt::format("no axis number (>= 1) given for axis {}", axis));
  return it->second;
}

double to_um(double v, Units u) { return v * um_per_unit(u); }

void check_positioning(const Table& t, std::string_view format) {
  if (t.forward.size() != t.position_mm.size() || t.position_mm.size() < 2)
    throw InputError(
        fmt::format("{}: a table of {} points (at least 2 needed)", format, t.position_mm.size()));
  for (std::size_t i = 0; i < t.forward.size(); ++i) {
    if (!std::isfinite(t.forward[i]) || !std::isfinite(t.position_mm[i]) ||
        (t.spec.bidirectional && !std::isfinite(t.reverse.at(i))))
      throw InputError(fmt::format("{}: point {} is not a finite number", format, i));
    if (std::abs(to_um(t.forward[i], t.spec.units)) > kMaxCorrectionMm * 1e3)
      throw InputError(
          fmt::format("{}: point {} = {} {} is beyond {} mm: not a geometric error "
                      "(check the units)",
                      format, i, t.forward[i], units_name(t.spec.units), kMaxCorrectionMm));
  }
  if (!std::isfinite(t.backlash))
    throw InputError(fmt::format("{}: the backlash is not a finite number", format));
}

}  // namespace

void validate(const CrossAxisTable& t) {
  if (!axis_name_ok(t.input) || !axis_name_ok(t.output))
    throw InputError(fmt::format("{}: axis names must be one letter A-Z", where(t)));
  if (t.correction_mm.size() < 2)
    throw InputError(
        fmt::format("{}: {} point(s), at least 2 needed", where(t), t.correction_mm.size()));
  if (!std::isfinite(t.start_mm) || !std::isfinite(t.interval_mm) || !(t.interval_mm > 0))
    throw InputError(fmt::format("{}: start {} mm, interval {} mm (expected finite, interval > 0)",
                                 where(t), t.start_mm, t.interval_mm));
  for (std::size_t i = 0; i < t.correction_mm.size(); ++i) {
    const double v = t.correction_mm[i];
    if (!std::isfinite(v))
      throw InputError(fmt::format("{}: point {} is not a finite number", where(t), i));
    if (std::abs(v) > kMaxCorrectionMm)
      throw InputError(
          fmt::format("{}: point {} = {} mm is beyond {} mm: not a geometric error "
                      "(check the units)",
                      where(t), i, v, kMaxCorrectionMm));
  }
}

std::vector<CrossAxisTable> from_model(const volcomp::CrossTables& t, double resolution_mm,
                                       bool skip_zero) {
  std::vector<CrossAxisTable> out;
  for (const auto& m : t.tables) {
    CrossAxisTable c{kAxisNames[m.input], kAxisNames[m.output], m.start_mm, m.interval_mm, {}};
    bool all_zero = true;
    for (double um : m.correction_um) {
      c.correction_mm.push_back(um * 1e-3);
      all_zero = all_zero && std::abs(um * 1e-3) < 0.5 * resolution_mm;
    }
    validate(c);
    if (!(skip_zero && all_zero)) out.push_back(std::move(c));
  }
  return out;
}

Table own_axis_table(const volcomp::CrossTables& t, kin::Axis axis, double resolution_mm,
                     Sign sign) {
  const auto& m = t.at(axis, axis);
  Table out;
  out.spec.sign = sign;
  out.spec.axis = kAxisNames[axis];
  out.spec.start_mm = m.start_mm;
  out.spec.interval_mm = m.interval_mm;
  out.spec.points = static_cast<int>(m.correction_um.size());
  out.spec.units = Units::mm;
  out.spec.resolution = resolution_mm;
  for (std::size_t i = 0; i < m.correction_um.size(); ++i) {
    out.position_mm.push_back(m.position_mm(i));
    const double mm = (sign == Sign::correction ? 1e-3 : -1e-3) * m.correction_um[i];
    out.forward.push_back(resolution_mm > 0 ? std::round(mm / resolution_mm) * resolution_mm : mm);
  }
  return out;
}

CrossAxisTable from_straightness(const std::string& input, const std::string& output,
                                 const Spec& grid, std::span<const double> position_mm,
                                 std::span<const double> deviation_um, bool remove_slope) {
  if (input == output)
    throw InputError(
        fmt::format("straightness of {}: the corrected axis (--output-axis) must be "
                    "another axis than the moving one",
                    input));
  Spec s = grid;
  s.axis = input;
  s.sign = Sign::correction;
  s.units = Units::mm;
  s.incremental = false;
  const Table t = cross(s, position_mm, deviation_um, remove_slope);
  CrossAxisTable c{input, output, grid.start_mm, grid.interval_mm, t.forward};
  validate(c);
  return c;
}

std::string write_cross_csv(std::span<const CrossAxisTable> tables) {
  std::string out =
      "# caldaq cross-axis compensation: correction of the output axis (what the control adds), "
      "mm, as a function of the input axis "
      "position\ninput,output,point,position_mm,correction_mm\n";
  for (const auto& t : tables) {
    validate(t);
    for (std::size_t i = 0; i < t.correction_mm.size(); ++i)
      out += fmt::format("{},{},{},{},{}\n", t.input, t.output, i, fixed(t.position_mm(i), 4),
                         fixed(t.correction_mm[i], 6));
  }
  return out;
}

std::string write_sinumerik_cec(std::span<const CrossAxisTable> tables,
                                const std::map<std::string, int>& axis_numbers, int first_table) {
  if (first_table < 0) throw InputError("SINUMERIK CEC: the first table index must be >= 0");
  std::string out = "%_N_NC_CEC_INI\n";
  out +=
      "; cross-axis compensation (SINUMERIK sag/angularity compensation, CEC), written by "
      "caldaq\n";
  out += meaning_header(format_meaning("siemens-cec"), "; ");
  out += "; values: compensation of the output axis in mm, at the input axis positions\n";
  std::string setup;
  int t = first_table;
  for (const auto& table : tables) {
    validate(table);
    setup += fmt::format(
        "; table {}: {} = f({}), {} points: MD18342 $MN_MM_CEC_MAX_POINTS[{}] >= "
        "{}, SD41300 $SN_CEC_TABLE_ENABLE[{}] = 1\n",
        t, table.output, table.input, table.correction_mm.size(), t, table.correction_mm.size(), t);
    ++t;
  }
  out += setup;
  out += "; and MD32710 $MA_CEC_ENABLE = 1 for each output axis\nCHANDATA(1)\n";
  t = first_table;
  for (const auto& table : tables) {
    const int in = axis_number(axis_numbers, table.input);
    const int outn = axis_number(axis_numbers, table.output);
    for (std::size_t i = 0; i < table.correction_mm.size(); ++i)
      out += fmt::format("$AN_CEC[{},{}]={}\n", t, i, fixed(table.correction_mm[i], 4));
    out += fmt::format("$AN_CEC_INPUT_AXIS[{}]=(AX{})\n", t, in);
    out += fmt::format("$AN_CEC_OUTPUT_AXIS[{}]=(AX{})\n", t, outn);
    out += fmt::format("$AN_CEC_STEP[{}]={}\n", t, fixed(table.interval_mm, 4));
    out += fmt::format("$AN_CEC_MIN[{}]={}\n", t, fixed(table.start_mm, 4));
    out += fmt::format("$AN_CEC_MAX[{}]={}\n", t, fixed(table.end_mm(), 4));
    out += fmt::format("$AN_CEC_DIRECTION[{}]=0\n", t);
    out += fmt::format("$AN_CEC_MULT_BY_TABLE[{}]=0\n", t);
    out += fmt::format("$AN_CEC_IS_MODULO[{}]=0\n", t);
    ++t;
  }
  out += "M17\n";
  return out;
}

std::string write_isg_cross(const CrossAxisTable& t, int slave_axis_number,
                            int master_axis_number) {
  validate(t);
  if (slave_axis_number < 1 || master_axis_number < 1 || slave_axis_number == master_axis_number)
    throw InputError(
        fmt::format("ISG cross compensation {} -> {}: axis numbers {} and {} (expected "
                    "two different logical axis numbers >= 1)",
                    t.input, t.output, master_axis_number, slave_axis_number));
  const auto tenth_um = [](double mm) { return std::llround(mm * 1e4); };
  std::string out = fmt::format(
      "# ISG/TwinCAT CNC cross compensation of axis {} as a function of axis {}, written by "
      "caldaq\n{}",
      t.output, t.input, meaning_header(format_meaning("isg-cross"), "# "));
  out += fmt::format("kopf.achs_nr {}\nkopf.log_achs_name {}\n", slave_axis_number, t.output);
  out += fmt::format("kw.crosscomp.last_index {}\n", t.correction_mm.size() - 1);
  out += fmt::format("kw.crosscomp.master_ax_nr {}\n", master_axis_number);
  out += "kw.crosscomp.unit 1\n";
  for (std::size_t i = 0; i < t.correction_mm.size(); ++i) {
    out += fmt::format("kw.crosscomp.table[{}].setpoint {}\n", i, tenth_um(t.position_mm(i)));
    out += fmt::format("kw.crosscomp.table[{}].correction {}\n", i, tenth_um(t.correction_mm[i]));
  }
  return out;
}

std::string write_isg_volumetric_list(kin::Topology t,
                                      const std::map<std::string, int>& axis_numbers,
                                      const std::string& csv_path) {
  if (csv_path.empty() || csv_path.find_first_of("\n\r") != std::string::npos ||
      csv_path.find(' ') != std::string::npos)
    throw InputError(
        fmt::format("ISG volumetric compensation: the parameter file path '{}' must "
                    "be one word without spaces",
                    csv_path));
  std::string chain;
  for (kin::Axis a : kin::chain_order(t)) chain += kAxisNames[a];
  std::string out =
      "# ISG Volumetric Compensation configuration (TF5280), written by caldaq\n"
      "# logical axis numbers of the ISO 230 axes\n";
  for (const char* a : kAxisNames)
    out += fmt::format("{}                {}\n", a, axis_number(axis_numbers, a));
  out += fmt::format("chain            {}\n", chain);
  out += fmt::format("workpiece_axes   {}\n", kin::workpiece_side_axes(t));
  out += fmt::format("file[0]          {}\nfile_format[0]   ISG_CSV\n", csv_path);
  return out;
}

std::string write_isg_volumetric_csv(const kin::Machine& m,
                                     const std::array<volcomp::AxisGrid, 3>& grid) {
  std::string out =
      "// ISO 230 error parameters for ISG Volumetric Compensation (ISG CSV format), written by "
      "caldaq\n// offsets in mm, angles in rad, arguments in mm\nC0Y B0Z A0Z\n";
  const auto rad = [](double urad) { return fixed(urad * 1e-6, 10); };
  out += fmt::format("{} {} {}\n", rad(m.squareness.c0y_urad), rad(m.squareness.b0z_urad),
                     rad(m.squareness.a0z_urad));
  for (std::size_t a = 0; a < 3; ++a) {
    const auto& g = grid[a];
    if (!(g.interval_mm > 0) || g.points < 2 || !std::isfinite(g.start_mm))
      throw InputError(
          fmt::format("ISG volumetric compensation: bad grid for axis {}", kAxisNames[a]));
    const char* n = kAxisNames[a];
    out += fmt::format("#\n{0} EX{0} EY{0} EZ{0} EA{0} EB{0} EC{0}\n", n);
    for (int i = 0; i < g.points; ++i) {
      const double q = g.start_mm + g.interval_mm * i;
      out += fixed(q, 4);
      for (std::size_t d = 0; d < 6; ++d) {
        const auto c = static_cast<kin::Component>(6 * a + d);
        double v = 0.0;
        try {
          v = kin::component(m, c)(q);
        } catch (const InputError& e) {
          throw InputError(fmt::format("{}: {}", kin::to_string(c), e.what()));
        }
        if (!std::isfinite(v))
          throw InputError(fmt::format("{} at {} mm is not finite", kin::to_string(c), q));
        out += " " + (d < 3 ? fixed(v * 1e-3, 7) : rad(v));
      }
      out += "\n";
    }
  }
  return out;
}

std::string write_heidenhain_com(std::span<const CrossAxisTable> same_input) {
  if (same_input.empty()) throw InputError("HEIDENHAIN .COM: no table");
  const auto& first = same_input.front();
  for (const auto& t : same_input) {
    validate(t);
    if (t.input != first.input || t.start_mm != first.start_mm ||
        t.interval_mm != first.interval_mm || t.correction_mm.size() != first.correction_mm.size())
      throw InputError(
          fmt::format("HEIDENHAIN .COM: the tables of one file share the input axis "
                      "and its points ({} -> {} differs)",
                      t.input, t.output));
  }
  std::string out = "AXISPOS";
  for (const auto& t : same_input) out += " " + t.output;
  out += "\n";
  for (std::size_t i = 0; i < first.correction_mm.size(); ++i) {
    out += fixed(first.position_mm(i), 4);
    // The columns hold the error (comp_meaning.cpp, "heidenhain"): minus the correction.
    for (const auto& t : same_input) out += " " + fixed(-t.correction_mm[i], 4);
    out += "\n";
  }
  return out;
}

std::string write_heidenhain_com(const Table& t) {
  check_positioning(t, "HEIDENHAIN .COM");
  if (t.spec.units != Units::mm)
    throw InputError("HEIDENHAIN .COM tables are in mm: use --units mm");
  if (t.spec.incremental)
    throw InputError("HEIDENHAIN .COM tables hold absolute values: no --incremental");
  if (t.spec.sign != format_meaning("heidenhain").written)
    throw InputError(
        "HEIDENHAIN .COM columns hold the measured error curve: the table given "
        "holds corrections");
  if (!axis_name_ok(t.spec.axis))
    throw InputError("HEIDENHAIN .COM: the axis name must be one letter");
  const bool two = t.spec.bidirectional || t.backlash != 0.0;
  std::string out = "AXISPOS " + t.spec.axis + (two ? " BACKLASH\n" : "\n");
  const double half = 0.5 * t.backlash * (t.spec.sign == Sign::correction ? 1.0 : -1.0);
  for (std::size_t i = 0; i < t.position_mm.size(); ++i) {
    const double fwd = t.spec.bidirectional ? t.forward[i] : t.forward[i] + half;
    const double rev = t.spec.bidirectional ? t.reverse[i] : t.forward[i] - half;
    out += fixed(t.position_mm[i], 4) + " " + fixed(fwd, 4);
    if (two) out += " " + fixed(rev, 4);
    out += "\n";
  }
  return out;
}

std::string write_heidenhain_cma(
    const std::vector<std::pair<std::string, std::string>>& input_and_com) {
  if (input_and_com.empty()) throw InputError("HEIDENHAIN .CMA: no table to assign");
  std::string header = "ACTIVE", row = "*";
  for (const auto& [input, com] : input_and_com) {
    if (!axis_name_ok(input)) throw InputError("HEIDENHAIN .CMA: the axis name must be one letter");
    if (com.empty() || com.find_first_of(" \t\r\n") != std::string::npos)
      throw InputError(fmt::format("HEIDENHAIN .CMA: '{}' is not a table name", com));
    header += " " + input;
    row += " " + com;
  }
  return header + "\n" + row + "\n";
}

FanucSteps fanuc_steps(const Table& t, const FanucOptions& o) {
  check_positioning(t, "FANUC pitch error compensation");
  if (t.spec.incremental)
    throw InputError(
        "FANUC pitch error compensation: give absolute values (caldaq makes the "
        "increments): no --incremental");
  if (t.spec.bidirectional)
    throw InputError(
        "FANUC pitch error compensation: one table per axis here (the bidirectional "
        "option, parameter 3605, is not written): use a table plus backlash");
  if (t.spec.sign != format_meaning("fanuc").written)
    throw InputError(
        "FANUC pitch error compensation values are corrections (compensation values): the table "
        "given holds errors");
  if (!(o.detection_unit_um > 0) || !std::isfinite(o.detection_unit_um) || o.magnification < 1 ||
      o.first_point < 0 || o.max_step < 1)
    throw InputError(
        "FANUC pitch error compensation: detection unit > 0, magnification >= 1, "
        "first point >= 0 and maximum step >= 1 are needed");
  const double interval = t.spec.interval_mm, start = t.position_mm.front();
  const double at = (o.reference_mm - start) / interval;
  if (!std::isfinite(at) || std::abs(at - std::round(at)) > 1e-6 || at < -1e-6 ||
      std::round(at) > static_cast<double>(t.position_mm.size() - 1))
    throw InputError(
        fmt::format("FANUC pitch error compensation: the reference position {} mm is "
                    "not a point of the grid {} + k * {} mm",
                    o.reference_mm, start, interval));
  FanucSteps f;
  f.reference_index = static_cast<std::size_t>(std::llround(at));
  f.unit_um = o.detection_unit_um * o.magnification;
  // Absolute compensation relative to the reference position, rounded to the unit; the
  // increments are differences of the rounded values, so their sums never drift.
  std::vector<long long> rounded;
  for (double v : t.forward)
    rounded.push_back(std::llround(
        (to_um(v, t.spec.units) - to_um(t.forward[f.reference_index], t.spec.units)) / f.unit_um));
  for (std::size_t i = 0; i < rounded.size(); ++i) {
    const long long step = i == 0 ? 0 : rounded[i] - rounded[i - 1];
    if (std::llabs(step) > o.max_step)
      throw InputError(
          fmt::format("FANUC pitch error compensation: point {} ({} mm) needs a step "
                      "of {} units, beyond {}: raise the magnification (3623) or "
                      "use a finer interval",
                      o.first_point + static_cast<int>(i), t.position_mm[i], step, o.max_step));
    f.steps.push_back(step);
  }
  return f;
}

Applied fanuc_applied(const Table& t, const FanucOptions& o) {
  const FanucSteps f = fanuc_steps(t, o);
  Applied a{.position_mm = t.position_mm, .forward_um = {}, .reverse_um = {}};
  long long sum = 0, at_reference = 0;
  std::vector<long long> sums;
  for (std::size_t i = 0; i < f.steps.size(); ++i) {
    sum += f.steps[i];
    sums.push_back(sum);
    if (i == f.reference_index) at_reference = sum;
  }
  for (long long s : sums)
    a.forward_um.push_back(static_cast<double>(s - at_reference) * f.unit_um);
  a.reverse_um = a.forward_um;
  return a;
}

std::string write_fanuc_pitch(const Table& t, const FanucOptions& o) {
  const FanucSteps f = fanuc_steps(t, o);
  const auto n = t.position_mm.size();
  const auto ref = f.reference_index;
  const double constant_um = to_um(t.forward[ref], t.spec.units);
  std::string out = fmt::format(
      "FANUC stored pitch error compensation, axis {}, written by caldaq\n{}"
      "Parameters of the axis:\n"
      "  3620 = {}   number of the compensation point of the reference position ({} mm)\n"
      "  3621 = {}   number of the farthest compensation point in the negative direction\n"
      "  3622 = {}   number of the farthest compensation point in the positive direction\n"
      "  3623 = {}   magnification\n"
      "  3624 = {}   interval between compensation points (mm)\n",
      t.spec.axis, meaning_header(format_meaning("fanuc"), ""),
      o.first_point + static_cast<int>(ref), fixed(o.reference_mm, 4), o.first_point,
      o.first_point + static_cast<int>(n) - 1, o.magnification, fixed(t.spec.interval_mm, 4));
  if (std::abs(constant_um) >= 0.5 * f.unit_um)
    out += fmt::format(
        "Not in this table: the correction at the reference position, {} um (the table is zero "
        "there by FANUC's rule); it stays in the residual unless the reference position is "
        "shifted by it\n",
        fixed(constant_um, 3));
  if (t.backlash != 0.0)
    out += fmt::format("Backlash (the control's backlash compensation): {} {}\n",
                       fixed(t.backlash, 4), units_name(t.spec.units));
  out += fmt::format(
      "Compensation values: detection units of {} um; each point's value is what it adds over "
      "the section ending at it, moving in the positive direction\npoint position_mm value\n",
      fixed(o.detection_unit_um, 4));
  for (std::size_t i = 0; i < n; ++i)
    out += fmt::format("{} {} {}\n", o.first_point + static_cast<int>(i),
                       fixed(t.position_mm[i], 4), f.steps[i]);
  return out;
}

std::string write_linuxcnc_matrixkins(const kin::Squareness& s, const volcomp::Carriers& c) {
  volcomp::validate(c);
  for (double v : {s.c0y_urad, s.b0z_urad, s.a0z_urad})
    if (!std::isfinite(v) || std::abs(v) > 1e5)
      throw InputError("LinuxCNC matrixkins: a squareness is not finite or beyond 0.1 rad");
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  // The carrier's travel feeds the other axis (volumetric_comp.cpp): joint_other += k * carrier.
  (c.xy == kin::Y ? m[0][1] : m[1][0]) += s.c0y_urad * 1e-6;
  (c.xz == kin::Z ? m[0][2] : m[2][0]) -= s.b0z_urad * 1e-6;
  (c.yz == kin::Z ? m[1][2] : m[2][1]) += s.a0z_urad * 1e-6;
  std::string out =
      "# Squareness compensation for LinuxCNC matrixkins, written by caldaq\n"
      "# INI: [KINS] KINEMATICS=matrixkins; X_joint = C_xx X + C_xy Y + C_xz Z, ...\n";
  const char* names = "xyz";
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      out += fmt::format("setp matrixkins.C_{}{} {}\n", names[r], names[k], fixed(m[r][k], 12));
  return out;
}

}  // namespace cal::comptable
