#include "serve/ballbar_set.hpp"

#include <cmath>
#include <numbers>

#include "ballbar_campaign.hpp"
#include "cal/daq/ballbar.hpp"
#include "cal/daq/gcode.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"

namespace daq::serve {
namespace {
using nlohmann::json;

json opt(const std::optional<double>& x) { return x ? json(*x) : json(nullptr); }

// What the page shows of a completed test (the full document is /api/runs/N).
json result_json(const BallbarTest& t) {
  return {{"G_bi_um", t.G_bi_um},
          {"squareness_um_per_m", opt(t.squareness_um_per_m)},
          {"scale_mismatch_um_per_m", opt(t.scale_mismatch_um_per_m)},
          {"servo_mismatch_ms", opt(t.servo_ms)},
          {"verdict", summary(t.verdict)},
          {"pass", t.verdict.configured ? json(t.verdict.pass) : json(nullptr)}};
}
}  // namespace

json circle_trace_json(const cal::storage::Store& store, std::int64_t run, const json& settings,
                       const json& result) {
  const auto [program, analysis] = circle_settings_from_json(settings);
  // Streamed into the segmenter (its samples paged) and decimated as the traces are read: the
  // plot holds a point a degree, not the run (issue 32).
  const auto segmenter = segment_stored_run(store, run, program);
  double cu = 0.0, cv = 0.0;
  if (const auto c = result.value("/iso230_4/centre_um"_json_pointer, json());
      c.is_array() && c.size() == 2 && c[0].is_number() && c[1].is_number())
    cu = c[0].get<double>(), cv = c[1].get<double>();
  const auto rounded = [](double x, double unit) { return std::round(x / unit) * unit; };
  json out{{"schema", "caldaq.circle-trace.v1"}, {"ccw", json::array()}, {"cw", json::array()}};
  for (const auto& t : segmenter.sources()) {
    auto& points = out[t.direction() == cal::circle::Direction::ccw ? "ccw" : "cw"];
    double last = -1e9;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double a = t.angle_deg(i);
      if (std::abs(a - last) < 1.0) continue;
      last = a;
      const double th = a * std::numbers::pi / 180.0;
      points.push_back({rounded(a, 0.01),
                        rounded(t.deviation_um(i) - cu * std::cos(th) - cv * std::sin(th), 0.001)});
    }
  }
  return out;
}

json set_plan_json(std::span<const CircleTest> tests) {
  json list = json::array();
  for (const auto& t : tests)
    list.push_back({{"plane", cal::daq::plane_name(t.plane)},
                    {"arc_deg", t.program.arc_deg},
                    {"feed_mm_per_min", t.program.feed_mm_per_min},
                    {"radius_mm", t.program.radius_mm}});
  return list;
}

BallbarSetProgress::BallbarSetProgress(std::span<const CircleTest> tests) {
  j_ = {{"schema", "caldaq.ballbar-set.v1"}, {"state", "running"}, {"current", 0}, {"reason", ""},
        {"tests", set_plan_json(tests)},     {"table", nullptr}};
  for (auto& t : j_["tests"]) t["run"] = nullptr, t["state"] = "pending", t["result"] = nullptr;
}

void BallbarSetProgress::update(std::span<const std::int64_t> done, std::int64_t current,
                                const cal::storage::Store* store) {
  auto& tests = j_["tests"];
  for (std::size_t i = 0; i < done.size() && i < tests.size(); ++i) {
    auto& t = tests[i];
    t["run"] = done[i];
    t["state"] = "done";
    if (!t["result"].is_null() || !store) continue;
    try {
      const std::int64_t run = done[i];
      t["result"] = result_json(ballbar_tests(*store, std::span(&run, 1)).front());
    } catch (const std::exception& e) {
      t["result"] = {{"error", e.what()}};
    }
  }
  done_.assign(done.begin(), done.end());
  if (done.size() < tests.size() && current > 0) {
    tests[done.size()]["run"] = current;
    tests[done.size()]["state"] = "running";
    j_["current"] = done.size();
  }
}

void BallbarSetProgress::end(std::string_view status, std::string_view reason,
                             const cal::storage::Store* store) {
  j_["state"] = status;
  j_["reason"] = reason;
  j_["current"] = nullptr;
  for (auto& t : j_["tests"])
    if (t["state"] != "done") t["state"] = t["run"].is_null() ? "not run" : "stopped";
  if (done_.empty() || !store) return;
  try {
    const auto tests = ballbar_tests(*store, done_);
    auto table = daq::to_json(volumetric_table(tests), tests);
    table.erase("tests");  // each test is in "tests" above
    j_["table"] = std::move(table);
  } catch (const std::exception& e) {
    j_["table"] = {{"error", e.what()}};
  }
}

}  // namespace daq::serve
