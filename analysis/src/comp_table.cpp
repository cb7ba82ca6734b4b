// Compensation tables (see comp_table.hpp and docs/compensation-tables.md).
#include "cal/analysis/comp_table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/fixed_text.hpp"
#include "cal/analysis/straightness.hpp"

namespace cal::comptable {
namespace {

// What a controller table can hold (see comp_table.hpp): an axis name of letters and digits
// (it is written into the table's text), a grid within +-100 m, at most max_points points, a
// resolution of 0 (none) or 1e-9 .. 1 in the table's units.
void validate(const Spec& s) {
  const bool axis_ok =
      !s.axis.empty() && s.axis.size() <= 8 &&
      std::isalpha(static_cast<unsigned char>(s.axis[0])) &&
      std::all_of(s.axis.begin(), s.axis.end(), [](unsigned char c) { return std::isalnum(c); });
  if (!axis_ok)
    throw InputError(fmt::format(
        "compensation table: axis name '{}': letters and digits only, a letter first, at most 8",
        s.axis));
  if (!(s.interval_mm > 0) || !(s.interval_mm <= max_position_mm))
    throw InputError(fmt::format("compensation table: interval {} mm must be > 0 and at most {}",
                                 s.interval_mm, max_position_mm));
  if (s.points < 2 || s.points > max_points)
    throw InputError(
        fmt::format("compensation table: {} points, expected 2 .. {}", s.points, max_points));
  const double end_mm = s.start_mm + (s.points - 1) * s.interval_mm;
  if (!(std::abs(s.start_mm) <= max_position_mm) || !(std::abs(end_mm) <= max_position_mm))
    throw InputError(fmt::format("compensation table: the grid {} .. {} mm must lie within +-{} mm",
                                 s.start_mm, end_mm, max_position_mm));
  if (!(s.resolution == 0 || (s.resolution >= 1e-9 && s.resolution <= 1)))
    throw InputError(fmt::format(
        "compensation table: resolution {} must be 0 (none) or within 1e-9 .. 1", s.resolution));
}

// The last guard before a writer: every number finite (an inf from an absurd input never
// reaches a controller).
void check_finite(const Table& t) {
  auto bad = [](const std::vector<double>& v) {
    return std::any_of(v.begin(), v.end(), [](double x) { return !std::isfinite(x); });
  };
  if (bad(t.position_mm) || bad(t.forward) || bad(t.reverse) || !std::isfinite(t.backlash))
    throw InputError(
        "compensation table: a value is not a finite number; nothing is written (check the "
        "input's units and the resolution)");
}

double to_units(double um, Units u) {
  switch (u) {
    case Units::mm:
      return um * 1e-3;
    case Units::um:
      return um;
    case Units::inch:
      return um / 25400.0;  // 1 in = 25.4 mm exactly
  }
  return um;
}

double round_to(double v, double res) { return res > 0 ? std::round(v / res) * res : v; }

// Linear interpolation of y(x) at q; x increasing. Outside: refuse or hold the end value.
double interpolate(const std::vector<double>& x, const std::vector<double>& y, double q,
                   Outside o) {
  const double eps = 1e-9;
  if (q < x.front() - eps || q > x.back() + eps) {
    if (o == Outside::refuse)
      throw InputError(
          fmt::format("compensation table: grid point {} mm is outside the measured "
                      "range {} .. {} mm (extend the run, or choose hold)",
                      q, x.front(), x.back()));
    return q < x.front() ? y.front() : y.back();
  }
  const auto hi = std::upper_bound(x.begin(), x.end(), q) - x.begin();
  if (hi == 0) return y.front();
  if (static_cast<std::size_t>(hi) == x.size()) return y.back();
  const auto lo = hi - 1;
  const double f = (q - x[static_cast<std::size_t>(lo)]) /
                   (x[static_cast<std::size_t>(hi)] - x[static_cast<std::size_t>(lo)]);
  return y[static_cast<std::size_t>(lo)] +
         f * (y[static_cast<std::size_t>(hi)] - y[static_cast<std::size_t>(lo)]);
}

// Error (um) -> table value: sign, units, then incremental, then rounding.
std::vector<double> finish(const Spec& s, const std::vector<double>& error_um) {
  std::vector<double> v;
  for (double e : error_um) v.push_back(to_units(s.sign == Sign::correction ? -e : e, s.units));
  if (s.incremental)
    for (std::size_t i = v.size(); i-- > 1;) v[i] -= v[i - 1];
  for (auto& x : v) x = round_to(x, s.resolution);
  return v;
}

std::vector<double> grid(const Spec& s) {
  std::vector<double> g;
  for (int i = 0; i < s.points; ++i) g.push_back(s.start_mm + i * s.interval_mm);
  return g;
}

}  // namespace

std::string fixed(double v, int decimals) {
  return control_text(v, decimals, "a value of a compensation table");
}

double um_per_unit(Units u) { return u == Units::mm ? 1e3 : u == Units::inch ? 25400.0 : 1.0; }

std::string units_name(Units u) { return u == Units::mm ? "mm" : u == Units::um ? "um" : "inch"; }

Units units_from_string(const std::string& s) {
  if (s == "mm") return Units::mm;
  if (s == "um") return Units::um;
  if (s == "inch" || s == "in") return Units::inch;
  throw InputError(fmt::format("units '{}' (expected mm, um or inch)", s));
}

Table positioning(const Spec& spec, std::span<const iso230_2::TargetStats> targets) {
  validate(spec);
  if (targets.size() < 2)
    throw InputError(fmt::format("compensation table: {} targets, at least 2", targets.size()));
  std::vector<double> x, up, down, bi;
  for (const auto& t : targets) {
    x.push_back(t.target_mm);
    up.push_back(t.runs_up > 0 ? t.mean_up_um : t.mean_down_um);
    down.push_back(t.runs_down > 0 ? t.mean_down_um : t.mean_up_um);
    bi.push_back(0.5 * (up.back() + down.back()));
  }
  Table t;
  t.spec = spec;
  t.position_mm = grid(spec);
  std::vector<double> f, r, m;
  for (double q : t.position_mm) {
    f.push_back(interpolate(x, up, q, spec.outside));
    r.push_back(interpolate(x, down, q, spec.outside));
    m.push_back(interpolate(x, bi, q, spec.outside));
  }
  if (spec.bidirectional) {
    t.forward = finish(spec, f);
    t.reverse = finish(spec, r);
  } else {
    t.forward = finish(spec, m);
    double sum = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) sum += down[i] - up[i];
    t.backlash =
        round_to(to_units(sum / static_cast<double>(x.size()), spec.units), spec.resolution);
  }
  return t;
}

