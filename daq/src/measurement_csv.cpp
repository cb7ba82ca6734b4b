#include "measurement_csv.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "cal/analysis/error.hpp"

namespace daq {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> f;
  std::size_t start = 0;
  for (;;) {
    const auto comma = line.find(',', start);
    f.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) return f;
    start = comma + 1;
  }
}

struct Where {
  const std::string& file;
  std::size_t line;
};

[[noreturn]] void fail(const Where& w, const std::string& what) {
  throw cal::InputError(fmt::format("{}:{}: {}", w.file, w.line, what));
}

double to_double(std::string_view s, const Where& w, std::string_view column) {
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || !std::isfinite(v)) {
    fail(w, fmt::format("column {}: '{}' is not a finite number", column, s));
  }
  return v;
}

int to_int(std::string_view s, const Where& w) {
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || v < 1) {
    fail(w, fmt::format("column run: '{}' is not a run number >= 1", s));
  }
  return v;
}

cal::iso230_2::Direction to_direction(std::string_view s, const Where& w) {
  if (s == "up" || s == "+" || s == "forward" || s == "fwd") return cal::iso230_2::Direction::up;
  if (s == "down" || s == "-" || s == "backward" || s == "bwd" || s == "reverse")
    return cal::iso230_2::Direction::down;
  fail(w, fmt::format("column direction: '{}' is not up or down", s));
}

}  // namespace

std::vector<cal::iso230_2::Measurement> parse_measurements(std::string_view text,
                                                           const std::string& name) {
  constexpr std::array<std::string_view, 4> kColumns{"target_mm", "run", "direction",
                                                     "deviation_um"};
  std::array<std::size_t, 4> col{};
  bool have_header = false;
  std::vector<cal::iso230_2::Measurement> out;
  std::istringstream in{std::string(text)};
  std::string raw;
  for (std::size_t line_no = 1; std::getline(in, raw); ++line_no) {
    const Where w{name, line_no};
    const auto line = trim(raw);
    if (line.empty() || line.front() == '#') continue;
    const auto f = split(line);
    if (!have_header) {
      for (std::size_t c = 0; c < kColumns.size(); ++c) {
        const auto it = std::find(f.begin(), f.end(), kColumns[c]);
        if (it == f.end()) {
          fail(w, fmt::format("header lacks column '{}' (expected target_mm,run,direction,"
                              "deviation_um)",
                              kColumns[c]));
        }
        col[c] = static_cast<std::size_t>(it - f.begin());
      }
      have_header = true;
      continue;
    }
    for (std::size_t c = 0; c < kColumns.size(); ++c) {
      if (col[c] >= f.size()) fail(w, fmt::format("missing column {}", kColumns[c]));
    }
    out.push_back({to_double(f[col[0]], w, "target_mm"), to_int(f[col[1]], w),
                   to_direction(f[col[2]], w), to_double(f[col[3]], w, "deviation_um")});
  }
  if (!have_header) throw cal::InputError(fmt::format("{}: empty file, no header", name));
  if (out.empty()) throw cal::InputError(fmt::format("{}: header but no measurements", name));
  return out;
}

std::vector<cal::iso230_2::Measurement> read_measurements(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw cal::InputError(fmt::format("{}: cannot open for reading", path));
  std::ostringstream ss;
  ss << f.rdbuf();
  return parse_measurements(ss.str(), path);
}

}  // namespace daq
