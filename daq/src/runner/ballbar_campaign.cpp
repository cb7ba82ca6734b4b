#include "ballbar_campaign.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "cal/analysis/error.hpp"
#include "circle_output.hpp"
#include "json_input.hpp"
#include "provenance.hpp"

namespace daq {

using nlohmann::json;
namespace ci = cal::circle;
namespace st = cal::storage;

namespace {

std::optional<ci::Plane> plane_of(const std::string& name) {
  if (name == "XY") return ci::Plane::xy;
  if (name == "YZ") return ci::Plane::yz;
  if (name == "ZX") return ci::Plane::zx;
  return std::nullopt;
}

// The newest current result of the run in a circle schema.
std::optional<json> current_circle_result(const st::RunReader& store, std::int64_t run) {
  std::optional<json> out;
  for (const auto& r : store.results(run)) {
    if (!r.current()) continue;
    json j = cal::daq::parse_stored_json(r.json);
    if (j.is_object() && is_circle_schema(j.value("schema", ""))) out = std::move(j);
  }
  return out;
}

BallbarTest test_of(const st::RunReader& store, const st::RunRecord& run) {
  const auto where = fmt::format("{}: run {}", store.name(), run.id);
  if (run.kind != "circle")
    throw cal::InputError(fmt::format("{} is a {} run, not a ballbar test", where, run.kind));
  const auto result = current_circle_result(store, run.id);
  if (!result) throw cal::InputError(fmt::format("{} has no circle result", where));
  const json settings = cal::daq::parse_stored_json(run.settings_json);
  BallbarTest t{.run = run.id,
                .started_unix_ms = run.started_unix_ms,
                .campaign = run.campaign,
                .plane_name = result->value("plane", std::string("XY")),
                .feed_mm_per_min = result->value("feed_mm_per_min", 0.0),
                .radius_mm = result->value("radius_mm", 0.0),
                .standard = result->value("standard", std::string())};
  const auto plane = plane_of(t.plane_name);
  if (!plane) throw cal::InputError(fmt::format("{}: plane '{}'", where, t.plane_name));
  t.plane = *plane;
  const auto& iso = result->value("iso230_4", json::object());
  t.arc_deg = iso.value("arc_deg", 360.0);
  // G(b) is among the values of 2005 and GB/T, informative under 1996.
  if (iso.contains("G_bi_um"))
    t.G_bi_um = iso["G_bi_um"].get<double>();
  else if (result->contains("informative") && (*result)["informative"].contains("G_bi_um"))
    t.G_bi_um = (*result)["informative"]["G_bi_um"].value("value", 0.0);
  for (const auto& d : result->value("diagnostics", json::array())) {
    const auto key = d.value("key", std::string());
    const double v = d.value("value", 0.0);
    if (key == "squareness") t.squareness_um_per_m = v;
    if (key == "scale_mismatch")
      t.scale_mismatch_um_per_m = v, t.mismatch_name = d.value("name", "");
    if (key == "servo_mismatch") t.servo_ms = v, t.servo_name = d.value("name", "");
    if (key == "radius_error") t.radius_error_um = v;
  }
  if (settings.is_object() && settings.contains("centre_mm") && settings["centre_mm"].is_array() &&
      settings["centre_mm"].size() == 3)
    t.centre_mm = std::array<double, 3>{settings["centre_mm"][0].get<double>(),
                                        settings["centre_mm"][1].get<double>(),
                                        settings["centre_mm"][2].get<double>()};
  t.verdict = verdict_of(settings.is_object() ? settings : json::object(), *result);
  return t;
}

std::string num_or_dash(const std::optional<double>& v, const char* format = "{:+.3f}") {
  return v ? fmt::format(fmt::runtime(format), *v) : std::string("-");
}

}  // namespace

std::vector<BallbarTest> ballbar_tests(const st::RunReader& store, std::span<const std::int64_t> runs) {
  std::vector<BallbarTest> out;
  for (auto id : runs) {
    const auto run = store.run(id);
    if (!run) throw cal::InputError(fmt::format("{}: no run {}", store.name(), id));
    out.push_back(test_of(store, *run));
  }
  return out;
}

std::vector<std::int64_t> ballbar_runs(const st::RunReader& store, std::string_view machine,
                                       std::string_view campaign) {
  const auto m = store.machine_by_name(machine);
  if (!m)
    throw cal::InputError(fmt::format("{}: no machine named '{}' (daq runs lists them)",
                                      store.name(), machine));
  std::vector<std::int64_t> out;
  for (const auto& r : store.runs())
    if (r.machine_id == m->id && r.kind == "circle" && r.status == st::RunStatus::complete &&
        (campaign.empty() || r.campaign == campaign) && current_circle_result(store, r.id))
      out.push_back(r.id);
  return out;
}

VolumetricTable volumetric_table(std::span<const BallbarTest> tests) {
  VolumetricTable v;
  std::vector<ci::PlaneValues> values;
  for (ci::Plane p : {ci::Plane::xy, ci::Plane::zx, ci::Plane::yz}) {
    std::vector<const BallbarTest*> in;
    for (const auto& t : tests) {
      if (t.plane != p) continue;
      if (!t.squareness_um_per_m || !t.scale_mismatch_um_per_m) {
        v.notes.push_back(
            fmt::format("run {} ({}) left out: its squareness or scale mismatch "
                        "was not fitted (see its notes)",
                        t.run, t.plane_name));
        continue;
      }
      in.push_back(&t);
    }
    const auto name = std::string(ci::Plane::xy == p ? "XY" : p == ci::Plane::zx ? "ZX" : "YZ");
    if (in.empty()) {
      v.notes.push_back(fmt::format("no test in {}: its squareness is not in the table", name));
      continue;
    }
    const double slowest = (*std::min_element(in.begin(), in.end(), [](auto* a, auto* b) {
                             return a->feed_mm_per_min < b->feed_mm_per_min;
                           }))->feed_mm_per_min;
    std::erase_if(in, [&](auto* t) { return t->feed_mm_per_min > slowest * (1 + 1e-9); });
    auto& use = v.used[static_cast<std::size_t>(p)];
    use.feed_mm_per_min = slowest;
    use.centre_mm = in.front()->centre_mm;
    ci::PlaneValues pv{.plane = p};
    double mean_sum = 0;
    int calibrated = 0;
    for (const auto* t : in) {
      use.runs.push_back(t->run);
      pv.squareness_um_per_m += *t->squareness_um_per_m / static_cast<double>(in.size());
      pv.scale_mismatch_um_per_m += *t->scale_mismatch_um_per_m / static_cast<double>(in.size());
      if (t->radius_error_um) mean_sum += *t->radius_error_um / t->radius_mm * 1e3, ++calibrated;
    }
    if (calibrated) pv.mean_scale_um_per_m = mean_sum / calibrated;
    values.push_back(pv);
  }
  v.combined = ci::combine_planes(values);
  return v;
}

json to_json(const BallbarTest& t) {
  const auto opt = [](const std::optional<double>& x) { return x ? json(*x) : json(nullptr); };
  json j{{"run", t.run},
         {"started_utc", utc_iso(t.started_unix_ms)},
         {"campaign", t.campaign},
         {"plane", t.plane_name},
         {"feed_mm_per_min", t.feed_mm_per_min},
         {"radius_mm", t.radius_mm},
         {"arc_deg", t.arc_deg},
         {"standard", t.standard},
         {"G_bi_um", t.G_bi_um},
         {"squareness_um_per_m", opt(t.squareness_um_per_m)},
         {"scale_mismatch_um_per_m", opt(t.scale_mismatch_um_per_m)},
         {"servo_mismatch_ms", opt(t.servo_ms)},
         {"radius_error_um", opt(t.radius_error_um)},
         {"verdict", to_json(t.verdict)}};
  j["verdict"]["summary"] = summary(t.verdict);
  return j;
}

json model_squareness(const VolumetricTable& v) {
  json block = json::object();
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& pv = v.combined.planes[i];
    if (!pv) continue;
    const auto& use = v.used[i];
    json e{{"iso230_1_urad", ci::location_error_urad(*pv)},
           {"method", use.runs.size() > 1 ? "circles" : "circle"},
           {"source",
            {{"kind", "ballbar"}, {"runs", use.runs}, {"feed_mm_per_min", use.feed_mm_per_min}}}};
    // A circle measures the squareness where it was run; without the position it stays unsaid.
    if (use.centre_mm) e["placement"] = "local", e["position_mm"] = *use.centre_mm;
    block[std::string(cal::kinematics::location_error_name(ci::model_plane(pv->plane)))] = e;
  }
  return block;
}