Table cross(const Spec& spec, std::span<const double> position_mm,
            std::span<const double> deviation_um, bool remove_slope) {
  validate(spec);
  const auto r =
      straightness::evaluate(position_mm, deviation_um, straightness::Reference::least_squares);
  std::vector<std::pair<double, double>> pts;
  for (std::size_t i = 0; i < position_mm.size(); ++i)
    pts.emplace_back(position_mm[i],
                     remove_slope ? r.residual_um[i] + r.intercept_um : deviation_um[i]);
  std::sort(pts.begin(), pts.end());
  std::vector<double> x, y;
  for (const auto& [a, b] : pts) x.push_back(a), y.push_back(b);
  Table t;
  t.spec = spec;
  t.spec.bidirectional = false;
  t.position_mm = grid(spec);
  std::vector<double> e;
  for (double q : t.position_mm) e.push_back(interpolate(x, y, q, spec.outside));
  t.forward = finish(spec, e);
  return t;
}

namespace {
// The value a direction-specific format needs at point i: the separate tables, or the single
// table with half the backlash on each side (lost motion b: the axis stops b/2 short in each
// direction, so the forward correction is larger by b/2 and the reverse smaller).
double directional(const Table& t, std::size_t i, bool forward) {
  if (t.spec.bidirectional) return forward ? t.forward[i] : t.reverse[i];
  const double half = 0.5 * t.backlash * (t.spec.sign == Sign::correction ? 1.0 : -1.0);
  return round_to(t.forward[i] + (forward ? half : -half), t.spec.resolution);
}

int decimals(const Spec& s) {
  if (s.resolution <= 0) return 6;
  return std::max(0, static_cast<int>(std::ceil(-std::log10(s.resolution) - 1e-9)));
}
}  // namespace

