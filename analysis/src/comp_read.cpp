// Reading a controller table back (see comp_read.hpp). Each reader knows only the file's text.
#include "cal/analysis/comp_read.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/error.hpp"

namespace cal::comptable {
namespace {

struct Lines {
  std::vector<std::string> lines;
  explicit Lines(std::string_view text) {
    std::string line;
    std::istringstream in{std::string(text)};
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines.push_back(line);
    }
  }
};

[[noreturn]] void fail(std::string_view format, std::size_t line, std::string_view what) {
  throw InputError(fmt::format("{} table, line {}: {}", format, line + 1, what));
}

double number(std::string_view format, std::size_t line, std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  double v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || !std::isfinite(v))
    fail(format, line, fmt::format("'{}' is not a number", s));
  return v;
}

std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> w;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
    if (i > start) w.push_back(s.substr(start, i - start));
  }
  return w;
}

// The index in "NAME[a,i,AXn]" or "table[i]": the number after the last '[' or ','.
int index_in(std::string_view format, std::size_t line, std::string_view s, bool middle) {
  const auto open = s.find('[');
  const auto close = s.find(']');
  if (open == std::string_view::npos || close == std::string_view::npos || close < open)
    fail(format, line, "no [index]");
  auto inside = s.substr(open + 1, close - open - 1);
  if (middle) {  // [0,i,AXn]
    const auto a = inside.find(','), b = inside.rfind(',');
    if (a == std::string_view::npos || b == a) fail(format, line, "expected [e,i,AXn]");
    inside = inside.substr(a + 1, b - a - 1);
  }
  return static_cast<int>(number(format, line, inside));
}

Applied siemens(const Lines& in) {
  std::map<int, double> values;
  double step = 0, min = 0;
  bool have_step = false, have_min = false;
  for (std::size_t i = 0; i < in.lines.size(); ++i) {
    const auto& l = in.lines[i];
    const auto eq = l.find('=');
    if (l.empty() || l[0] != '$' || eq == std::string::npos) continue;
    const std::string_view name(l.data(), eq), value(l.data() + eq + 1, l.size() - eq - 1);
    if (name.starts_with("$AA_ENC_COMP_STEP")) {
      step = number("siemens", i, value), have_step = true;
    } else if (name.starts_with("$AA_ENC_COMP_MIN")) {
      min = number("siemens", i, value), have_min = true;
    } else if (name.starts_with("$AA_ENC_COMP[")) {
      values[index_in("siemens", i, name, true)] = number("siemens", i, value);
    }
  }
  if (!have_step || !have_min || values.size() < 2)
    fail("siemens", in.lines.size() - 1, "no $AA_ENC_COMP table with _STEP and _MIN");
  Applied a;
  int expect = 0;
  for (const auto& [k, v] : values) {
    if (k != expect++) fail("siemens", 0, fmt::format("point {} is missing", expect - 1));
    a.position_mm.push_back(min + step * k);
    a.forward_um.push_back(v * 1e3);  // mm, as written
  }
  a.reverse_um = a.forward_um;
  return a;
}

Applied linuxcnc(const Lines& in) {
  Applied a;
  for (std::size_t i = 0; i < in.lines.size(); ++i) {
    const auto w = words(in.lines[i]);
    if (w.empty()) continue;
    if (w.size() != 3) fail("linuxcnc", i, "expected 'nominal forward-trim reverse-trim'");
    a.position_mm.push_back(number("linuxcnc", i, w[0]));
    a.forward_um.push_back(number("linuxcnc", i, w[1]) * 1e3);
    a.reverse_um.push_back(number("linuxcnc", i, w[2]) * 1e3);
  }
  return a;
}

Applied isg(const Lines& in) {
  std::map<int, double> set, pos, neg;
  for (std::size_t i = 0; i < in.lines.size(); ++i) {
    const auto w = words(in.lines[i]);
    if (w.size() != 2 || !w[0].starts_with("kw.ssfk.table[")) continue;
    const int k = index_in("isg", i, w[0], false);
    const double v = number("isg", i, w[1]) * 0.1;  // 0.1 um
    if (w[0].ends_with(".setpoint")) set[k] = v * 1e-3;
    if (w[0].ends_with(".pos")) pos[k] = v;
    if (w[0].ends_with(".neg")) neg[k] = v;
  }
  Applied a;
  for (const auto& [k, x] : set) {
    if (!pos.contains(k) || !neg.contains(k))
      fail("isg", 0, fmt::format("point {} lacks a value", k));
    a.position_mm.push_back(x);
    a.forward_um.push_back(pos[k]);
    a.reverse_um.push_back(neg[k]);
  }
  return a;
}

