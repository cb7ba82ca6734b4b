// Reading cross-axis and volumetric compensation files back as their controls apply them (see
// comp_read.hpp): what the simulated shop's control loads, so that the verification loop of
// these formats runs against a known truth, and the prediction `daq verify` compares with.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>

#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/volumetric_comp.hpp"

namespace cal::comptable {
namespace {

namespace kin = kinematics;

constexpr std::array<const char*, 3> kAxes{"X", "Y", "Z"};

struct Line {
  std::size_t number;  // 1-based
  std::string text;
};

std::vector<Line> lines_of(std::string_view text) {
  std::vector<Line> out;
  std::istringstream in{std::string(text)};
  std::string l;
  for (std::size_t n = 1; std::getline(in, l); ++n) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    out.push_back({n, l});
  }
  return out;
}

std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> w;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == ',')) ++i;
    const std::size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != ',') ++i;
    if (i > start) w.push_back(s.substr(start, i - start));
  }
  return w;
}

// A file's name as a *.CMA names it: without its directory (TNC:\\, /), in lower case.
std::string name_key(std::string_view path) {
  const auto slash = path.find_last_of("/\\:");
  std::string b(slash == std::string_view::npos ? path : path.substr(slash + 1));
  for (auto& c : b) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return b;
}

[[noreturn]] void fail(std::string_view what, std::size_t file, std::size_t line,
                       std::string_view why) {
  throw InputError(fmt::format("{} file {}, line {}: {}", what, file + 1, line, why));
}

double number(std::string_view what, std::size_t file, std::size_t line, std::string_view s) {
  double v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || !std::isfinite(v))
    fail(what, file, line, fmt::format("'{}' is not a number", s));
  return v;
}

// The numbers inside the first [...] of s, split at commas ("$AN_CEC[0,3]" -> {0, 3}).
std::vector<int> indices(std::string_view what, std::size_t file, std::size_t line,
                         std::string_view s) {
  const auto open = s.find('['), close = s.find(']');
  if (open == std::string_view::npos || close == std::string_view::npos || close < open)
    fail(what, file, line, "no [index]");
  std::vector<int> out;
  auto inside = s.substr(open + 1, close - open - 1);
  while (true) {
    const auto comma = inside.find(',');
    out.push_back(static_cast<int>(number(what, file, line, inside.substr(0, comma))));
    if (comma == std::string_view::npos) break;
    inside.remove_prefix(comma + 1);
  }
  return out;
}

std::string axis_of(const std::map<std::string, int>& numbers, int n, std::string_view what,
                    std::size_t file, std::size_t line) {
  for (const auto& [name, k] : numbers)
    if (k == n) return name;
  fail(what, file, line, fmt::format("axis number {} is none of the machine's axes", n));
}

// SINUMERIK CEC: per table t, $AN_CEC[t,i] (mm), $AN_CEC_INPUT_AXIS[t]=(AXn),
// $AN_CEC_OUTPUT_AXIS[t]=(AXn), $AN_CEC_STEP[t], $AN_CEC_MIN[t].
void read_cec(const std::vector<Line>& in, std::size_t file,
              const std::map<std::string, int>& numbers, std::vector<CrossTableApplied>& out) {
  constexpr std::string_view what = "SINUMERIK CEC";
  struct T {
    std::map<int, double> values;
    std::optional<double> step, min;
    std::string input, output;
  };
  std::map<int, T> tables;
  const auto ax = [&](std::string_view v, std::size_t line) {
    const auto p = v.find("AX");
    if (p == std::string_view::npos) fail(what, file, line, "expected (AXn)");
    auto n = v.substr(p + 2);
    if (const auto close = n.find(')'); close != std::string_view::npos) n = n.substr(0, close);
    return axis_of(numbers, static_cast<int>(number(what, file, line, n)), what, file, line);
  };
  for (const auto& [n, l] : in) {
    const auto eq = l.find('=');
    if (!l.starts_with("$AN_CEC") || eq == std::string::npos) continue;
    const std::string_view name(l.data(), eq), value(l.data() + eq + 1, l.size() - eq - 1);
    const auto idx = indices(what, file, n, name);
    T& t = tables[idx.front()];
    if (name.starts_with("$AN_CEC[")) {
      if (idx.size() != 2) fail(what, file, n, "expected $AN_CEC[t,i]");
      t.values[idx[1]] = number(what, file, n, value);
    } else if (name.starts_with("$AN_CEC_INPUT_AXIS[")) {
      t.input = ax(value, n);
    } else if (name.starts_with("$AN_CEC_OUTPUT_AXIS[")) {
      t.output = ax(value, n);
    } else if (name.starts_with("$AN_CEC_STEP[")) {
      t.step = number(what, file, n, value);
    } else if (name.starts_with("$AN_CEC_MIN[")) {
      t.min = number(what, file, n, value);
    }
  }
  for (const auto& [k, t] : tables) {
    if (t.input.empty() || t.output.empty() || !t.step || !t.min || t.values.size() < 2)
      fail(what, file, 0, fmt::format("table {} lacks its axes, _STEP, _MIN or 2 values", k));
    CrossTableApplied a{t.input, t.output, {}, {}};
    int expect = 0;
    for (const auto& [i, v] : t.values) {
      if (i != expect++)
        fail(what, file, 0, fmt::format("table {}: point {} is missing", k, i - 1));
      a.position_mm.push_back(*t.min + *t.step * i);
      a.correction_um.push_back(v * 1e3);
    }
    out.push_back(std::move(a));
  }
}

