#include "iso230_2_output.hpp"

#include <fmt/format.h>

#include "result_rows.hpp"

namespace daq {

nlohmann::json to_json(const cal::iso230_2::Evaluation& e) {
  nlohmann::json j;
  j["schema"] = "caldaq.iso230-2.v1";
  j["standard"] = {{"key", e.standard.key}, {"title", e.standard.title}, {"note", e.standard.note}};
  j["bidirectional"] = e.bidirectional;
  j["runs_per_direction"] = e.runs;
  j["targets"] = nlohmann::json::array();
  for (const auto& t : e.targets) {
    nlohmann::json tj = {{"target_mm", t.target_mm},
                         {"runs_up", t.runs_up},
                         {"mean_up_um", t.mean_up_um},
                         {"s_up_um", t.s_up_um},
                         {"mean_bi_um", t.mean_bi_um}};
    if (e.bidirectional) {
      tj["runs_down"] = t.runs_down;
      tj["mean_down_um"] = t.mean_down_um;
      tj["s_down_um"] = t.s_down_um;
      tj["reversal_um"] = t.reversal_um;
    }
    j["targets"].push_back(tj);
  }
  j["per_target"] = nlohmann::json::object();
  for (const auto& p : e.per_target) {
    j["per_target"][p.key] = {
        {"symbol", p.symbol}, {"description", p.description}, {"values_um", p.values_um}};
  }
  j["axis"] = nlohmann::json::object();
  for (const auto& a : e.axis) {
    j["axis"][a.key] = {
        {"symbol", a.symbol}, {"description", a.description}, {"value_um", a.value_um}};
  }
  j["runs_text"] = runs_text(e);
  // The values as every output lists them (result_rows.hpp): "axis" is read by key.
  nlohmann::json values = nlohmann::json::array();
  for (const auto& a : e.axis)
    values.push_back({{"key", a.key},
                      {"symbol", a.symbol},
                      {"description", a.description},
                      {"value", a.value_um},
                      {"unit", "um"}});
  j["values"] = rows_json(linear_rows({{"values", values}}));
  j["warnings"] = e.warnings;
  j["notes"] = e.notes;
  return j;
}

std::string runs_text(const nlohmann::json& doc) {
  int lo = 1 << 30, hi = 0;
  std::vector<std::string> fewer;
  const bool bi = doc.value("bidirectional", true);
  const auto targets = doc.value("targets", nlohmann::json::array());
  for (const auto& t : targets)
    for (const char* key : {"runs_up", "runs_down"})
      if (t.contains(key))
        lo = std::min(lo, t[key].get<int>()), hi = std::max(hi, t[key].get<int>());
  if (hi == 0) return fmt::format("{} runs per direction", doc.value("runs_per_direction", 0));
  if (lo == hi) return fmt::format("{} runs per direction", hi);
  for (const auto& t : targets)
    for (const char* key : {"runs_up", "runs_down"})
      if (t.contains(key) && t[key].get<int>() < hi)
        fewer.push_back(fmt::format("{} at {:.3f} mm {}", t[key].get<int>(),
                                    t.value("target_mm", 0.0),
                                    !bi                                  ? ""
                                    : std::string_view(key) == "runs_up" ? "up"
                                                                         : "down"));
  return fmt::format("{} to {} runs per direction ({} at every other target and direction; {})", lo,
                     hi, hi, fmt::join(fewer, ", "));
}

std::string runs_text(const cal::iso230_2::Evaluation& e) {
  nlohmann::json j;
  j["bidirectional"] = e.bidirectional;
  j["runs_per_direction"] = e.runs;
  j["targets"] = nlohmann::json::array();
  for (const auto& t : e.targets) {
    nlohmann::json tj{{"target_mm", t.target_mm}, {"runs_up", t.runs_up}};
    if (e.bidirectional) tj["runs_down"] = t.runs_down;
    j["targets"].push_back(tj);
  }
  return runs_text(j);
}

nlohmann::json to_json(const cal::iso230_2::Plan& p) {
  nlohmann::json j;
  j["schema"] = "caldaq.plan.v1";
  j["targets_mm"] = p.targets_mm;
  j["moves"] = nlohmann::json::array();
  for (const auto& m : p.moves) {
    const char* kind = m.kind == cal::iso230_2::MoveKind::measure   ? "measure"
                       : m.kind == cal::iso230_2::MoveKind::overrun ? "overrun"
                                                                    : "reposition";
    j["moves"].push_back({{"kind", kind},
                          {"run", m.run},
                          {"direction", cal::iso230_2::to_string(m.direction)},
                          {"target", m.target_index},
                          {"position_mm", m.position_mm}});
  }
  j["warnings"] = p.warnings;
  j["notes"] = p.notes;
  return j;
}

nlohmann::json to_json(const cal::unc::Budget& b) {
  nlohmann::json j;
  j["contributors"] = nlohmann::json::array();
  for (const auto& c : b.contributors) {
    j["contributors"].push_back({{"name", c.name}, {"model", c.model}, {"u_um", c.u_um}});
  }
  j["u_index"] = b.u_index;
  j["u_combined_um"] = b.u_combined_um;
  j["k"] = b.k;
  j["expanded_um"] = b.expanded_um;
  j["warnings"] = b.warnings;
  return j;
}

void print(const cal::iso230_2::Evaluation& e) {
  // The values first, as every output prints them (result_rows.hpp), then each target's.
  print_result(to_json(e));
  fmt::print("\n{:>12}", "target/mm");
  for (const auto& p : e.per_target) fmt::print(" {:>9}", p.symbol);
  fmt::print("   (um)\n");
  for (std::size_t i = 0; i < e.targets.size(); ++i) {
    fmt::print("{:>12}", number_text(e.targets[i].target_mm));
    for (const auto& p : e.per_target) fmt::print(" {:>9}", number_text(p.values_um[i]));
    fmt::print("\n");
  }
}

void print(const cal::unc::Budget& b, double length_m) {
  fmt::print("Measurement uncertainty of the positional deviation at L = {} m\n", length_m);
  for (const auto& c : b.contributors) {
    fmt::print("  {:<38} u = {:>8.4f} um   {}\n", c.name, c.u_um, c.model);
  }
  fmt::print("  combined standard uncertainty u_c = {:.4f} um\n", b.u_combined_um);
  fmt::print("  expanded uncertainty U (k = {:g})  = {:.3f} um\n", b.k, b.expanded_um);
  for (const auto& w : b.warnings) fmt::print("warning: {}\n", w);
}

namespace {

// A rotary axis's evaluation: its values as every output prints them (print_result, as daq
// show), then each target's means and reversal.
void print_rotary(const nlohmann::json& j) {
  print_result(j);
  fmt::print("\n{:>10} {:>10} {:>10} {:>10} {:>10}   (arcsec)\n", "target/deg", "mean up",
             "mean down", "mean", "reversal");
  const auto cell = [](const nlohmann::json& v) {
    return v.is_number() ? fmt::format("{:+.3f}", v.get<double>()) : std::string("-");
  };
  for (const auto& t : j["targets"])
    fmt::print("{:>10.3f} {:>10} {:>10} {:>10} {:>10}\n", t["position_deg"].get<double>(),
               cell(t["mean_up"]), cell(t["mean_down"]), cell(t["mean"]), cell(t["reversal"]));
}

}  // namespace

void print_kind_result(const nlohmann::json& j, const std::string& component) {
  if (j.value("schema", "") == "caldaq.rotary.v1") return print_rotary(j);
  const std::string unit = j.value("unit", "");
  fmt::print("{} {} (mean of the stops at each target, {})\n", j.value("kind", ""), component,
             unit);
  for (const auto& t : j["targets"])
    fmt::print("  {:10.3f} mm  {:+10.3f}  (spread {:.3f}, {} stops)\n",
               t["position_mm"].get<double>(), t["mean"].get<double>(), t["spread"].get<double>(),
               t["count"].get<int>());
  fmt::print("range {:.3f} {}\n", j["range"].get<double>(), unit);
  if (j.contains("straightness_um"))
    fmt::print("straightness {:.3f} um about the least-squares line (slope {:+.3f} um/m)\n",
               j["straightness_um"].get<double>(), j["slope_um_per_m"].get<double>());
}

std::vector<cal::iso230_2::Measurement> measurements(
    const std::vector<cal::storage::CapturedTarget>& targets) {
  std::vector<cal::iso230_2::Measurement> out;
  for (const auto& t : targets)
    out.push_back(
        {t.nominal_mm, t.run_number,
         t.direction == '+' ? cal::iso230_2::Direction::up : cal::iso230_2::Direction::down,
         t.deviation_um});
  return out;
}

}  // namespace daq