Applied heidenhain(const Lines& in) {
  Applied a;
  std::size_t columns = 0;
  for (std::size_t i = 0; i < in.lines.size(); ++i) {
    const auto w = words(in.lines[i]);
    if (w.empty()) continue;
    if (w[0] == "AXISPOS") {
      columns = w.size();
      if (columns < 2 || columns > 3) fail("heidenhain", i, "expected AXISPOS AXIS [BACKLASH]");
      continue;
    }
    if (columns == 0 || w.size() != columns) fail("heidenhain", i, "a row of another width");
    a.position_mm.push_back(number("heidenhain", i, w[0]));
    a.forward_um.push_back(number("heidenhain", i, w[1]) * 1e3);
    a.reverse_um.push_back(number("heidenhain", i, w[columns == 3 ? 2 : 1]) * 1e3);
  }
  return a;
}

Applied fanuc(const Lines& in) {
  std::map<int, long long> param;
  double unit_um = 0;
  std::vector<std::pair<double, long long>> points;
  bool rows = false;
  for (std::size_t i = 0; i < in.lines.size(); ++i) {
    const auto w = words(in.lines[i]);
    if (w.size() >= 3 && w[1] == "=" && w[0].size() == 4)
      param[static_cast<int>(number("fanuc", i, w[0]))] = std::llround(number("fanuc", i, w[2]));
    if (in.lines[i].starts_with("Compensation values: detection units of "))
      unit_um = number("fanuc", i, words(in.lines[i])[5]);
    if (in.lines[i] == "point position_mm value") {
      rows = true;
      continue;
    }
    if (rows && w.size() == 3)
      points.emplace_back(number("fanuc", i, w[1]), std::llround(number("fanuc", i, w[2])));
  }
  if (!param.contains(3620) || !param.contains(3621) || !param.contains(3623) || unit_um <= 0 ||
      points.size() < 2)
    fail("fanuc", 0, "no parameters 3620, 3621, 3623, detection unit and points");
  const auto ref = static_cast<std::size_t>(param[3620] - param[3621]);
  if (ref >= points.size()) fail("fanuc", 0, "the reference point is not among the points");
  const double unit = unit_um * static_cast<double>(param[3623]);
  // The absolute compensation: the values summed from the farthest negative point, taken
  // relative to the reference position's point (zero there).
  std::vector<long long> sum;
  long long s = 0;
  for (const auto& [x, v] : points) sum.push_back(s += v);
  Applied a;
  for (std::size_t k = 0; k < points.size(); ++k) {
    a.position_mm.push_back(points[k].first);
    a.forward_um.push_back(static_cast<double>(sum[k] - sum[ref]) * unit);
  }
  a.reverse_um = a.forward_um;
  return a;
}

}  // namespace

Applied read_applied(std::string_view format, std::string_view text, bool inverted) {
  const Lines in(text);
  Applied a =
      format == "siemens"      ? siemens(in)
      : format == "linuxcnc"   ? linuxcnc(in)
      : format == "isg"        ? isg(in)
      : format == "heidenhain" ? heidenhain(in)
      : format == "fanuc"
          ? fanuc(in)
          : throw InputError(fmt::format("reading a '{}' table back is not supported (siemens, "
                                         "linuxcnc, isg, heidenhain, fanuc)",
                                         format));
  if (a.position_mm.size() < 2)
    throw InputError(fmt::format("{} table: fewer than 2 points", format));
  // The values as the vendor reads them: an error is taken off (the control adds -value).
  const bool error = format_meaning(format).written == Sign::error;
  const double sign = (error ? -1.0 : 1.0) * (inverted ? -1.0 : 1.0);
  for (auto* v : {&a.forward_um, &a.reverse_um})
    for (auto& x : *v) x *= sign;
  return a;
}

}  // namespace cal::comptable