// ISG cross compensation list: kopf.log_achs_name (the slave), kw.crosscomp.master_ax_nr,
// kw.crosscomp.table[i].setpoint and .correction (0.1 um).
void read_isg_cross(const std::vector<Line>& in, std::size_t file,
                    const std::map<std::string, int>& numbers,
                    std::vector<CrossTableApplied>& out) {
  constexpr std::string_view what = "ISG cross compensation";
  std::string slave, master;
  std::map<int, double> set, value;
  for (const auto& [n, l] : in) {
    const auto w = words(l);
    if (w.size() != 2 || l.starts_with("#")) continue;
    if (w[0] == "kopf.log_achs_name") slave = std::string(w[1]);
    if (w[0] == "kw.crosscomp.master_ax_nr")
      master = axis_of(numbers, static_cast<int>(number(what, file, n, w[1])), what, file, n);
    if (w[0] == "kw.crosscomp.unit" && number(what, file, n, w[1]) != 1)
      fail(what, file, n, "only kw.crosscomp.unit 1 (0.1 um) is read");
    if (!w[0].starts_with("kw.crosscomp.table[")) continue;
    const int k = indices(what, file, n, w[0]).front();
    const double v = number(what, file, n, w[1]) * 0.1;  // um
    if (w[0].ends_with(".setpoint")) set[k] = v * 1e-3;
    if (w[0].ends_with(".correction")) value[k] = v;
  }
  if (slave.empty() || master.empty() || set.size() < 2)
    fail(what, file, 0, "no kopf.log_achs_name, kw.crosscomp.master_ax_nr and 2 points");
  CrossTableApplied a{master, slave, {}, {}};
  for (const auto& [k, x] : set) {
    if (!value.contains(k)) fail(what, file, 0, fmt::format("point {} has no correction", k));
    a.position_mm.push_back(x);
    a.correction_um.push_back(value[k]);
  }
  out.push_back(std::move(a));
}

// caldaq's cross CSV: input,output,point,position_mm,correction_mm.
void read_cross_csv(const std::vector<Line>& in, std::size_t file,
                    std::vector<CrossTableApplied>& out) {
  constexpr std::string_view what = "caldaq cross CSV";
  std::map<std::pair<std::string, std::string>, CrossTableApplied> by;
  std::vector<std::pair<std::string, std::string>> order;
  for (const auto& [n, l] : in) {
    if (l.empty() || l.starts_with("#") || l.starts_with("input,")) continue;
    const auto w = words(l);
    if (w.size() != 5) fail(what, file, n, "expected input,output,point,position_mm,correction_mm");
    const std::pair<std::string, std::string> key{std::string(w[0]), std::string(w[1])};
    if (!by.contains(key)) order.push_back(key), by[key] = {key.first, key.second, {}, {}};
    by[key].position_mm.push_back(number(what, file, n, w[3]));
    by[key].correction_um.push_back(number(what, file, n, w[4]) * 1e3);
  }
  for (const auto& k : order) out.push_back(std::move(by[k]));
}