json to_json(const VolumetricTable& v, std::span<const BallbarTest> tests) {
  json planes = json::array();
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& pv = v.combined.planes[i];
    if (!pv) continue;
    const auto mp = ci::model_plane(pv->plane);
    planes.push_back({{"plane", i == 0   ? "XY"
                                : i == 1 ? "YZ"
                                         : "ZX"},
                      {"runs", v.used[i].runs},
                      {"feed_mm_per_min", v.used[i].feed_mm_per_min},
                      {"squareness_um_per_m", pv->squareness_um_per_m},
                      {"location_error", std::string(cal::kinematics::location_error_name(mp))},
                      {"location_error_urad", ci::location_error_urad(*pv)},
                      {"scale_mismatch_um_per_m", pv->scale_mismatch_um_per_m},
                      {"mean_scale_um_per_m",
                       pv->mean_scale_um_per_m ? json(*pv->mean_scale_um_per_m) : json(nullptr)}});
  }
  json scale = nullptr;
  if (v.combined.scale_um_per_m) {
    const auto& s = *v.combined.scale_um_per_m;
    scale = {{"X", s[0]},
             {"Y", s[1]},
             {"Z", s[2]},
             {"absolute", v.combined.scale_absolute},
             {"residual_rms_um_per_m", v.combined.scale_residual_um_per_m
                                           ? json(*v.combined.scale_residual_um_per_m)
                                           : json(nullptr)}};
  }
  json t = json::array();
  for (const auto& x : tests) t.push_back(to_json(x));
  return {{"schema", "caldaq.ballbar-volumetric.v1"},
          {"convention",
           "squareness_um_per_m: positive when the angle between the positive axes exceeds 90 "
           "deg; location_error_urad: ISO 230-1, E_C0Y = +XY, E_B0Z = -ZX, E_A0Z = +YZ "
           "(docs/kinematics.md); scale_mismatch_um_per_m: s_u - s_v in the plane's order "
           "(XY: X - Y, ZX: Z - X, YZ: Y - Z)"},
          {"planes", planes},
          {"scale_um_per_m", scale},
          {"closure_um_per_m",
           v.combined.closure_um_per_m ? json(*v.combined.closure_um_per_m) : json(nullptr)},
          {"model_squareness", model_squareness(v)},
          {"notes", v.notes},
          {"tests", t}};
}

