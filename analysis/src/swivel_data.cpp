// SINUMERIK CYCLE800 swivel data (kinematics type P) from the fitted axis lines
// (swivel_data.hpp); the semantics and their sources in docs/kinematics.md.
#include "cal/analysis/swivel_data.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "cal/analysis/error.hpp"
#include "cal/analysis/fixed_text.hpp"
#include "cal/analysis/text.hpp"

namespace cal::kinematics {

namespace {

using Eigen::Vector3d;

constexpr double kMmPerUm = 1e-3;
constexpr double kRadPerUrad = 1e-6;
// How far a record's V may be from its axis's nominal direction (rad): a fitted tilt is
// micro-radians; more is another machine's record or a wrong axis.
constexpr double kMaxTiltRad = 0.01;

Vector3d vec(const Vec3& v) { return {v[0], v[1], v[2]}; }
Vec3 arr(const Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// R(e) = Rz(e_c) Ry(e_b) Rx(e_a), as the model builds an axis's direction (rotary.hpp).
Eigen::Matrix3d rotation(const Vector3d& eps) {
  return (Eigen::AngleAxisd(eps.z(), Vector3d::UnitZ()) *
          Eigen::AngleAxisd(eps.y(), Vector3d::UnitY()) *
          Eigen::AngleAxisd(eps.x(), Vector3d::UnitX()))
      .toRotationMatrix();
}

Vector3d nominal_direction(RotaryLetter l) { return Vector3d::Unit(direction_index(l)); }

void require_finite(const Vec3& v, std::string_view what) {
  for (std::size_t k = 0; k < 3; ++k)
    if (!std::isfinite(v[k]))
      throw InputError(fmt::format("{}[{}] is {}: nothing non-finite goes into a controller table",
                                   what, k, v[k]));
}

// The actual line's point at the nominal pivot's plane, and its direction R(orientation) d.
Vec3 line_point_mm(const RotaryAxis& r) {
  require_finite(r.pivot_mm, fmt::format("rotary {} pivot_mm", to_string(r.letter)));
  require_finite(r.location_position_um,
                 fmt::format("rotary {} location position", to_string(r.letter)));
  return arr(vec(r.pivot_mm) + kMmPerUm * vec(r.location_position_um));
}

Vec3 line_direction(const RotaryAxis& r) {
  require_finite(r.location_orientation_urad,
                 fmt::format("rotary {} location orientation", to_string(r.letter)));
  return arr(rotation(kRadPerUrad * vec(r.location_orientation_urad)) *
             nominal_direction(r.letter));
}

// The table axes in Siemens' order: 1st (carries the 2nd), then 2nd (carries the workpiece).
std::vector<const RotaryAxis*> swivel_axes(const FiveAxisMachine& m) {
  const auto& r = m.rotary;
  const bool table_only =
      std::all_of(r.begin(), r.end(), [](const RotaryAxis& a) { return a.side == Side::table; });
  if (r.empty() || !table_only || (r.size() == 2 && r[0].letter == r[1].letter))
    throw InputError(
        "a SINUMERIK swivel table (kinematics type P) turns the workpiece only: the model's "
        "rotary axes must be one or two table axes of different letters (e.g. [C table, A "
        "table])");
  if (r.size() == 1) return {&r[0]};
  return {&r[1], &r[0]};  // chain order is from the workpiece: r[1] carries r[0]
}

// The orientation errors (urad, in the model's R(e) d layout) whose direction is u, a unit
// vector near d: the inverse of R(e) d with the error about d itself 0.
Vec3 orientation_of(RotaryLetter l, const Vector3d& u) {
  Vec3 e{};
  switch (l) {
    case RotaryLetter::c:  // R d = (cos a sin b, -sin a, cos a cos b)
      e = {-std::asin(u.y()), std::atan2(u.x(), u.z()), 0.0};
      break;
    case RotaryLetter::a:  // R d = (cos c cos b, sin c cos b, -sin b)
      e = {0.0, -std::asin(u.z()), std::atan2(u.y(), u.x())};
      break;
    case RotaryLetter::b:  // R d = (-sin c cos a, cos c cos a, sin a)
      e = {std::asin(u.z()), 0.0, std::atan2(-u.x(), u.y())};
      break;
  }
  return {e[0] / kRadPerUrad, e[1] / kRadPerUrad, e[2] / kRadPerUrad};
}

// The variable numbers written: k of $TC_CARRk, its slot in the record, its decimals.
struct Slot {
  int k;
  Vec3 SwivelRecord::*vector;  // nullptr: not a vector
  std::size_t component;
  int decimals;
};

std::vector<Slot> vector_slots() {
  std::vector<Slot> s;
  const auto add = [&](int first, Vec3 SwivelRecord::*v, int decimals) {
    for (std::size_t c = 0; c < 3; ++c) s.push_back({first + static_cast<int>(c), v, c, decimals});
  };
  add(1, &SwivelRecord::i1_mm, 6);
  add(4, &SwivelRecord::i2_mm, 6);
  add(7, &SwivelRecord::v1, 9);
  add(10, &SwivelRecord::v2, 9);
  add(15, &SwivelRecord::i3_mm, 6);
  add(18, &SwivelRecord::i4_mm, 6);
  return s;
}

// The fine offsets of I1..I4: the basic number + 40 (W1: "The fine offset value assigned to a
// basic parameter is obtained when the value 40 is added to the parameter number").
constexpr int kFineOffsets[] = {41, 42, 43, 44, 45, 46, 55, 56, 57, 58, 59, 60};

}  // namespace

SwivelRecord sinumerik_swivel_record(const FiveAxisMachine& m, const SwivelOptions& o) {
  if (o.number < 1 || o.number > 9999)
    throw InputError(fmt::format("swivel data record {}: expected 1 .. 9999", o.number));
  const auto axes = swivel_axes(m);
  SwivelRecord rec;
  rec.number = o.number;
  const double sense = o.reverse_angles ? -1.0 : 1.0;
  const Vec3 p1 = line_point_mm(*axes[0]);
  rec.axis1 = std::string(to_string(axes[0]->letter));
  rec.i2_mm = p1;
  rec.v1 = arr(sense * vec(line_direction(*axes[0])));
  if (axes.size() == 2) {
    const Vec3 p2 = line_point_mm(*axes[1]);
    rec.axis2 = std::string(to_string(axes[1]->letter));
    rec.i3_mm = arr(vec(p2) - vec(p1));
    rec.v2 = arr(sense * vec(line_direction(*axes[1])));
  }
  rec.i4_mm = arr(-(vec(rec.i2_mm) + vec(rec.i3_mm)));
  return rec;
}

std::string sinumerik_swivel_program(const SwivelRecord& r, std::string_view origin_comment) {
  for (const auto& [v, name] : {std::pair{&r.i1_mm, "I1"},
                                {&r.i2_mm, "I2"},
                                {&r.i3_mm, "I3"},
                                {&r.i4_mm, "I4"},
                                {&r.v1, "V1"},
                                {&r.v2, "V2"}})
    require_finite(*v, name);
  const int n = r.number;
  std::string s = fmt::format(
      "; SINUMERIK CYCLE800 swivel data record {n}, kinematics type P (swivel table): the rotary\n"
      "; axes' fitted average lines (caldaq, docs/kinematics.md \"SINUMERIK CYCLE800 swivel "
      "data\").\n"
      "; Numbering per SINUMERIK Function Manual W1 (toolholder with orientation capability):\n"
      ";   I1 $TC_CARR1..3, I2 4..6, V1 7..9, V2 10..12, I3 15..17, I4 18..20; fine offsets +40.\n"
      "; Meaning per the SINUMERIK 840D sl Commissioning Manual, \"Swivel table\":\n"
      ";   I2 distance from the machine reference point to the pivot point/intersection of the\n"
      ";   1st rotary axis; I3 from there to the pivot point/intersection of the 2nd rotary axis;\n"
      ";   I4 closure of the I4=-(I2+I3) vector chain. Rotary axis 2 is based on rotary axis 1.\n"
      ";   Angle counted positively for clockwise rotation facing the direction of V (W1).\n"
      "; Values in mm, machine axes X Y Z, in the model's home (machine) coordinates: the\n"
      ";   machine reference point is taken as the model's origin.\n"
      "; Chosen where the text is silent: each pivot point is the fitted line's point at its\n"
      ";   nominal pivot's plane (lines that do not intersect have no intersection); V is the\n"
      ";   fitted line's direction (unit length), tilted by the fitted orientation errors.\n"
      "; V's sign: {sense}\n"
      "; Not written: $TC_CARR13,14 (angles: the axes are named in 21, 22), 24..33 (angle\n"
      ";   offsets, Hirth, limits), 34..40 (names, user data), 64,65. The fine offsets of I1..I4\n"
      ";   are set to 0: the basic values below are the whole description.\n"
      "; Axis names are the model's letters: rename to the channel's axes if they differ.\n",
      fmt::arg("n", n),
      fmt::arg("sense",
               "the table turns right-handed about V for a positive angle of the model (its own\n"
               ";   rotation about +X, +Y, +Z); if the machine's angle runs the other way, V1 and "
               "V2 are\n;   negated (daq model kinematics --reverse-angles)."));
  // One comment line whatever the text holds (a path with a newline would start a block).
  if (!origin_comment.empty()) s += fmt::format("; {}\n", text::terminal_safe(origin_comment));
  for (const auto& slot : vector_slots())
    s += fmt::format("$TC_CARR{}[{}]={}\n", slot.k, n,
                     control_text((r.*slot.vector)[slot.component], slot.decimals,
                                  fmt::format("$TC_CARR{}[{}]", slot.k, n)));
  s += fmt::format("$TC_CARR21[{}]={}\n", n, r.axis1.empty() ? "0" : r.axis1);
  s += fmt::format("$TC_CARR22[{}]={}\n", n, r.axis2.empty() ? "0" : r.axis2);
  s += fmt::format("$TC_CARR23[{}]=\"{}\"\n", n, r.kind);
  for (const int k : kFineOffsets) s += fmt::format("$TC_CARR{}[{}]=0\n", k, n);
  s += "M30\n";
  return s;
}

SwivelRecord parse_sinumerik_swivel_program(std::string_view text, std::string_view where) {
  SwivelRecord r;
  std::optional<int> record;
  std::vector<int> seen;
  const auto slots = vector_slots();
  std::size_t line_no = 0;
  while (!text.empty()) {
    const auto eol = text.find('\n');
    std::string line(text.substr(0, eol));
    text = eol == std::string_view::npos ? std::string_view{} : text.substr(eol + 1);
    ++line_no;
    const auto fail = [&](std::string_view what) {
      throw InputError(fmt::format("{}:{}: {}", where, line_no, what));
    };
    if (const auto c = line.find(';'); c != std::string::npos) line.erase(c);
    line.erase(std::remove_if(line.begin(), line.end(),
                              [](char ch) { return ch == ' ' || ch == '\t' || ch == '\r'; }),
               line.end());
    if (line.empty() || line == "M30" || line == "M17" || line == "M2" || line == "M02") continue;
    // $TC_CARRk[n]=value
    int k = 0, n = 0, used = 0;
    if (std::sscanf(line.c_str(), "$TC_CARR%d[%d]=%n", &k, &n, &used) != 2 || used == 0)
      fail(fmt::format("'{}': expected $TC_CARRk[n]=value", text::terminal_safe(line)));
    const std::string value = line.substr(static_cast<std::size_t>(used));
    if (record && *record != n)
      fail(fmt::format("record {} after record {}: one record per file", n, *record));
    record = n;
    if (std::find(seen.begin(), seen.end(), k) != seen.end())
      fail(fmt::format("$TC_CARR{} given twice", k));
    seen.push_back(k);
    const auto real = [&]() {
      char* end = nullptr;
      const double v = std::strtod(value.c_str(), &end);
      if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(v) ||
          std::abs(v) > 1e5)
        fail(fmt::format("$TC_CARR{}: '{}' is not a finite number", k, text::terminal_safe(value)));
      return v;
    };
    const auto slot =
        std::find_if(slots.begin(), slots.end(), [&](const Slot& s) { return s.k == k; });
    if (slot != slots.end()) {
      (r.*(slot->vector))[slot->component] = real();
    } else if (k == 21 || k == 22) {
      const bool named =
          value.size() == 1 && std::string_view("ABC").find(value[0]) != std::string_view::npos;
      if (!named && value != "0")
        fail(fmt::format("$TC_CARR{}: '{}' is not a rotary axis A, B or C", k,
                         text::terminal_safe(value)));
      (k == 21 ? r.axis1 : r.axis2) = value == "0" ? "" : value;
    } else if (k == 23) {
      if (value != "\"P\"" && value != "\"p\"")
        fail(fmt::format("$TC_CARR23: '{}': only kinematics type \"P\" (swivel table) is read",
                         text::terminal_safe(value)));
    } else if (std::find(std::begin(kFineOffsets), std::end(kFineOffsets), k) !=
               std::end(kFineOffsets)) {
      if (real() != 0.0)
        fail(
            fmt::format("$TC_CARR{}: a fine offset other than 0 is not read (the basic "
                        "values are the description)",
                        k));
    } else {
      fail(fmt::format("$TC_CARR{} is not a variable of the swivel table's description", k));
    }
  }
  if (!record) throw InputError(fmt::format("{}: no $TC_CARR assignment", where));
  r.number = *record;
  return r;
}

FiveAxisMachine swivel_control_machine(const SwivelRecord& rec, const FiveAxisMachine& model) {
  const auto axes = swivel_axes(model);  // checks the chain
  const std::string names = axes.size() == 2 ? std::string(to_string(axes[0]->letter)) + ", " +
                                                   std::string(to_string(axes[1]->letter))
                                             : std::string(to_string(axes[0]->letter));
  if (rec.axis1 != to_string(axes[0]->letter) ||
      rec.axis2 != (axes.size() == 2 ? to_string(axes[1]->letter) : std::string_view{}))
    throw InputError(fmt::format("the record's axes are '{}', '{}'; the model's are {}", rec.axis1,
                                 rec.axis2, names));
  FiveAxisMachine m = model;
  for (RotaryAxis& r : m.rotary) {
    r.location_position_um = {};
    r.location_orientation_urad = {};
    r.motion = {};
  }
  const auto place = [&](RotaryAxis& r, const Vec3& point, const Vec3& v, std::string_view name) {
    require_finite(point, name);
    require_finite(v, name);
    Vector3d u = vec(v);
    if (u.norm() == 0.0) throw InputError(fmt::format("{}: a zero rotary axis vector", name));
    u.normalize();
    const Vector3d d = nominal_direction(r.letter);
    if (u.dot(d) < 0) u = -u;  // written with reverse_angles: the same line
    if (std::acos(std::min(1.0, u.dot(d))) > kMaxTiltRad)
      throw InputError(fmt::format("{} = ({:g}, {:g}, {:g}) is more than {} rad off the {} axis",
                                   name, v[0], v[1], v[2], kMaxTiltRad, to_string(r.letter)));
    r.pivot_mm = point;
    r.location_orientation_urad = orientation_of(r.letter, u);
  };
  // m.rotary mirrors model.rotary: the 1st axis is the last in chain order.
  RotaryAxis& first = m.rotary.back();
  place(first, rec.i2_mm, rec.v1, "I2 / V1");
  if (m.rotary.size() == 2)
    place(m.rotary.front(), arr(vec(rec.i2_mm) + vec(rec.i3_mm)), rec.v2, "I2 + I3 / V2");
  return m;
}

std::string_view heidenhain_not_written_reason() {
  return "HEIDENHAIN kinematics are not written: the public text we found (the iTNC 530 HSCI "
         "Technical Manual's kinematics description table: KEY, AXIS, COORD; 'Trans' a "
         "translation or rotation by COORD, 'MachAxis' where an axis becomes effective, 'The "
         "start of the sequence is always the tool reference point') gives the table's format "
         "but not the sign of a Trans entry on the workpiece side of the chain, the sense of a "
         "table axis's rotation, nor which rows cycle 451 (KinematicsOpt) adjusts; without them "
         "the values' meaning cannot be stated. Enter the fitted lines by hand with the machine "
         "builder's kinematics description (daq model show lists them), or let cycle 451 measure "
         "and correct the kinematics on the control (docs/kinematics.md, \"HEIDENHAIN\")";
}

}  // namespace cal::kinematics