// LinuxCNC matrixkins: X_joint = C_xx X + C_xy Y + C_xz Z ...: the control adds C_ab x b to a.
// As tables: the line through two points far apart (exact, linear).
void read_matrixkins(const std::vector<Line>& in, std::size_t file,
                     std::vector<CrossTableApplied>& out) {
  constexpr std::string_view what = "LinuxCNC matrixkins";
  constexpr double kFarMm = 1e5;
  for (const auto& [n, l] : in) {
    const auto w = words(l);
    if (w.size() != 3 || w[0] != "setp" || !w[1].starts_with("matrixkins.C_")) continue;
    const auto ab = w[1].substr(13);
    const auto a = std::string_view("xyz").find(ab.size() == 2 ? ab[0] : '?');
    const auto b = std::string_view("xyz").find(ab.size() == 2 ? ab[1] : '?');
    if (a == std::string_view::npos || b == std::string_view::npos)
      fail(what, file, n, fmt::format("'{}' is not matrixkins.C_ab with a, b of x, y, z", w[1]));
    const double c = number(what, file, n, w[2]);
    if (a == b) {
      if (std::abs(c - 1.0) > 1e-3)
        fail(what, file, n, "a diagonal coefficient other than 1 (a scale) is not read");
      continue;
    }
    out.push_back({kAxes[b], kAxes[a], {-kFarMm, kFarMm}, {-kFarMm * c * 1e3, kFarMm * c * 1e3}});
  }
}

// ISG volumetric: the configuration list gives the chain (letters without F) and the number
// of workpiece-side axes; the CSV the location errors C0Y B0Z A0Z (rad) and per axis a block
// "X EXX EYX EZX EAX EBX ECX" (mm, mm, mm, rad, rad, rad over the argument in mm).
struct IsgVolumetric {
  std::string chain;
  int workpiece_axes = -1;
  std::optional<kin::Squareness> squareness;
  std::array<std::vector<std::array<double, 7>>, 3> rows;
};

void read_isg_vol_list(const std::vector<Line>& in, std::size_t file, IsgVolumetric& v) {
  constexpr std::string_view what = "ISG volumetric configuration";
  for (const auto& [n, l] : in) {
    const auto w = words(l);
    if (w.size() != 2 || l.starts_with("#")) continue;
    if (w[0] == "chain") v.chain = std::string(w[1]);
    if (w[0] == "workpiece_axes") v.workpiece_axes = static_cast<int>(number(what, file, n, w[1]));
  }
}

void read_isg_vol_csv(const std::vector<Line>& in, std::size_t file, IsgVolumetric& v) {
  constexpr std::string_view what = "ISG CSV parameter file";
  int axis = -1;
  bool location = false;
  for (const auto& [n, l] : in) {
    if (l.empty() || l.starts_with("//")) continue;
    if (l.starts_with("#")) {
      axis = -1, location = false;
      continue;
    }
    const auto w = words(l);
    if (w.size() == 3 && w[0] == "C0Y") {
      location = true;
      continue;
    }
    if (location) {
      if (w.size() != 3) fail(what, file, n, "expected the three location errors");
      v.squareness =
          kin::Squareness{number(what, file, n, w[0]) * 1e6, number(what, file, n, w[1]) * 1e6,
                          number(what, file, n, w[2]) * 1e6};
      location = false;
      continue;
    }
    if (w.size() == 7 && (w[0] == "X" || w[0] == "Y" || w[0] == "Z")) {
      axis = static_cast<int>(std::string_view("XYZ").find(w[0][0]));
      continue;
    }
    if (axis < 0) fail(what, file, n, "a row before its block's header (X EXX ...)");
    if (w.size() != 7) fail(what, file, n, "expected the argument and six errors");
    std::array<double, 7> r{};
    for (std::size_t k = 0; k < 7; ++k) r[k] = number(what, file, n, w[k]);
    v.rows[static_cast<std::size_t>(axis)].push_back(r);
  }
}