std::string write_csv(const Table& t) {
  validate(t.spec);
  check_finite(t);
  const int d = decimals(t.spec);
  std::string out =
      fmt::format("# caldaq compensation table: axis {}, {} values in {}, {}, {}\n", t.spec.axis,
                  t.spec.sign == Sign::correction ? "correction" : "error",
                  units_name(t.spec.units), t.spec.incremental ? "incremental" : "absolute",
                  t.spec.bidirectional ? "forward/reverse" : "backlash " + fixed(t.backlash, d));
  // An inch table names its columns in inch and gives the positions in inch too (a control in
  // inch mode reads both in its unit); mm and um tables keep positions in mm.
  const bool inch = t.spec.units == Units::inch;
  if (inch)
    out += t.spec.bidirectional ? "point,position_in,forward_in,reverse_in\n"
                                : "point,position_in,value_in\n";
  else
    out +=
        t.spec.bidirectional ? "point,position_mm,forward,reverse\n" : "point,position_mm,value\n";
  for (std::size_t i = 0; i < t.position_mm.size(); ++i) {
    if (inch)
      out += fmt::format("{},{},{}", i, fixed(t.position_mm[i] / 25.4, 5), fixed(t.forward[i], d));
    else
      out += fmt::format("{},{},{}", i, fixed(t.position_mm[i], 4), fixed(t.forward[i], d));
    if (t.spec.bidirectional) out += "," + fixed(t.reverse[i], d);
    out += "\n";
  }
  return out;
}

namespace {
// A writer's table must carry its format's sign (comp_meaning.hpp): the sign is the vendor's,
// never a choice.
void check_sign(const Table& t, std::string_view format) {
  const auto& m = format_meaning(format);
  if (t.spec.sign != m.written)
    throw InputError(
        fmt::format("{} values are {} (the vendor's meaning, comp_meaning): the "
                    "table given holds the other sign",
                    m.name, m.written == Sign::error ? "errors" : "corrections"));
}
}  // namespace

// LinuxCNC, [JOINT_n] COMP_FILE with COMP_FILE_TYPE = 1: one line per point, "nominal
// forward-trim reverse-trim" in machine units; a trim is added to the commanded position, so
// the values are corrections (docs/compensation-tables.md). Absolute values only.
std::string write_linuxcnc(const Table& t) {
  if (t.spec.incremental)
    throw InputError("LinuxCNC compensation files hold absolute corrections: no --incremental");
  check_sign(t, "linuxcnc");
  validate(t.spec);
  check_finite(t);
  const int d = decimals(t.spec);
  std::string out;
  for (std::size_t i = 0; i < t.position_mm.size(); ++i) {
    const double nominal = t.spec.units == Units::inch ? t.position_mm[i] / 25.4
                           : t.spec.units == Units::um ? t.position_mm[i] * 1e3
                                                       : t.position_mm[i];
    out += fmt::format("{} {} {}\n", fixed(nominal, 4), fixed(directional(t, i, true), d),
                       fixed(directional(t, i, false), d));
  }
  return out;
}

// SINUMERIK 840D leadscrew error compensation (LEC), as a part program setting the system
// variables $AA_ENC_COMP (values in mm), $AA_ENC_COMP_STEP, _MIN, _MAX and _IS_MODULO of the
// first measuring system, as in Siemens' function manual "Extended Functions", K3
// Compensation. One table (the controller's backlash is a machine datum, given as a comment).
// The values are the measured errors: "A positive compensation value causes the corresponding
// machine axis to move in the negative direction" (comp_meaning.cpp).
std::string write_siemens(const Table& t, int axis_number) {
  check_sign(t, "siemens");
  if (t.spec.units != Units::mm) throw InputError("SINUMERIK LEC tables are in mm: use --units mm");
  if (t.spec.incremental)
    throw InputError("SINUMERIK LEC tables hold absolute values: no --incremental");
  if (t.spec.bidirectional)
    throw InputError("one SINUMERIK LEC table per measuring system: use a table plus backlash");
  validate(t.spec);
  check_finite(t);
  if (axis_number < 1 || axis_number > 99)
    throw InputError(fmt::format("SINUMERIK axis number {}: expected 1 .. 99", axis_number));
  const int d = std::min(decimals(t.spec), 6);
  std::string out = fmt::format(
      "; LEC for axis {} ({}), written by caldaq\n{}; backlash (MD32450) {} mm\n", t.spec.axis,
      axis_number, meaning_header(format_meaning("siemens"), "; "), fixed(t.backlash, d));
  out += "CHANDATA(1)\n";
  for (std::size_t i = 0; i < t.forward.size(); ++i)
    out += fmt::format("$AA_ENC_COMP[0,{},AX{}]={}\n", i, axis_number, fixed(t.forward[i], d));
  out += fmt::format("$AA_ENC_COMP_STEP[0,AX{}]={}\n", axis_number, fixed(t.spec.interval_mm, 4));
  out += fmt::format("$AA_ENC_COMP_MIN[0,AX{}]={}\n", axis_number, fixed(t.position_mm.front(), 4));
  out += fmt::format("$AA_ENC_COMP_MAX[0,AX{}]={}\n", axis_number, fixed(t.position_mm.back(), 4));
  out += fmt::format("$AA_ENC_COMP_IS_MODULO[0,AX{}]=0\n", axis_number);
  out += "M17\n";
  return out;
}

