// daq model map of a model with rotary axes (caldaq.model.v2): the tool tip's position and
// orientation error over the linear volume and the rotary range (cal::kinematics rotary.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/analysis/rotary.hpp"
#include "csv_columns.hpp"
#include "model_cli.hpp"

namespace daq {

namespace {

constexpr double kMaxPoses = 2e6;  // held in memory, as the 3-axis map

struct Pose {
  kin::Vec3 p_mm{};
  std::vector<double> angles_deg;
};

struct PoseError {
  Pose pose;
  kin::VolumetricError e;
};

double norm(const kin::Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

std::string angles_text(const mdl::Model& m, std::span<const double> angles_deg) {
  std::string s;
  for (std::size_t i = 0; i < angles_deg.size(); ++i)
    s += fmt::format("{}{} {:g}", i ? ", " : "", kin::to_string(m.rotary[i].axis.letter),
                     angles_deg[i]);
  return s + " deg";
}

std::vector<double> steps(double lo, double hi, std::size_t n) {
  std::vector<double> v;
  for (std::size_t i = 0; i < n; ++i)
    v.push_back(n == 1 ? lo
                       : lo + (hi - lo) * static_cast<double>(i) / (static_cast<double>(n) - 1.0));
  return v;
}

std::vector<Pose> grid_poses(const mdl::Model& m, const kin::Grid& g, std::size_t angle_count) {
  double total = static_cast<double>(g.count[0]) * static_cast<double>(g.count[1]) *
                 static_cast<double>(g.count[2]);
  for (std::size_t i = 0; i < m.rotary.size(); ++i) total *= static_cast<double>(angle_count);
  if (angle_count == 0) throw cal::InputError("--angle-count needs 1 or more");
  if (total > kMaxPoses)
    throw cal::InputError(
        fmt::format("{:g} poses (the grid times --angle-count per rotary "
                    "axis): more than {:g}",
                    total, kMaxPoses));
  std::vector<std::vector<double>> angles(1);
  for (const auto& r : m.rotary) {
    std::vector<std::vector<double>> next;
    for (const auto& a : angles)
      for (double v : steps(r.range_deg[0], r.range_deg[1], angle_count)) {
        next.push_back(a);
        next.back().push_back(v);
      }
    angles = std::move(next);
  }
  std::vector<Pose> poses;
  for (double x : steps(g.min_mm[0], g.max_mm[0], g.count[0]))
    for (double y : steps(g.min_mm[1], g.max_mm[1], g.count[1]))
      for (double z : steps(g.min_mm[2], g.max_mm[2], g.count[2]))
        for (const auto& a : angles) poses.push_back({{x, y, z}, a});
  return poses;
}

std::vector<Pose> csv_poses(const mdl::Model& m, const std::string& path, std::vector<int>& lines) {
  std::vector<std::string> columns{"x_mm", "y_mm", "z_mm"};
  for (const auto& c : rotary_angle_columns(m)) columns.push_back(c);
  const auto csv = read_csv_columns(path, columns);
  std::vector<Pose> poses;
  for (std::size_t r = 0; r < csv.rows(); ++r) {
    Pose p{{csv.numbers.at("x_mm")[r], csv.numbers.at("y_mm")[r], csv.numbers.at("z_mm")[r]}, {}};
    for (std::size_t i = 3; i < columns.size(); ++i)
      p.angles_deg.push_back(csv.numbers.at(columns[i])[r]);
    poses.push_back(std::move(p));
  }
  lines = csv.line;
  return poses;
}

// The errors at every pose; an error names the pose (and its CSV line when there is one).
std::vector<PoseError> evaluate(const kin::FiveAxisMachine& machine, const std::vector<Pose>& poses,
                                kin::Method method, const std::string& where,
                                const std::vector<int>& lines, const mdl::Model& m) {
  std::vector<PoseError> out;
  out.reserve(poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto& p = poses[k];
    const std::string at =
        fmt::format("{}the error at ({:g}, {:g}, {:g}) mm, {}",
                    lines.empty() ? "" : fmt::format("{}:{}: ", where, lines[k]), p.p_mm[0],
                    p.p_mm[1], p.p_mm[2], angles_text(m, p.angles_deg));
    kin::VolumetricError e;
    try {
      e = kin::five_axis_error(machine, p.p_mm, p.angles_deg, method);
    } catch (const cal::InputError& err) {
      throw cal::InputError(fmt::format("{}: {}", at, err.what()));
    }
    const auto& t = e.translation_um;
    const auto& r = e.rotation_urad;
    require_finite(std::array{t[0], t[1], t[2], r[0], r[1], r[2]}, at);
    out.push_back({p, e});
  }
  return out;
}

// One error alone (the others zero), first order: what it contributes over the poses.
struct RotaryContribution {
  std::string name;
  double max_norm_um = 0.0, rms_um = 0.0, max_rotation_urad = 0.0;
};

RotaryContribution contribution(const std::string& name, const kin::FiveAxisMachine& alone,
                                const std::vector<Pose>& poses) {
  RotaryContribution c{name};
  double sum = 0.0;
  for (const auto& p : poses) {
    const auto e = kin::five_axis_error(alone, p.p_mm, p.angles_deg, kin::Method::first_order);
    const double n = norm(e.translation_um);
    c.max_norm_um = std::max(c.max_norm_um, n);
    c.max_rotation_urad = std::max(c.max_rotation_urad, norm(e.rotation_urad));
    sum += n * n;
  }
  c.rms_um = poses.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(poses.size()));
  return c;
}

// Each location and component error of the rotary axes alone, and the linear axes' 21
// together; ranked by the largest |e|.
std::vector<RotaryContribution> contributions(const mdl::Model& m, const std::vector<Pose>& poses) {
  kin::FiveAxisMachine bare = mdl::five_axis(m);
  for (auto& r : bare.rotary) {
    r.location_position_um = {};
    r.location_orientation_urad = {};
    r.motion = {};
  }
  std::vector<RotaryContribution> out;
  {
    kin::FiveAxisMachine linear = bare;
    out.push_back(contribution("linear axes (21 errors together)", linear, poses));
  }
  kin::Machine no_linear;
  no_linear.topology = m.machine.topology;
  no_linear.tool_offset_mm = m.machine.tool_offset_mm;
  no_linear.table_offset_mm = m.machine.table_offset_mm;
  for (std::size_t i = 0; i < m.rotary.size(); ++i) {
    const auto& full = m.rotary[i].axis;
    const auto names = kin::location_error_names(full.letter);
    const std::size_t own = kin::direction_index(full.letter);
    std::size_t n = 0;
    for (std::size_t slot = 0; slot < 6; ++slot) {
      if (slot % 3 == own) continue;
      kin::FiveAxisMachine alone = bare;
      alone.linear = no_linear;
      auto& r = alone.rotary[i];
      if (slot < 3)
        r.location_position_um[slot] = full.location_position_um[slot];
      else
        r.location_orientation_urad[slot - 3] = full.location_orientation_urad[slot - 3];
      out.push_back(contribution(names[n++], alone, poses));
    }
    for (std::size_t d = 0; d < 6; ++d) {
      kin::FiveAxisMachine alone = bare;
      alone.linear = no_linear;
      const auto& from = mdl::rotary_component(full, d);
      if (from.is_zero()) continue;
      mdl::rotary_component(alone.rotary[i], d) = from;
      out.push_back(contribution(mdl::rotary_component_name(full.letter, d), alone, poses));
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.max_norm_um > b.max_norm_um; });
  return out;
}

json point_json(const mdl::Model& m, const PoseError& pe) {
  json angles = json::object();
  for (std::size_t i = 0; i < m.rotary.size(); ++i)
    angles[std::string(kin::to_string(m.rotary[i].axis.letter))] = pe.pose.angles_deg[i];
  return {{"position_mm", vec_json(pe.pose.p_mm)},
          {"angles_deg", angles},
          {"error_um", vec_json(pe.e.translation_um)},
          {"rotation_urad", vec_json(pe.e.rotation_urad)}};
}

void print_points(const mdl::Model& m, const std::vector<PoseError>& errors) {
  fmt::print("{:>10} {:>10} {:>10}", "x_mm", "y_mm", "z_mm");
  for (const auto& r : m.rotary)
    fmt::print(" {:>9}", fmt::format("{}_deg", kin::to_string(r.axis.letter)));
  fmt::print(" {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "ex_um", "ey_um", "ez_um", "|e|_um",
             "ea_urad", "eb_urad", "ec_urad");
  for (const auto& pe : errors) {
    const auto& p = pe.pose.p_mm;
    const auto& t = pe.e.translation_um;
    const auto& r = pe.e.rotation_urad;
    fmt::print("{:>10} {:>10} {:>10}", fixed_text(p[0], 3), fixed_text(p[1], 3),
               fixed_text(p[2], 3));
    for (double a : pe.pose.angles_deg) fmt::print(" {:>9}", fixed_text(a, 3));
    fmt::print(" {:>9} {:>9} {:>9} {:9.3f} {:>9} {:>9} {:>9}\n", fixed_text(t[0], 3),
               fixed_text(t[1], 3), fixed_text(t[2], 3), norm(t), fixed_text(r[0], 3),
               fixed_text(r[1], 3), fixed_text(r[2], 3));
  }
}

}  // namespace

std::vector<std::string> rotary_angle_columns(const mdl::Model& m) {
  std::vector<std::string> columns;
  for (const auto& r : m.rotary) {
    std::string c(kin::to_string(r.axis.letter));
    c[0] = static_cast<char>(c[0] - 'A' + 'a');
    columns.push_back(c + "_deg");
  }
  return columns;
}

void run_five_axis_map(const mdl::Model& m, const FiveAxisMapRequest& q) {
  const kin::FiveAxisMachine machine = mdl::five_axis(m);
  std::vector<int> lines;
  const std::vector<Pose> poses =
      q.points.empty() ? grid_poses(m, q.grid, q.angle_count) : csv_poses(m, q.points, lines);
  const auto errors = evaluate(machine, poses, q.method, q.points, lines, m);
  if (!q.points.empty()) {
    if (!q.json) return print_points(m, errors);
    json pts = json::array();
    for (const auto& pe : errors) pts.push_back(point_json(m, pe));
    auto j = map_json_head("caldaq.five-axis-map.v1", q.file, q.method);
    j["points"] = std::move(pts);
    fmt::print("{}\n", j.dump(2));
    return;
  }
  const auto largest =
      std::max_element(errors.begin(), errors.end(), [](const auto& a, const auto& b) {
        return norm(a.e.translation_um) < norm(b.e.translation_um);
      });
  const auto turned =
      std::max_element(errors.begin(), errors.end(), [](const auto& a, const auto& b) {
        return norm(a.e.rotation_urad) < norm(b.e.rotation_urad);
      });
  kin::Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const auto& pe : errors)
    for (std::size_t i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], pe.e.translation_um[i]);
      hi[i] = std::max(hi[i], pe.e.translation_um[i]);
    }
  const auto ranked = contributions(m, poses);
  const auto& g = q.grid;
  if (q.json) {
    json pts = json::array();
    for (const auto& pe : errors) pts.push_back(point_json(m, pe));
    json ranges = json::object(), cs = json::array();
    for (const auto& r : m.rotary)
      ranges[std::string(kin::to_string(r.axis.letter))] = {{"range_deg", r.range_deg},
                                                            {"count", q.angle_count}};
    for (const auto& c : ranked)
      cs.push_back({{"error", c.name},
                    {"max_norm_um", c.max_norm_um},
                    {"rms_um", c.rms_um},
                    {"max_rotation_urad", c.max_rotation_urad}});
    json grid = grid_json(g);  // and the rotary axes' ranges
    grid["rotary"] = std::move(ranges);
    auto j = map_json_head("caldaq.five-axis-map.v1", q.file, q.method);
    j.update(json{{"grid", std::move(grid)},
                  {"summary",
                   {{"max_norm_um", norm(largest->e.translation_um)},
                    {"max_norm_at", point_json(m, *largest)},
                    {"max_rotation_urad", norm(turned->e.rotation_urad)},
                    {"max_rotation_at", point_json(m, *turned)},
                    {"min_um", vec_json(lo)},
                    {"max_um", vec_json(hi)}}},
                  {"contributions", cs},
                  {"points", pts}});
    fmt::print("{}\n", j.dump(2));
    return;
  }
  std::string rotary_grid;
  for (const auto& r : m.rotary)
    rotary_grid += fmt::format(", {} {:g} .. {:g} deg ({})", kin::to_string(r.axis.letter),
                               r.range_deg[0], r.range_deg[1], q.angle_count);
  fmt::print(
      "Five-axis error of {} ({} model), {} x {} x {} points over ({:g} .. {:g}, {:g} .. {:g}, "
      "{:g} .. {:g}) mm{}: {} poses\n",
      m.name.empty() ? q.file : m.name, method_name(q.method), g.count[0], g.count[1], g.count[2],
      g.min_mm[0], g.max_mm[0], g.min_mm[1], g.max_mm[1], g.min_mm[2], g.max_mm[2], rotary_grid,
      errors.size());
  const auto& lp = largest->pose.p_mm;
  const auto& tp = turned->pose.p_mm;
  fmt::print("  largest |e|            {:.3f} um at ({:g}, {:g}, {:g}) mm, {}\n",
             norm(largest->e.translation_um), lp[0], lp[1], lp[2],
             angles_text(m, largest->pose.angles_deg));
  fmt::print("  largest tool rotation  {:.3f} urad at ({:g}, {:g}, {:g}) mm, {}\n",
             norm(turned->e.rotation_urad), tp[0], tp[1], tp[2],
             angles_text(m, turned->pose.angles_deg));
  for (std::size_t i = 0; i < 3; ++i)
    fmt::print("  e{}  {:>9} .. {:>9} um (range {:.3f})\n", static_cast<char>('x' + i),
               fixed_text(lo[i], 3), fixed_text(hi[i], 3), hi[i] - lo[i]);
  fmt::print(
      "Contributions, ranked (largest |e| of each error alone, first order; workpiece frame):\n");
  std::size_t k = 0;
  for (const auto& c : ranked) {
    if (c.max_norm_um == 0.0 && c.max_rotation_urad == 0.0) continue;
    fmt::print("  {:2}. {:34} {:9.3f} um  (RMS {:.3f}; tool rotation up to {:.3f} urad)\n", ++k,
               c.name, c.max_norm_um, c.rms_um, c.max_rotation_urad);
  }
}

}  // namespace daq