kin::Machine machine_of(const IsgVolumetric& v, std::array<std::array<double, 2>, 3>& range) {
  if (v.chain.size() != 3 || v.workpiece_axes < 0 || v.workpiece_axes > 3)
    throw InputError("ISG volumetric: the configuration list (chain, workpiece_axes) is missing");
  if (!v.squareness) throw InputError("ISG volumetric: the CSV has no location errors (C0Y ...)");
  std::string topology = v.chain;
  topology.insert(static_cast<std::size_t>(v.workpiece_axes), 1, 'F');
  kin::Machine m;
  m.topology = kin::topology_from_string(topology);
  m.squareness = *v.squareness;
  for (std::size_t a = 0; a < 3; ++a) {
    const auto& rows = v.rows[a];
    if (rows.size() < 2)
      throw InputError(fmt::format("ISG volumetric: axis {} has fewer than 2 rows", kAxes[a]));
    std::vector<double> q;
    for (const auto& r : rows) q.push_back(r[0]);
    range[a] = {q.front(), q.back()};
    for (std::size_t d = 0; d < 6; ++d) {
      std::vector<double> e;
      for (const auto& r : rows) e.push_back(r[d + 1] * (d < 3 ? 1e3 : 1e6));  // um, urad
      kin::component(m, static_cast<kin::Component>(6 * a + d)) = kin::ErrorFunction::table(q, e);
    }
  }
  return m;
}

// HEIDENHAIN *.CMA (MANUALplus 620 technical manual p. 718): "[Axis in column from *.com] =
// F(Axis in column from *.cma, in which *.com is entered)": a header line of the columns (ACTIVE
// and one per input axis), rows of *.COM names, the row with * in ACTIVE the active one ("only
// one table can be active"). Each *.COM name of the active row (without its directory, in
// lower case) -> the input axis of its column.
void read_cma(const std::vector<Line>& in, std::size_t file,
              std::map<std::string, std::string>& input_of) {
  constexpr std::string_view what = "HEIDENHAIN *.CMA";
  std::vector<std::string_view> header;
  std::size_t active = 0;
  bool found = false;
  for (const auto& [n, l] : in) {
    const auto w = words(l);
    if (w.empty()) continue;
    if (header.empty()) {
      header = w;
      const auto it = std::find(header.begin(), header.end(), "ACTIVE");
      if (it == header.end())
        fail(what, file, n, "expected the header line: ACTIVE and a column per input axis");
      active = static_cast<std::size_t>(it - header.begin());
      continue;
    }
    if (w.size() != header.size()) fail(what, file, n, "a row of another width than the header");
    if (w[active] != "*") continue;
    if (found) fail(what, file, n, "a second active row (only one row can be active)");
    found = true;
    for (std::size_t k = 0; k < w.size(); ++k)
      if (k != active && header[k] != "NR" && w[k] != "-")
        input_of[name_key(w[k])] = std::string(header[k]);
  }
  if (!found) fail(what, file, 0, "no active row (* in the ACTIVE column)");
}

// HEIDENHAIN *.COM: the header "AXISPOS" and a column per output axis, rows of the position
// (mm) and the values (mm) of each column; `input` from the *.CMA.
void read_com(const std::vector<Line>& in, std::size_t file, const std::string& input,
              std::vector<CrossTableApplied>& out) {
  constexpr std::string_view what = "HEIDENHAIN *.COM";
  std::vector<CrossTableApplied> t;
  for (const auto& [n, l] : in) {
    const auto w = words(l);
    if (w.empty()) continue;
    if (t.empty()) {
      if (w[0] != "AXISPOS" || w.size() < 2)
        fail(what, file, n, "expected the header line: AXISPOS and a column per axis");
      for (std::size_t k = 1; k < w.size(); ++k) {
        if (w[k] == "BACKLASH")
          fail(what, file, n,
               "a BACKLASH column (the negative direction's values) is not read as a cross-axis "
               "table");
        t.push_back({input, std::string(w[k]), {}, {}});
      }
      continue;
    }
    if (w.size() != t.size() + 1) fail(what, file, n, "a row of another width than the header");
    const double x = number(what, file, n, w[0]);
    for (std::size_t k = 0; k < t.size(); ++k) {
      t[k].position_mm.push_back(x);
      t[k].correction_um.push_back(number(what, file, n, w[k + 1]) * 1e3);
    }
  }
  if (t.empty()) fail(what, file, 0, "no header line (AXISPOS ...)");
  for (auto& x : t) out.push_back(std::move(x));
}

// Which function a file of the set is, from its text.
enum class Part {
  cec,
  isg_cross,
  isg_other,
  csv,
  matrixkins,
  hal_other,
  vol_list,
  vol_csv,
  com,
  cma
};