void print_volumetric(const VolumetricTable& v, std::span<const BallbarTest> tests) {
  fmt::print("Ballbar tests ({}):\n", tests.size());
  fmt::print("  {:>5}  {:<5} {:>7} {:>8} {:>6} {:>9} {:>12} {:>13} {:>10}\n", "run", "plane",
             "R mm", "F mm/min", "arc", "G(b) um", "squareness", "mismatch", "servo ms");
  for (const auto& t : tests)
    fmt::print("  {:>5}  {:<5} {:>7g} {:>8g} {:>6g} {:>9.3f} {:>12} {:>13} {:>10}\n", t.run,
               t.plane_name, t.radius_mm, t.feed_mm_per_min, t.arc_deg, t.G_bi_um,
               num_or_dash(t.squareness_um_per_m), num_or_dash(t.scale_mismatch_um_per_m),
               num_or_dash(t.servo_ms));
  fmt::print(
      "\nThree-plane table (each plane at its slowest feed; alpha positive when the angle between "
      "the\npositive axes exceeds 90 deg; the machine model's ISO 230-1 location errors: E_C0Y = "
      "+alpha XY,\nE_B0Z = -alpha ZX, E_A0Z = +alpha YZ; docs/circle.md):\n");
  fmt::print("  {:<5} {:<12} {:>8} {:>16} {:>22} {:>18}\n", "plane", "runs", "feed", "alpha um/m",
             "location error urad", "mismatch um/m");
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& pv = v.combined.planes[i];
    if (!pv) continue;
    const auto mp = ci::model_plane(pv->plane);
    std::string runs;
    for (auto r : v.used[i].runs) runs += (runs.empty() ? "" : ",") + std::to_string(r);
    const char* pair = i == 0 ? "X - Y" : i == 1 ? "Y - Z" : "Z - X";
    fmt::print("  {:<5} {:<12} {:>8g} {:>+16.3f} {:>8} = {:>+11.3f} {:>7} {:>+10.3f}\n",
               i == 0   ? "XY"
               : i == 1 ? "YZ"
                        : "ZX",
               runs, v.used[i].feed_mm_per_min, pv->squareness_um_per_m,
               cal::kinematics::location_error_name(mp), ci::location_error_urad(*pv), pair,
               pv->scale_mismatch_um_per_m);
  }
  if (const auto& s = v.combined.scale_um_per_m)
    fmt::print("  scale X {:+.3f}, Y {:+.3f}, Z {:+.3f} um/m ({}){}\n", (*s)[0], (*s)[1], (*s)[2],
               v.combined.scale_absolute
                   ? "absolute, from the calibrated bar's radius error and the mismatches"
                   : "relative: their mean set to 0; the absolute scale needs a calibrated bar",
               v.combined.scale_residual_um_per_m
                   ? fmt::format("; least-squares residual {:.3f} um/m",
                                 *v.combined.scale_residual_um_per_m)
                   : std::string());
  else
    fmt::print("  scale: not evaluated (needs the mismatches of two planes)\n");
  if (v.combined.closure_um_per_m)
    fmt::print("  closure (X - Y) + (Y - Z) + (Z - X) = {:+.3f} um/m (0 for a consistent set)\n",
               *v.combined.closure_um_per_m);
  for (const auto& n : v.notes) fmt::print("  note: {}\n", n);
}

