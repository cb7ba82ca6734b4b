// The stop quality in one line (run_quality.hpp), as the report, `daq show`/`recompensate`, a
// run's events and a builder's refusal print it after a label: the state once, then a comma
// ("Run quality: ok: every stop ..." had two colons in a row).
#include <gtest/gtest.h>

#include <vector>

#include "cal/storage/store.hpp"
#include "run_quality.hpp"

namespace {

cal::storage::CapturedTarget stop(int target, int run, double deviation_um) {
  cal::storage::CapturedTarget t;
  t.target_index = target;
  t.run_number = run;
  t.direction = '+';
  t.nominal_mm = 100.0 * target;
  t.deviation_um = deviation_um;
  return t;
}

TEST(RunQualityText, AnAssessmentReadsStateCommaSummary) {
  // 4 targets, 3 runs each, repeating to 0.01 um: no stop beyond max(5 x median spread, floor).
  std::vector<cal::storage::CapturedTarget> stops;
  for (int t = 0; t < 4; ++t)
    for (int r = 1; r <= 3; ++r) stops.push_back(stop(t, r, 1.0 + 0.01 * r));
  const auto q = daq::assess_stops(stops, "um");
  ASSERT_EQ(q.state, "ok");
  ASSERT_TRUE(q.summary.starts_with("ok: every stop within")) << q.summary;  // as stored
  const auto text = daq::quality_text(q);
  EXPECT_TRUE(text.starts_with("ok, every stop within")) << text;
  EXPECT_EQ(text.find("ok:"), std::string::npos) << text;
}

TEST(RunQualityText, ASuspectRunSaysSuspectOnce) {
  std::vector<cal::storage::CapturedTarget> stops;
  for (int t = 0; t < 4; ++t)
    for (int r = 1; r <= 3; ++r) stops.push_back(stop(t, r, 1.0 + 0.01 * r));
  stops[4].deviation_um += 5.0;  // target 1, run 2: 5 um off the others
  const auto q = daq::assess_stops(stops, "um");
  ASSERT_EQ(q.state, "suspect");
  const auto text = daq::quality_text(q);
  EXPECT_TRUE(text.starts_with("suspect, 1 stop(s) beyond")) << text;
  EXPECT_EQ(text.find("suspect:"), std::string::npos) << text;
}

TEST(RunQualityText, AStoredSummaryWithoutItsStateGetsIt) {
  // A stored quality may not begin with its state (a run planted by hand, an older store).
  EXPECT_EQ(daq::quality_text({.state = "suspect", .summary = "planted verdict"}),
            "suspect, planted verdict");
  EXPECT_EQ(daq::quality_text({.state = "not checked", .summary = ""}), "not checked");
  EXPECT_EQ(daq::quality_text({.state = "", .summary = "ok: x"}), "ok: x");
  EXPECT_EQ(daq::quality_text({.state = "not checked", .summary = "not checked: one run"}),
            "not checked, one run");
}

}  // namespace