Part part_of(std::string_view format, std::string_view text) {
  if (format == "siemens-cec") return Part::cec;
  if (format == "heidenhain") {
    const auto first = text.find_first_not_of(" \t\r\n");
    return first != std::string_view::npos && text.substr(first).starts_with("AXISPOS") ? Part::com
                                                                                        : Part::cma;
  }
  if (format == "csv") return Part::csv;
  if (format == "isg-cross")
    return text.find("kw.crosscomp.") != std::string_view::npos ? Part::isg_cross : Part::isg_other;
  if (format == "linuxcnc-matrixkins" || format == "linuxcnc")
    return text.find("matrixkins.C_") != std::string_view::npos ? Part::matrixkins
                                                                : Part::hal_other;
  // isg-volumetric
  return text.find("file_format[0]") != std::string_view::npos ? Part::vol_list : Part::vol_csv;
}

}  // namespace

bool is_cross_format(std::string_view format) {
  return format == "csv" || format == "siemens-cec" || format == "isg-cross" ||
         format == "linuxcnc-matrixkins" || format == "isg-volumetric" || format == "heidenhain";
}

CrossApplied read_cross_applied(std::string_view format, std::span<const std::string> files,
                                const std::map<std::string, int>& axis_numbers, bool inverted) {
  std::vector<CompFile> named;
  for (const auto& t : files) named.push_back({"", t});
  return read_cross_applied(format, named, axis_numbers, inverted);
}

namespace {
// HEIDENHAIN: each *.COM's input axis, from the active row of the set's *.CMA.
std::map<std::string, std::string> com_inputs(std::span<const CompFile> files) {
  std::map<std::string, std::string> input_of;
  bool cma = false;
  for (std::size_t f = 0; f < files.size(); ++f)
    if (part_of("heidenhain", files[f].text) == Part::cma) {
      if (cma) throw InputError("HEIDENHAIN: more than one *.CMA among the files");
      cma = true;
      read_cma(lines_of(files[f].text), f, input_of);
    }
  if (!cma)
    throw InputError(
        "HEIDENHAIN: no *.CMA among the files: a *.COM's input axis is named there, not in the "
        "*.COM");
  return input_of;
}

const std::string& com_input(const std::map<std::string, std::string>& input_of, const CompFile& f,
                             std::size_t index) {
  const auto it = input_of.find(name_key(f.name));
  if (f.name.empty() || it == input_of.end())
    throw InputError(fmt::format(
        "HEIDENHAIN *.COM file {} ('{}'): not in the active row of the *.CMA, so its input axis "
        "is unknown",
        index + 1, f.name));
  return it->second;
}
}  // namespace

CrossApplied read_cross_applied(std::string_view format, std::span<const CompFile> files,
                                const std::map<std::string, int>& axis_numbers, bool inverted) {
  if (!is_cross_format(format))
    throw InputError(fmt::format(
        "reading a '{}' cross-axis compensation back is not supported (csv, siemens-cec, "
        "isg-cross, linuxcnc-matrixkins, isg-volumetric, heidenhain)",
        format));
  CrossApplied a;
  IsgVolumetric vol;
  const auto input_of =
      format == "heidenhain" ? com_inputs(files) : std::map<std::string, std::string>{};
  for (std::size_t f = 0; f < files.size(); ++f) {
    const auto in = lines_of(files[f].text);
    switch (part_of(format, files[f].text)) {
      case Part::com:
        read_com(in, f, com_input(input_of, files[f], f), a.tables);
        break;
      case Part::cma:
        break;  // read above
      case Part::cec:
        read_cec(in, f, axis_numbers, a.tables);
        break;
      case Part::isg_cross:
        read_isg_cross(in, f, axis_numbers, a.tables);
        break;
      case Part::csv:
        read_cross_csv(in, f, a.tables);
        break;
      case Part::matrixkins:
        read_matrixkins(in, f, a.tables);
        break;
      case Part::vol_list:
        read_isg_vol_list(in, f, vol);
        break;
      case Part::vol_csv:
        read_isg_vol_csv(in, f, vol);
        break;
      case Part::isg_other:
      case Part::hal_other:
        break;  // positioning tables of the same set: not of the cross-axis function
    }
  }
  // The values as the vendor reads them: an error is taken off (the control adds -value).
  const bool error = format_meaning(format).written == Sign::error;
  const double sign = (error ? -1.0 : 1.0) * (inverted ? -1.0 : 1.0);
  if (format == "isg-volumetric") {
    a.volumetric = machine_of(vol, a.volumetric_range_mm);
    // volcomp::correction_um is the correction of the errors: the vendor's reading already.
    a.volumetric_factor = inverted ? -1.0 : 1.0;
    return a;
  }
  if (a.tables.empty())
    throw InputError(
        fmt::format("{}: no cross-axis table in the {} file(s)", format, files.size()));
  for (auto& t : a.tables) {
    if (t.position_mm.size() < 2 || !std::is_sorted(t.position_mm.begin(), t.position_mm.end()))
      throw InputError(fmt::format("{}: the table of {} over {} needs 2 increasing points", format,
                                   t.output, t.input));
    for (auto& v : t.correction_um) v *= sign;
  }
  return a;
}

