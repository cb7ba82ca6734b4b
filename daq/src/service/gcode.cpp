// Part programs (see gcode.hpp).
#include "cal/daq/gcode.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "cal/analysis/error.hpp"

namespace cal::daq {
namespace {

std::string num(double v) {  // 4 decimals, no "-0.0000"
  if (std::abs(v) < 5e-5) v = 0.0;
  return fmt::format("{:.4f}", v);
}
std::string signed_num(double v) {  // Heidenhain writes the sign: X+12.5000
  if (std::abs(v) < 5e-5) v = 0.0;
  return fmt::format("{:+.4f}", v);
}

struct Writer {
  Dialect d;
  std::vector<std::string> lines;
  int block = 0;

  void add(std::string text) {
    if (d == Dialect::heidenhain)
      lines.push_back(fmt::format("{} {}", block++, text));
    else
      lines.push_back(std::move(text));
  }
  void begin(const std::string& name, const std::string& what) {
    if (d == Dialect::heidenhain) {
      add(fmt::format("BEGIN PGM {} MM", name));
      add(fmt::format("; {}", what));
    } else if (d == Dialect::fanuc) {
      lines.push_back("%");
      add(fmt::format("O1000 ({})", what));
      add("G21 G90 G17 G94");
    } else {
      add(fmt::format("; {}", what));
      add("G71 G90 G17 G94");
    }
  }
  void line_to(std::string_view axes, double feed) {
    if (d == Dialect::heidenhain)
      add(fmt::format("L {} F{}", axes, std::lround(feed)));
    else if (d == Dialect::fanuc)
      add(fmt::format("G01 {} F{}", axes, std::lround(feed)));
    else
      add(fmt::format("G1 {} F{}", axes, std::lround(feed)));
  }
  void dwell(double s) {
    if (d == Dialect::heidenhain) {
      add("CYCL DEF 9.0 DWELL TIME");
      add(fmt::format("CYCL DEF 9.1 DWELL {}", num(s)));
    } else if (d == Dialect::fanuc) {
      add(fmt::format("G04 P{}", std::lround(s * 1000)));  // P in ms
    } else {
      add(fmt::format("G4 F{}", num(s)));  // F in seconds
    }
  }
  void end(const std::string& name) {
    if (d == Dialect::heidenhain)
      add(fmt::format("END PGM {} MM", name));
    else
      add("M30");
    if (d == Dialect::fanuc) lines.push_back("%");
  }
  std::string text() const {
    std::string out;
    for (const auto& l : lines) out += l + "\n";
    return out;
  }
};

std::string axis_word(Dialect d, char axis, double v) {
  return d == Dialect::heidenhain ? fmt::format("{}{}", axis, signed_num(v))
                                  : fmt::format("{}{}", axis, num(v));
}

}  // namespace

Dialect dialect_from_string(std::string_view s) {
  if (s == "fanuc" || s == "iso") return Dialect::fanuc;
  if (s == "heidenhain") return Dialect::heidenhain;
  if (s == "siemens" || s == "sinumerik") return Dialect::siemens;
  throw InputError(fmt::format("G-code dialect '{}' (expected fanuc, heidenhain or siemens)", s));
}

std::string linear_program(const iso230_2::Plan& plan, const LinearProgram& p, Dialect d) {
  if (!(p.feed_mm_per_min > 0) || !(p.dwell_s > 0))
    throw InputError(fmt::format("program: feed {} mm/min and dwell {} s must be > 0",
                                 p.feed_mm_per_min, p.dwell_s));
  Writer w{d, {}, 0};
  w.begin(p.name, fmt::format("ISO 230-2 test of {}: {} targets, {} moves", p.axis,
                              plan.targets_mm.size(), plan.moves.size()));
  for (const auto& m : plan.moves) {
    w.line_to(axis_word(d, p.axis, m.position_mm), p.feed_mm_per_min);
    if (m.kind == iso230_2::MoveKind::measure) w.dwell(p.dwell_s);
  }
  w.end(p.name);
  return w.text();
}

std::string circle_program(const BallbarProgram& b, const CircleProgramSetup& s, Dialect d) {
  BallbarSegmenter check(b);  // the same validation of the program's numbers
  Writer w{d, {}, 0};
  w.begin(s.name, fmt::format("ballbar circle R {} mm at F{}, overshoot {} deg", num(b.radius_mm),
                              std::lround(b.feed_mm_per_min), num(b.overshoot_deg)));
  const double t0 = b.start_deg * std::numbers::pi / 180.0;
  auto point = [&](double angle_deg, double r) {
    const double a = angle_deg * std::numbers::pi / 180.0;
    return std::pair{s.centre_x_mm + r * std::cos(a), s.centre_y_mm + r * std::sin(a)};
  };
  const auto [ox, oy] = point(b.start_deg, b.radius_mm + b.feed_in_mm);
  const auto [sx, sy] = point(b.start_deg, b.radius_mm);
  (void)t0;
  w.line_to(axis_word(d, 'X', ox) + " " + axis_word(d, 'Y', oy), b.feed_mm_per_min);
  w.line_to(axis_word(d, 'X', sx) + " " + axis_word(d, 'Y', sy), b.feed_mm_per_min);
  w.dwell(b.dwell_s);
  if (d == Dialect::heidenhain)
    w.add(fmt::format("CC X{} Y{}", signed_num(s.centre_x_mm), signed_num(s.centre_y_mm)));
  const double sweep = 360.0 + 2 * b.overshoot_deg;
  auto arcs = [&](bool ccw, double from_deg) {
    const int pieces = static_cast<int>(std::ceil(sweep / 180.0));
    double at = from_deg;
    for (int k = 0; k < pieces; ++k) {
      const double next = at + (ccw ? 1 : -1) * sweep / pieces;
      const auto [fx, fy] = point(at, b.radius_mm);
      const auto [ex, ey] = point(next, b.radius_mm);
      if (d == Dialect::heidenhain)
        w.add(fmt::format("C X{} Y{} {} F{}", signed_num(ex), signed_num(ey), ccw ? "DR+" : "DR-",
                          std::lround(b.feed_mm_per_min)));
      else if (d == Dialect::fanuc)
        w.add(fmt::format("{} X{} Y{} I{} J{} F{}", ccw ? "G03" : "G02", num(ex), num(ey),
                          num(s.centre_x_mm - fx), num(s.centre_y_mm - fy),
                          std::lround(b.feed_mm_per_min)));
      else
        w.add(fmt::format("{} X{} Y{} I={} J={} F{}", ccw ? "G3" : "G2", num(ex), num(ey),
                          num(s.centre_x_mm - fx), num(s.centre_y_mm - fy),
                          std::lround(b.feed_mm_per_min)));
      at = next;
    }
    return at;
  };
  const double end_ccw = arcs(true, b.start_deg);
  w.dwell(b.dwell_s);
  arcs(false, end_ccw);
  w.line_to(axis_word(d, 'X', ox) + " " + axis_word(d, 'Y', oy), b.feed_mm_per_min);
  w.end(s.name);
  return w.text();
}

}  // namespace cal::daq
