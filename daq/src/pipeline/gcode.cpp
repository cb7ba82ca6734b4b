// Part programs (see gcode.hpp; the syntax of each dialect and its sources: docs/circle.md).
#include "cal/daq/gcode.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/fixed_text.hpp"

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
// A word's number: 4 decimals (0.1 um, 0.0001 s), no "-0.0000" (cal::control_text).
std::string num(double v, std::string_view what = "value") {
  return control_text(checked(v, what), 4, what);
}
std::string signed_num(double v, std::string_view what) {  // Heidenhain: X+12.5000, R+50.0000
  const std::string s = num(v, what);
  return s.front() == '-' ? s : "+" + s;
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
  static_assert(one_per_value<Plane>(fanuc));
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
      add(fmt::format("CYCL DEF 9.1 DWELL {}", num(s, "dwell")));
    } else if (d == Dialect::fanuc) {
      if (fanuc_dwell == FanucDwell::p_ms)
        add(fmt::format("G04 P{}", std::lround(checked(s, "dwell") * 1000)));  // ms, no point
      else  // s; 3 decimals fit IS-B, IS-C
        add(fmt::format("G04 X{}", control_text(checked(s, "dwell"), 3, "dwell")));
    } else {
      add(fmt::format("G4 F{}", num(s, "dwell")));  // F: seconds in a G4 block
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
  const std::string what = fmt::format("{} word", axis);
  return d == Dialect::heidenhain ? fmt::format("{}{}", axis, signed_num(v, what))
                                  : fmt::format("{}{}", axis, num(v, what));
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
    const std::string what = fmt::format("{} word", letter);
    return d == Dialect::siemens ? fmt::format("{}={}", letter, num(v, what))
                                 : fmt::format("{}{}", letter, num(v, what));
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

namespace {

constexpr double deg = std::numbers::pi / 180.0;

// The plane's frame in 3D: the unit vectors of its first and second axis (x, y, z).
using V3 = std::array<double, 3>;
std::pair<V3, V3> axes_of(Plane p) {
  switch (p) {
    case Plane::zx:
      return {V3{0, 0, 1}, V3{1, 0, 0}};
    case Plane::yz:
      return {V3{0, 1, 0}, V3{0, 0, 1}};
    case Plane::xy:
    default:
      return {V3{1, 0, 0}, V3{0, 1, 0}};
  }
}
V3 direction(Plane p, double angle_deg) {
  const auto [eu, ev] = axes_of(p);
  const double c = std::cos(angle_deg * deg), n = std::sin(angle_deg * deg);
  return {c * eu[0] + n * ev[0], c * eu[1] + n * ev[1], c * eu[2] + n * ev[2]};
}
double angle_in(Plane p, const V3& dir) {
  const auto [eu, ev] = axes_of(p);
  const auto dot = [](const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  return std::atan2(dot(dir, ev), dot(dir, eu)) / deg;
}
// The angle of -Z in a vertical plane (the bottom of its circle, under the table ball), or
// none for XY.
std::optional<double> bottom_deg(Plane p) {
  if (p == Plane::zx) return 180.0;
  if (p == Plane::yz) return -90.0;
  return std::nullopt;
}
double wrap360(double a) { return std::fmod(std::fmod(a, 360.0) + 360.0, 360.0); }

// One arc of a transition: in `plane`, from one angle, by a signed sweep (+ ccw).
struct ArcMove {
  Plane plane;
  double from_deg, sweep_deg;
};

// The arc from a to b in a plane that does not pass under the ball (vertical planes), else the
// shorter way round.
ArcMove arc_between(Plane p, double a, double b) {
  const double ccw = wrap360(b - a), cw = ccw - 360.0;
  if (ccw < 1e-9) return {p, a, 0.0};
  if (const auto bottom = bottom_deg(p)) {
    const bool ccw_passes = wrap360(*bottom - a) > 1e-9 && wrap360(*bottom - a) < ccw - 1e-9;
    return {p, a, ccw_passes ? cw : ccw};
  }
  return {p, a, ccw <= 180.0 ? ccw : cw};
}

// From (p1, a1) to (p2, a2) on the sphere about the ball: one arc in a shared plane, or two
// through a pole on the axis the planes share (+X or -X for XY/ZX, +Y or -Y for XY/YZ, +Z for
// ZX/YZ: -Z is under the ball), the pair with the smaller total sweep.
std::vector<ArcMove> transition(Plane p1, double a1, Plane p2, double a2) {
  if (p1 == p2) return {arc_between(p1, a1, a2)};
  const V3 target = direction(p2, a2);
  const auto [u1, v1] = axes_of(p1);
  const auto [u2, v2] = axes_of(p2);
  // The target on p1's circle already (e.g. a pole): one arc.
  const double along = std::abs(target[0] * (u1[1] * v1[2] - u1[2] * v1[1]) +
                                target[1] * (u1[2] * v1[0] - u1[0] * v1[2]) +
                                target[2] * (u1[0] * v1[1] - u1[1] * v1[0]));
  if (along < 1e-12) return {arc_between(p1, a1, angle_in(p1, target))};
  V3 shared{};
  for (int k = 0; k < 3; ++k)
    shared[static_cast<std::size_t>(k)] =
        (u1[static_cast<std::size_t>(k)] + v1[static_cast<std::size_t>(k)]) *
                    (u2[static_cast<std::size_t>(k)] + v2[static_cast<std::size_t>(k)]) >
                0
            ? 1.0
            : 0.0;
  std::vector<ArcMove> best;
  double best_cost = 1e300;
  for (double sign : {1.0, -1.0}) {
    const V3 pole{sign * shared[0], sign * shared[1], sign * shared[2]};
    if (pole[2] < 0) continue;  // under the ball
    const ArcMove first = arc_between(p1, a1, angle_in(p1, pole));
    const ArcMove second = arc_between(p2, angle_in(p2, pole), a2);
    const double cost = std::abs(first.sweep_deg) + std::abs(second.sweep_deg);
    if (cost < best_cost) best_cost = cost, best = {first, second};
  }
  return best;
}

void comment_block(Writer& w, const std::string& text) {
  if (w.d == Dialect::fanuc)
    w.add("(" + text + ")");
  else
    w.add("; " + text);
}

void stop_block(Writer& w) {
  w.add(w.d == Dialect::fanuc ? "M00" : w.d == Dialect::siemens ? "M0" : "STOP");
}

class CircleWriter {
 public:
  CircleWriter(Writer& w, const CircleProgramSetup& s) : w_(w), s_(s) {}

  // A point at an angle of a plane at a distance from the table ball, as the plane's two words.
  std::string words(Plane p, double angle_deg, double r) const {
    const PlaneFrame f = frame_of(p);
    const double a = angle_deg * deg;
    return pair_words(w_.d, f.u, f.cu + r * std::cos(a), f.v, f.cv + r * std::sin(a));
  }

  void plane(Plane p) {
    if (w_.d != Dialect::heidenhain && p != w_.plane) w_.add(plane_word(w_.d, p));
    w_.plane = p;
  }

  // Arcs of radius r in plane p from an angle by a signed sweep, in pieces of at most 180 deg
  // (by centre) or 90 deg (by radius). Returns the end angle.
  double arcs(Plane p, double from_deg, double sweep_deg, double r, double feed) {
    if (std::abs(sweep_deg) < 1e-9) return from_deg;
    plane(p);
    const PlaneFrame f = frame_of(p);
    const bool by_centre = s_.arcs == ArcForm::centre, ccw = sweep_deg > 0;
    if (w_.d == Dialect::heidenhain && by_centre && (!cc_ || *cc_ != p)) {
      w_.add(fmt::format("CC {}", pair_words(w_.d, f.u, f.cu, f.v, f.cv)));
      cc_ = p;
    }
    const double max_piece_deg = by_centre ? 180.0 : 90.0;
    const int pieces = static_cast<int>(std::ceil(std::abs(sweep_deg) / max_piece_deg - 1e-9));
    const std::string fw = w_.feed(feed);
    double at = from_deg;
    for (int k = 0; k < pieces; ++k) {
      const double next = at + sweep_deg / pieces;
      const double a = at * deg;
      const double fu = f.cu + r * std::cos(a), fv = f.cv + r * std::sin(a);
      const std::string end = words(p, next, r);
      const std::string g = w_.d == Dialect::fanuc ? (ccw ? "G03" : "G02") : (ccw ? "G3" : "G2");
      const std::string dr = ccw ? "DR+" : "DR-";
      // Every piece is at most 180 degrees: the radius is written positive in all dialects.
      if (w_.d == Dialect::heidenhain)
        w_.add(by_centre ? fmt::format("C {} {} {}", end, dr, fw)
                         : fmt::format("CR {} R{} {} {}", end, signed_num(r, "radius"), dr, fw));
      else if (!by_centre)
        w_.add(fmt::format("{} {} {}{} {}", g, end,
                           w_.d == Dialect::fanuc ? "R" : "CR=", num(r, "radius"), fw));
      else
        w_.add(fmt::format("{} {} {} {}", g, end,
                           centre_words(w_.d, f.u, f.cu - fu, f.v, f.cv - fv), fw));
      at = next;
    }
    return at;
  }

  void comment(const std::string& text) { comment_block(w_, text); }

  void stop() { stop_block(w_); }

 private:
  PlaneFrame frame_of(Plane p) const {
    CircleProgramSetup s = s_;
    s.plane = p;
    return frame(s);
  }
  Writer& w_;
  const CircleProgramSetup& s_;
  std::optional<Plane> cc_;
};

std::string upper(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::vector<SetArc> ballbar_transition(Plane p1, double a1_deg, Plane p2, double a2_deg) {
  std::vector<SetArc> out;
  for (const auto& m : transition(p1, a1_deg, p2, a2_deg))
    out.push_back({m.plane, m.from_deg, m.sweep_deg});
  return out;
}

std::string plane_name(Plane p) { return p == Plane::zx ? "ZX" : p == Plane::yz ? "YZ" : "XY"; }

std::vector<BallbarSetTest> ballbar_set(const BallbarSetConfig& c) {
  if (c.planes.empty() || c.feeds_mm_per_min.empty() || c.radii_mm.empty())
    throw InputError("ballbar set: give at least one plane, one feed and one radius");
  if (!(c.partial_arc_deg >= 180.0 && c.partial_arc_deg <= 360.0))
    throw InputError(
        fmt::format("ballbar set: partial arc {} degrees must be 180..360", c.partial_arc_deg));
  std::vector<BallbarSetTest> out;
  for (double r : c.radii_mm)
    for (Plane p : c.planes)
      for (double f : c.feeds_mm_per_min) {
        BallbarProgram b{.radius_mm = r,
                         .feed_mm_per_min = f,
                         .sample_rate_hz = c.sample_rate_hz,
                         .feed_in_mm = c.feed_in_mm,
                         .dwell_s = c.dwell_s};
        if (p == Plane::xy || c.partial_arc_deg >= 360.0) {
          b.overshoot_deg = c.overshoot_deg;
          b.start_deg = 0.0;
          b.arc_deg = 360.0;
        } else {
          // Symmetric about +Z, which is at 0 deg in ZX (Z first) and 90 deg in YZ.
          const double top = p == Plane::zx ? 0.0 : 90.0;
          b.overshoot_deg = c.partial_overshoot_deg;
          b.arc_deg = c.partial_arc_deg;
          b.start_deg = top - c.partial_arc_deg / 2 - c.partial_overshoot_deg;
        }
        BallbarSegmenter check(b);  // the same validation as a single test
        out.push_back({p, b});
      }
  return out;
}

std::string circle_set_program(std::span<const BallbarSetTest> tests, const CircleProgramSetup& s,
                               Dialect d) {
  if (tests.empty()) throw InputError("program: the ballbar set has no test");
  check_name(s.name);
  for (const auto& t : tests) {
    const auto& b = t.program;
    BallbarSegmenter check(b);  // validates the numbers
    check_feed_dwell(b.feed_mm_per_min, std::max(b.dwell_s, 1e-3));
    checked(b.radius_mm + b.feed_in_mm, "radius");
    if (!(b.overshoot_deg <= 180))
      throw InputError(fmt::format("program: overshoot {} deg is over 180", b.overshoot_deg));
  }
  const bool set = tests.size() > 1;
  Writer w{d, s.fanuc_dwell, tests.front().plane, {}, 0};
  const auto& b0 = tests.front().program;
  w.begin(
      s.name,
      set ? fmt::format("ballbar set of {} tests (docs/circle.md, the standard set)", tests.size())
          : fmt::format("ballbar circle R {} mm at F{}, overshoot {} deg", num(b0.radius_mm),
                        std::lround(b0.feed_mm_per_min), num(b0.overshoot_deg)));
  CircleWriter c(w, s);
  // Where the tool is: plane, angle and distance from the ball (after the first move).
  Plane at_plane = tests.front().plane;
  double at_deg = b0.start_deg, at_r = 0.0;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const auto& [p, b] = tests[i];
    const double out_r = b.radius_mm + b.feed_in_mm;
    if (set)
      c.comment(upper(fmt::format("test {} of {}: {} {:g} deg R{} F{}", i + 1, tests.size(),
                                  plane_name(p), b.arc_deg, num(b.radius_mm),
                                  std::lround(b.feed_mm_per_min))));
    if (i == 0) {
      w.line_to(c.words(p, b.start_deg, out_r), b.feed_mm_per_min);
    } else {
      if (std::abs(out_r - at_r) > 1e-9) {  // another bar: off, out along the radius, on
        c.comment(
            upper(fmt::format("remove the R{} bar", num(at_r - tests[i - 1].program.feed_in_mm))));
        c.stop();
        c.plane(at_plane);
        w.line_to(c.words(at_plane, at_deg, out_r), b.feed_mm_per_min);
        c.comment(upper(fmt::format("fit the R{} bar", num(b.radius_mm))));
        c.stop();
      }
      // On the sphere of the feed-in distance about the ball: the bar stays on.
      for (const auto& m : transition(at_plane, at_deg, p, b.start_deg))
        c.arcs(m.plane, m.from_deg, m.sweep_deg, out_r, b.feed_mm_per_min);
    }
    c.plane(p);
    w.line_to(c.words(p, b.start_deg, b.radius_mm), b.feed_mm_per_min);  // feed-in
    w.dwell(b.dwell_s);
    const double sweep = b.arc_deg + 2 * b.overshoot_deg;
    const double end_ccw = c.arcs(p, b.start_deg, sweep, b.radius_mm, b.feed_mm_per_min);
    w.dwell(b.dwell_s);
    c.arcs(p, end_ccw, -sweep, b.radius_mm, b.feed_mm_per_min);
    w.line_to(c.words(p, b.start_deg, out_r), b.feed_mm_per_min);  // feed-out
    at_plane = p, at_deg = b.start_deg, at_r = out_r;
  }
  w.end(s.name);
  return w.text();
}

std::string circle_program(const BallbarProgram& b, const CircleProgramSetup& s, Dialect d) {
  const BallbarSetTest one{s.plane, b};
  return circle_set_program(std::span(&one, 1), s, d);
}

std::string rotary_ballbar_program(std::span<const RotaryProgramPoint> points,
                                   const RotaryProgramSetup& s, Dialect d) {
  if (points.empty()) throw InputError("program: the rotary ballbar test has no point");
  check_name(s.name);
  check_feed_dwell(s.feed_mm_per_min, s.dwell_s);
  if (s.rotary != 'A' && s.rotary != 'B' && s.rotary != 'C')
    throw InputError(fmt::format("program: rotary axis '{}' (expected A, B or C)", s.rotary));
  const bool plain = std::all_of(s.what.begin(), s.what.end(), [](unsigned char c) {
    return std::isalnum(c) ||
           std::string_view(" -.,:=+/").find(static_cast<char>(c)) != std::string_view::npos;
  });
  if (!plain || s.what.size() > 120)
    throw InputError(
        "program: the title may hold letters, digits, spaces and - . , : = + / only, at most "
        "120 characters");
  Writer w{d, s.fanuc_dwell, Plane::xy, {}, 0};
  w.begin(s.name, upper(s.what));
  comment_block(
      w, "X Y Z: THE SPINDLE BALL CENTRE; " + std::string(1, s.rotary) + ": THE TABLE ANGLE");
  const auto words = [&](const RotaryProgramPoint& p) {
    return axis_word(d, 'X', p.x_mm) + " " + axis_word(d, 'Y', p.y_mm) + " " +
           axis_word(d, 'Z', p.z_mm) + " " + axis_word(d, s.rotary, p.angle_deg);
  };
  w.line_to(words(points.front()), s.feed_mm_per_min);
  comment_block(w, "FIT THE BAR");
  stop_block(w);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (i > 0) w.line_to(words(points[i]), s.feed_mm_per_min);
    if (points[i].measure) w.dwell(s.dwell_s);
  }
  comment_block(w, "REMOVE THE BAR");
  stop_block(w);
  w.end(s.name);
  return w.text();
}

}  // namespace cal::daq