kin::Vec3 cross_correction_um(const CrossApplied& a, const kin::Vec3& p) {
  kin::Vec3 c{};
  const auto index = [](const std::string& axis) {
    return static_cast<std::size_t>(std::string_view("XYZ").find(axis.front()));
  };
  for (const auto& t : a.tables) {
    const auto in = index(t.input), out = index(t.output);
    if (in > 2 || out > 2) continue;  // an axis the simulated machine does not have
    c[out] += correction_at_um(t.position_mm, t.correction_um, p[in]);
  }
  if (a.volumetric) {
    kin::Vec3 q = p;
    for (std::size_t k = 0; k < 3; ++k)
      q[k] = std::clamp(q[k], a.volumetric_range_mm[k][0], a.volumetric_range_mm[k][1]);
    const auto v = volcomp::correction_um(*a.volumetric, q);
    for (std::size_t k = 0; k < 3; ++k) c[k] += a.volumetric_factor * v[k];
  }
  return c;
}

namespace {
// A value's decimals as written, so a rewritten file keeps its notation.
int decimals_written(std::string_view v) {
  const auto dot = v.find('.');
  return dot == std::string_view::npos ? 0 : static_cast<int>(v.size() - dot - 1);
}
}  // namespace

std::string scale_cross_values(std::string_view format, std::string_view text, double factor) {
  const auto part = part_of(format, text);
  std::string out;
  for (const auto& [n, l] : lines_of(text)) {
    std::string line = l;
    const auto w = words(l);
    // A value made smaller keeps what the control makes of it: a control that applies the
    // file 25.4 times as large needs two more decimals (where the notation has decimals).
    const int more =
        std::abs(factor) < 1 ? static_cast<int>(std::ceil(-std::log10(std::abs(factor)))) : 0;
    // (a copy: clang before 16 cannot capture a structured binding)
    const auto scaled = [&, line_no = n](std::string_view v) {
      const int d = decimals_written(v);
      return fixed(number(format, 0, line_no, v) * factor, d > 0 ? d + more : 0);
    };
    if (part == Part::cec && l.starts_with("$AN_CEC[")) {
      const auto eq = l.find('=');
      line = l.substr(0, eq + 1) + scaled(std::string_view(l).substr(eq + 1));
    } else if (part == Part::isg_cross && w.size() == 2 &&
               w[0].starts_with("kw.crosscomp.table[") && w[0].ends_with(".correction")) {
      line = fmt::format("{} {}", w[0], scaled(w[1]));
    } else if (part == Part::matrixkins && w.size() == 3 && w[0] == "setp" &&
               w[1].starts_with("matrixkins.C_") && w[1].size() == 15 && w[1][13] != w[1][14]) {
      line = fmt::format("setp {} {}", w[1], scaled(w[2]));
    } else if (part == Part::csv && w.size() == 5 && !l.starts_with("#") &&
               !l.starts_with("input,")) {
      line = fmt::format("{},{},{},{},{}", w[0], w[1], w[2], w[3], scaled(w[4]));
    } else if (part == Part::com && w.size() >= 2 && w[0] != "AXISPOS") {
      line = std::string(w[0]);  // the position; every column's value scaled
      for (std::size_t k = 1; k < w.size(); ++k) line += " " + scaled(w[k]);
    } else if (part == Part::vol_csv && !l.starts_with("//") && !l.starts_with("#") && !w.empty() &&
               w[0] != "C0Y" && w[0] != "X" && w[0] != "Y" && w[0] != "Z") {
      // The location errors' line (3 values) and each row (the argument first, unchanged).
      line = w.size() == 3 ? "" : std::string(w[0]);
      for (std::size_t k = w.size() == 3 ? 0 : 1; k < w.size(); ++k)
        line += (line.empty() ? "" : " ") + scaled(w[k]);
    }
    out += line + "\n";
  }
  return out;
}

