// Part programs (see gcode.hpp; the syntax of each dialect and its sources: docs/acquisition.md).
#include "cal/daq/gcode.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "cal/analysis/error.hpp"

namespace cal::daq {
namespace {

// The last guard before a number reaches the controller: whatever the caller checked, a
// non-finite or absurd value (beyond +-1 km, where 4 decimals no longer fit the 8 + 4 digits
// of the controls' words) is refused, never written as "nan", "inf" or 1e+09.
constexpr double kMaxWordValue = 1e6;
double checked(double v, std::string_view what) {
  if (!std::isfinite(v) || std::abs(v) > kMaxWordValue)
    throw InputError(
        fmt::format("program: {} {} is not a finite value within +-{}", what, v, kMaxWordValue));
  return v;
}
std::string num(double v) {  // 4 decimals, no "-0.0000"
  checked(v, "value");
  if (std::abs(v) < 5e-5) v = 0.0;
  return fmt::format("{:.4f}", v);
}
std::string signed_num(double v) {  // Heidenhain writes the sign: X+12.5000
  checked(v, "value");
  if (std::abs(v) < 5e-5) v = 0.0;
  return fmt::format("{:+.4f}", v);
}

// A program name every dialect takes: letters, digits and '_', a letter first, at most 24
// (Heidenhain's BEGIN PGM allows letters, digits and '_'; Fanuc and SINUMERIK only show it in
// a comment, where a ')' or a line break would end the comment or the block).
void check_name(const std::string& name) {
  const bool ok = !name.empty() && name.size() <= 24 &&
                  std::isalpha(static_cast<unsigned char>(name[0])) &&
                  std::all_of(name.begin(), name.end(),
                              [](unsigned char c) { return std::isalnum(c) || c == '_'; });
  if (!ok)
    throw InputError(fmt::format(
        "program name '{}': letters, digits and '_' only, a letter first, at most 24", name));
}

const char* plane_word(Dialect d, Plane p) {
  static constexpr std::array<const char*, 3> fanuc{"G17", "G18", "G19"};
  (void)d;  // the same words in ISO/Fanuc and SINUMERIK
  return fanuc[static_cast<std::size_t>(p)];
}

struct Writer {
  Dialect d;
  FanucDwell fanuc_dwell = FanucDwell::p_ms;
  Plane plane = Plane::xy;
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
      lines.push_back("%");  // tape start; not a block
      add(fmt::format("O1000 ({})", what));
      add(fmt::format("G21 G90 {} G94", plane_word(d, plane)));  // mm, absolute, plane, mm/min
    } else {
      add(fmt::format("; {}", what));
      add(fmt::format("G71 G90 {} G94", plane_word(d, plane)));  // G71: metric on SINUMERIK
    }
  }
  std::string feed(double f) const { return fmt::format("F{}", std::lround(checked(f, "feed"))); }
  void line_to(std::string_view axes, double f) {
    if (d == Dialect::heidenhain)
      add(fmt::format("L {} {}", axes, feed(f)));
    else if (d == Dialect::fanuc)
      add(fmt::format("G01 {} {}", axes, feed(f)));
    else
      add(fmt::format("G1 {} {}", axes, feed(f)));
  }
  void dwell(double s) {
    if (d == Dialect::heidenhain) {
      add("CYCL DEF 9.0 DWELL TIME");
      add(fmt::format("CYCL DEF 9.1 DWELL {}", num(s)));
    } else if (d == Dialect::fanuc) {
      if (fanuc_dwell == FanucDwell::p_ms)
        add(fmt::format("G04 P{}", std::lround(checked(s, "dwell") * 1000)));  // ms, no point
      else
        add(fmt::format("G04 X{:.3f}", checked(s, "dwell")));  // s; 3 decimals fit IS-B, IS-C
    } else {
      add(fmt::format("G4 F{}", num(s)));  // F: seconds in a G4 block
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

// The circle's plane: its axes (u, v) with u x v along the positive third axis, and the centre.
struct PlaneFrame {
  char u, v;
  double cu, cv;
};

PlaneFrame frame(const CircleProgramSetup& s) {
  switch (s.plane) {
    case Plane::zx:
      return {'Z', 'X', s.centre_z_mm, s.centre_x_mm};
    case Plane::yz:
      return {'Y', 'Z', s.centre_y_mm, s.centre_z_mm};
    case Plane::xy:
    default:
      return {'X', 'Y', s.centre_x_mm, s.centre_y_mm};
  }
}

// Two axis words in alphabetical order (X before Y before Z), as programs are usually written.
std::string pair_words(Dialect d, char a, double va, char b, double vb) {
  if (a > b) std::swap(a, b), std::swap(va, vb);
  return axis_word(d, a, va) + " " + axis_word(d, b, vb);
}

// The incremental centre words of ISO / SINUMERIK: I for X, J for Y, K for Z.
std::string centre_words(Dialect d, char a, double va, char b, double vb) {
  if (a > b) std::swap(a, b), std::swap(va, vb);
  const auto word = [&](char axis, double v) {
    const char letter = static_cast<char>('I' + (axis - 'X'));
    return d == Dialect::siemens ? fmt::format("{}={}", letter, num(v))
                                 : fmt::format("{}{}", letter, num(v));
  };
  return word(a, va) + " " + word(b, vb);
}

void check_feed_dwell(double feed_mm_per_min, double dwell_s) {
  if (!(feed_mm_per_min > 0) || !(feed_mm_per_min <= 1e6) || !(dwell_s > 0) || !(dwell_s <= 3600))
    throw InputError(fmt::format(
        "program: feed {} mm/min and dwell {} s must be > 0 and at most 1e6 mm/min and 3600 s",
        feed_mm_per_min, dwell_s));
}

}  // namespace

Dialect dialect_from_string(std::string_view s) {
  if (s == "fanuc" || s == "iso") return Dialect::fanuc;
  if (s == "heidenhain") return Dialect::heidenhain;
  if (s == "siemens" || s == "sinumerik") return Dialect::siemens;
  throw InputError(fmt::format(
      "G-code dialect '{}' (expected fanuc, iso, heidenhain, siemens or sinumerik)", s));
}

Plane plane_from_string(std::string_view s) {
  std::string u(s);
  std::transform(u.begin(), u.end(), u.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (u == "XY" || u == "G17") return Plane::xy;
  if (u == "ZX" || u == "XZ" || u == "G18") return Plane::zx;
  if (u == "YZ" || u == "ZY" || u == "G19") return Plane::yz;
  throw InputError(fmt::format("circle plane '{}' (expected XY, ZX or YZ; or G17, G18, G19)", s));
}

std::string linear_program(const iso230_2::Plan& plan, const LinearProgram& p, Dialect d) {
  check_feed_dwell(p.feed_mm_per_min, p.dwell_s);
  if (p.axis != 'X' && p.axis != 'Y' && p.axis != 'Z')
    throw InputError(fmt::format("program: axis '{}' (expected X, Y or Z)", p.axis));
  if (p.trigger_dwell_s > 0 && !(p.dwell_s > p.trigger_dwell_s + p.settle_s))
    throw InputError(fmt::format(
        "program: dwell {} s is too short for the trigger's dwell {} s plus {} s of settling "
        "(the machine would leave before the stop is recognised); program at least {} s",
        p.dwell_s, p.trigger_dwell_s, p.settle_s, p.trigger_dwell_s + p.settle_s));
  if (plan.moves.empty()) throw InputError("program: the plan has no moves");
  check_name(p.name);
  Writer w{d, p.fanuc_dwell, Plane::xy, {}, 0};
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
  check_name(s.name);
  check_feed_dwell(b.feed_mm_per_min, std::max(b.dwell_s, 1e-3));
  checked(b.radius_mm + b.feed_in_mm, "radius");
  if (!(b.overshoot_deg <= 180))
    throw InputError(fmt::format("program: overshoot {} deg is over 180", b.overshoot_deg));
  const PlaneFrame f = frame(s);
  Writer w{d, s.fanuc_dwell, s.plane, {}, 0};
  w.begin(s.name, fmt::format("ballbar circle R {} mm at F{}, overshoot {} deg", num(b.radius_mm),
                              std::lround(b.feed_mm_per_min), num(b.overshoot_deg)));
  // A point of the circle (or of the feed-in line) at an angle from the plane's first axis.
  auto point = [&](double angle_deg, double r) {
    const double a = angle_deg * std::numbers::pi / 180.0;
    return std::pair{f.cu + r * std::cos(a), f.cv + r * std::sin(a)};
  };
  auto words = [&](std::pair<double, double> p) {
    return pair_words(d, f.u, p.first, f.v, p.second);
  };
  const auto outside = point(b.start_deg, b.radius_mm + b.feed_in_mm);
  w.line_to(words(outside), b.feed_mm_per_min);
  w.line_to(words(point(b.start_deg, b.radius_mm)), b.feed_mm_per_min);  // feed-in
  w.dwell(b.dwell_s);
  const bool by_centre = s.arcs == ArcForm::centre;
  if (d == Dialect::heidenhain && by_centre)
    w.add(fmt::format("CC {}", pair_words(d, f.u, f.cu, f.v, f.cv)));
  const double sweep = 360.0 + 2 * b.overshoot_deg;
  const double max_piece_deg = by_centre ? 180.0 : 90.0;
  const std::string feed = w.feed(b.feed_mm_per_min);
  auto arcs = [&](bool ccw, double from_deg) {
    const int pieces = static_cast<int>(std::ceil(sweep / max_piece_deg - 1e-9));
    double at = from_deg;
    for (int k = 0; k < pieces; ++k) {
      const double next = at + (ccw ? 1 : -1) * sweep / pieces;
      const auto [fu, fv] = point(at, b.radius_mm);
      const std::string end = words(point(next, b.radius_mm));
      const std::string g = d == Dialect::fanuc ? (ccw ? "G03" : "G02") : (ccw ? "G3" : "G2");
      const std::string dr = ccw ? "DR+" : "DR-";
      // Every piece is at most 180 degrees: the radius is written positive in all dialects.
      if (d == Dialect::heidenhain)
        w.add(by_centre ? fmt::format("C {} {} {}", end, dr, feed)
                        : fmt::format("CR {} R{} {} {}", end, signed_num(b.radius_mm), dr, feed));
      else if (!by_centre)
        w.add(fmt::format("{} {} {}{} {}", g, end,
                          d == Dialect::fanuc ? "R" : "CR=", num(b.radius_mm), feed));
      else
        w.add(fmt::format("{} {} {} {}", g, end, centre_words(d, f.u, f.cu - fu, f.v, f.cv - fv),
                          feed));
      at = next;
    }
    return at;
  };
  const double end_ccw = arcs(true, b.start_deg);
  w.dwell(b.dwell_s);
  arcs(false, end_ccw);
  w.line_to(words(outside), b.feed_mm_per_min);  // feed-out
  w.end(s.name);
  return w.text();
}

}  // namespace cal::daq
