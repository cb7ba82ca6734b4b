#pragma once
// The ballbar set started from the page (docs/web.md, "The ballbar set"): the set's tests in
// the order of its program (circle_tests: planes, feeds, radii), which are done with their
// stored values and verdicts, which one runs, and at the end the three-plane table. Every
// value comes from the CLI's code (ballbar_campaign.hpp, `daq ballbar volumetric`); this only
// collects it for the page's status.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string_view>
#include <vector>

#include "circle_run.hpp"

namespace cal::storage {
class Store;
}

namespace daq::serve {

class BallbarSetProgress {
 public:
  explicit BallbarSetProgress(std::span<const CircleTest> tests);
  // The runs of the tests completed so far, in order, and the current test's run (0: none).
  // The stored values of a completed run are read once, from `store` (may be null: not yet).
  void update(std::span<const std::int64_t> done, std::int64_t current,
              const cal::storage::Store* store);
  // The set has ended ("complete", "incomplete", "aborted", with the reason): no test runs;
  // the three-plane table of its completed tests, as `daq ballbar volumetric --runs` gives it.
  void end(std::string_view status, std::string_view reason, const cal::storage::Store* store);
  // caldaq.ballbar-set.v1 (docs/web.md): a few hundred bytes per test, sent with every update.
  const nlohmann::json& to_json() const { return j_; }

 private:
  nlohmann::json j_;
  std::vector<std::int64_t> done_;
};

// A stored circle run's two traces for the page's polar plot, caldaq.circle-trace.v1:
// {"ccw": [[angle_deg, deviation_um], ...], "cw": [...]}, the least-squares centre of its result
// removed (ISO 230-4 evaluates about it, as the report's plot does), a point per degree at most
// (about 900 points for a whole test, some 20 KB). The segmentation is the analysis' own
// (BallbarSegmenter on the stored bar readings). cal::InputError when it cannot be cut.
nlohmann::json circle_trace_json(const cal::storage::Store& store, std::int64_t run,
                                 const nlohmann::json& settings, const nlohmann::json& result);

// The tests of a set for the Run view's plan: plane, arc, feed and radius of each.
nlohmann::json set_plan_json(std::span<const CircleTest> tests);

}  // namespace daq::serve