std::string shift_cross_values(std::string_view format, std::string_view text,
                               const std::string& output, double add_um,
                               const std::map<std::string, int>& axis_numbers, bool& with_table) {
  if (format != "siemens-cec" && format != "isg-cross" && format != "csv" && format != "heidenhain")
    throw InputError(fmt::format(
        "a {} compensation cannot hold a constant of one axis: check the control's reference "
        "point (or the workpiece datum) instead",
        format));
  const auto part = part_of(format, text);
  const auto in = lines_of(text);
  with_table = false;
  // The table (CEC index) or rows of `output`.
  std::optional<int> cec_table;
  if (part == Part::cec) {
    const auto it = axis_numbers.find(output);
    const std::string ax = it == axis_numbers.end() ? "" : fmt::format("=(AX{})", it->second);
    for (const auto& [n, l] : in)
      if (!cec_table && !ax.empty() && l.starts_with("$AN_CEC_OUTPUT_AXIS[") && l.ends_with(ax))
        cec_table = indices(format, 0, n, l).front();
    with_table = cec_table.has_value();
  }
  if (part == Part::isg_cross)
    for (const auto& [n, l] : in)
      if (const auto w = words(l); w.size() == 2 && w[0] == "kopf.log_achs_name" && w[1] == output)
        with_table = true;
  if (part == Part::csv)
    for (const auto& [n, l] : in)
      if (const auto w = words(l); w.size() == 5 && w[1] == output && !l.starts_with("#"))
        with_table = true;
  // HEIDENHAIN: the column of `output` in a *.COM (the first file that has one is moved).
  std::optional<std::size_t> com_column;
  if (part == Part::com)
    for (const auto& [n, l] : in)
      if (const auto w = words(l); !w.empty() && w[0] == "AXISPOS") {
        for (std::size_t k = 1; k < w.size(); ++k)
          if (w[k] == output) com_column = k;
        break;
      }
  if (com_column) with_table = true;
  const double sign = format_meaning(format).written == Sign::error ? -1.0 : 1.0;
  std::string out;
  for (const auto& [n, l] : in) {
    std::string line = l;
    const auto w = words(l);
    const auto moved = [&, line_no = n](std::string_view v, double unit_um) {
      return fixed(number(format, 0, line_no, v) + sign * add_um / unit_um, decimals_written(v));
    };
    if (with_table && cec_table && l.starts_with("$AN_CEC[") &&
        indices(format, 0, n, l).front() == *cec_table) {
      const auto eq = l.find('=');
      line = l.substr(0, eq + 1) + moved(std::string_view(l).substr(eq + 1), 1e3);
    } else if (with_table && part == Part::isg_cross && w.size() == 2 &&
               w[0].starts_with("kw.crosscomp.table[") && w[0].ends_with(".correction")) {
      line = fmt::format("{} {}", w[0], moved(w[1], 0.1));
    } else if (with_table && part == Part::csv && w.size() == 5 && w[1] == output &&
               !l.starts_with("#")) {
      line = fmt::format("{},{},{},{},{}", w[0], w[1], w[2], w[3], moved(w[4], 1e3));
    } else if (com_column && w.size() > *com_column && w[0] != "AXISPOS") {
      line = std::string(w[0]);
      for (std::size_t k = 1; k < w.size(); ++k)
        line += " " + (k == *com_column ? moved(w[k], 1e3) : std::string(w[k]));
    }
    out += line + "\n";
  }
  return out;
}

namespace {
// A position as written, moved by -shift (mm) in the file's unit (um per unit of the position).
std::string position_moved(std::string_view format, std::size_t line, std::string_view v,
                           double shift_mm, double mm_per_unit) {
  // At least the decimals that hold the shift (0.001 mm: 3; 0.1 um units: 0).
  const int d = std::max(decimals_written(v), mm_per_unit < 1e-3 ? 0 : 4);
  return fixed(number(format, 0, line, v) - shift_mm / mm_per_unit, d);
}
}  // namespace