// Beckhoff TwinCAT CNC (ISG) leadscrew error compensation list, kw.ssfk.*: the documented
// interval (P-COMP-00018) and, per point, setpoint (P-COMP-00025), pos and neg (P-COMP-00023,
// -00024), all in 0.1 um. The header and count/mode lines are named in the docs' parameter
// list only by number here (see docs/compensation-tables.md).
std::string write_isg(const Table& t) {
  if (t.spec.incremental) throw InputError("ISG SSFK lists hold absolute values: no --incremental");
  check_sign(t, "isg");
  validate(t.spec);
  check_finite(t);
  auto tenth_um = [&](double v) {  // table units -> 0.1 um
    const double um = v * um_per_unit(t.spec.units);
    return static_cast<long long>(std::llround(um * 10.0));
  };
  std::string out =
      fmt::format("# ISG/TwinCAT CNC leadscrew error compensation, axis {}, written by caldaq\n{}",
                  t.spec.axis, meaning_header(format_meaning("isg"), "# "));
  out += "# set P-COMP-00019 (start), P-COMP-00020 (number of values) and P-COMP-00021 (mode:\n";
  out += fmt::format("# bilateral) for this list: start {:.4f} mm, {} values\n",
                     t.position_mm.front(), t.position_mm.size());
  out += fmt::format("kw.ssfk.interval {}\n", std::llround(t.spec.interval_mm * 1e4));
  for (std::size_t i = 0; i < t.position_mm.size(); ++i) {
    out += fmt::format("kw.ssfk.table[{}].setpoint {}\n", i, std::llround(t.position_mm[i] * 1e4));
    out += fmt::format("kw.ssfk.table[{}].pos {}\n", i, tenth_um(directional(t, i, true)));
    out += fmt::format("kw.ssfk.table[{}].neg {}\n", i, tenth_um(directional(t, i, false)));
  }
  return out;
}

double correction_at_um(const std::vector<double>& position_mm, const std::vector<double>& um,
                        double x_mm) {
  return interpolate(position_mm, um, x_mm, Outside::hold);
}

Applied applied(const Table& t, bool backlash_in_table) {
  validate(t.spec);
  check_finite(t);
  const double to_um = um_per_unit(t.spec.units);
  const double sign = t.spec.sign == Sign::correction ? 1.0 : -1.0;
  // The values as the control holds them: increments summed back to absolute values.
  auto absolute = [&](std::vector<double> v) {
    if (t.spec.incremental)
      for (std::size_t i = 1; i < v.size(); ++i) v[i] += v[i - 1];
    for (auto& x : v) x *= sign * to_um;
    return v;
  };
  Applied a{.position_mm = t.position_mm, .forward_um = {}, .reverse_um = {}};
  if (t.spec.bidirectional) {
    a.forward_um = absolute(t.forward);
    a.reverse_um = absolute(t.reverse);
  } else if (backlash_in_table && !t.spec.incremental) {
    std::vector<double> f, r;
    for (std::size_t i = 0; i < t.position_mm.size(); ++i)
      f.push_back(directional(t, i, true)), r.push_back(directional(t, i, false));
    a.forward_um = absolute(f);
    a.reverse_um = absolute(r);
  } else {
    a.forward_um = a.reverse_um = absolute(t.forward);
  }
  return a;
}

PredictedResidual predict(const Applied& a, std::span<const iso230_2::TargetStats> targets) {
  PredictedResidual p;
  for (const auto& t : targets) {
    const double up = t.runs_up > 0 ? t.mean_up_um : t.mean_down_um;
    const double down = t.runs_down > 0 ? t.mean_down_um : t.mean_up_um;
    p.target_mm.push_back(t.target_mm);
    p.before_up_um.push_back(up);
    p.before_down_um.push_back(down);
    p.up_um.push_back(up + correction_at_um(a.position_mm, a.forward_um, t.target_mm));
    p.down_um.push_back(down + correction_at_um(a.position_mm, a.reverse_um, t.target_mm));
    p.before_max_um = std::max({p.before_max_um, std::abs(up), std::abs(down)});
    p.after_max_um =
        std::max({p.after_max_um, std::abs(p.up_um.back()), std::abs(p.down_um.back())});
  }
  return p;
}

}  // namespace cal::comptable