json history_json(std::span<const BallbarTest> tests) {
  json j{{"schema", "caldaq.ballbar-history.v1"}, {"series", json::array()}};
  std::map<std::tuple<int, double, double>, std::vector<const BallbarTest*>> series;
  for (const auto& t : tests)
    series[{static_cast<int>(t.plane), t.feed_mm_per_min, t.radius_mm}].push_back(&t);
  for (const auto& [k, list] : series) {
    json s{{"plane", list.front()->plane_name},
           {"feed_mm_per_min", std::get<1>(k)},
           {"radius_mm", std::get<2>(k)},
           {"tests", json::array()}};
    for (const auto* t : list) s["tests"].push_back(to_json(*t));
    j["series"].push_back(std::move(s));
  }
  return j;
}

void print_history(std::span<const BallbarTest> tests) {
  std::map<std::tuple<int, double, double>, std::vector<const BallbarTest*>> series;
  for (const auto& t : tests)
    series[{static_cast<int>(t.plane), t.feed_mm_per_min, t.radius_mm}].push_back(&t);
  for (const auto& [k, list] : series) {
    fmt::print("{} at {:g} mm/min, R {:g} mm:\n", list.front()->plane_name, std::get<1>(k),
               std::get<2>(k));
    fmt::print("  {:<17} {:>5} {:<14} {:>8} {:>11} {:>10} {:>9} {:>10}  {}\n", "date (UTC)", "run",
               "campaign", "G(b) um", "squareness", "mismatch", "servo ms", "radius um", "verdict");
    for (const auto* t : list)
      fmt::print("  {:<17} {:>5} {:<14} {:>8.3f} {:>11} {:>10} {:>9} {:>10}  {}\n",
                 utc_iso(t->started_unix_ms).substr(0, 16), t->run,
                 t->campaign.empty() ? "-" : t->campaign, t->G_bi_um,
                 num_or_dash(t->squareness_um_per_m), num_or_dash(t->scale_mismatch_um_per_m),
                 num_or_dash(t->servo_ms), num_or_dash(t->radius_error_um), summary(t->verdict));
  }
}

}  // namespace daq