std::vector<CompFile> shift_cross_positions(std::string_view format,
                                            std::span<const CompFile> files,
                                            const std::string& input, const std::string& output,
                                            double shift_mm,
                                            const std::map<std::string, int>& axis_numbers) {
  if (format != "siemens-cec" && format != "isg-cross" && format != "csv" && format != "heidenhain")
    throw InputError(fmt::format(
        "a {} compensation has no positions of one table to shift ({}): check the machine "
        "datum of {} instead",
        format,
        format == "linuxcnc-matrixkins" ? "matrixkins is a line: a shift of it is a constant"
                                        : "its tables are the error parameters of whole axes",
        input));
  const auto number_of = [&](const std::string& axis) {
    const auto it = axis_numbers.find(axis);
    return it == axis_numbers.end() ? -1 : it->second;
  };
  const auto input_of =
      format == "heidenhain" ? com_inputs(files) : std::map<std::string, std::string>{};
  std::vector<CompFile> out;
  bool any = false;
  for (std::size_t f = 0; f < files.size(); ++f) {
    const auto part = part_of(format, files[f].text);
    const auto in = lines_of(files[f].text);
    // Which lines hold this table's positions.
    std::optional<int> cec;  // the CEC table of output over input
    bool whole = false;      // every position line of the file (ISG list, *.COM)
    if (part == Part::cec) {
      std::map<int, std::pair<std::string, std::string>> io;
      for (const auto& [n, l] : in) {
        // `line` by copy: clang 14 (the fuzz build) cannot capture a structured binding.
        const auto ax = [line = l](std::string_view prefix) {
          return line.starts_with(prefix) && line.find("(AX") != std::string::npos;
        };
        if (ax("$AN_CEC_INPUT_AXIS[")) io[indices(format, f, n, l).front()].first = l;
        if (ax("$AN_CEC_OUTPUT_AXIS[")) io[indices(format, f, n, l).front()].second = l;
      }
      for (const auto& [t, p] : io)
        if (!cec && p.first.ends_with(fmt::format("=(AX{})", number_of(input))) &&
            p.second.ends_with(fmt::format("=(AX{})", number_of(output))))
          cec = t;
    }
    if (part == Part::isg_cross) {
      bool slave = false, master = false;
      for (const auto& [n, l] : in) {
        const auto w = words(l);
        if (w.size() == 2 && w[0] == "kopf.log_achs_name" && w[1] == output) slave = true;
        if (w.size() == 2 && w[0] == "kw.crosscomp.master_ax_nr" &&
            number(format, f, n, w[1]) == number_of(input))
          master = true;
      }
      whole = slave && master;
    }
    if (part == Part::com && com_input(input_of, files[f], f) == input)
      for (const auto& [n, l] : in)
        if (const auto w = words(l); !w.empty() && w[0] == "AXISPOS") {
          whole = std::find(w.begin() + 1, w.end(), output) != w.end();
          break;
        }
    std::string text;
    for (const auto& [n, l] : in) {
      std::string line = l;
      const auto w = words(l);
      if (cec && (l.starts_with("$AN_CEC_MIN[") || l.starts_with("$AN_CEC_MAX[")) &&
          indices(format, f, n, l).front() == *cec) {
        const auto eq = l.find('=');
        line = l.substr(0, eq + 1) +
               position_moved(format, n, std::string_view(l).substr(eq + 1), shift_mm, 1.0);
        any = true;
      } else if (whole && part == Part::isg_cross && w.size() == 2 &&
                 w[0].starts_with("kw.crosscomp.table[") && w[0].ends_with(".setpoint")) {
        line = fmt::format("{} {}", w[0], position_moved(format, n, w[1], shift_mm, 1e-4));
        any = true;
      } else if (whole && part == Part::com && w.size() >= 2 && w[0] != "AXISPOS") {
        line = position_moved(format, n, w[0], shift_mm, 1.0);
        for (std::size_t k = 1; k < w.size(); ++k) line += " " + std::string(w[k]);
        any = true;
      } else if (part == Part::csv && w.size() == 5 && w[0] == input && w[1] == output &&
                 !l.starts_with("#")) {
        line = fmt::format("{},{},{},{},{}", w[0], w[1], w[2],
                           position_moved(format, n, w[3], shift_mm, 1.0), w[4]);
        any = true;
      }
      text += line + "\n";
    }
    out.push_back({files[f].name, text});
  }
  if (!any)
    throw InputError(fmt::format("{}: no table of {} over {} whose positions could be shifted",
                                 format, output, input));
  return out;
}

}  // namespace cal::comptable
