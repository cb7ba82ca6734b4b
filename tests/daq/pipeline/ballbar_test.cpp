// BallbarSegmenter: feed-in detection, angle assignment from the program timing, trimming of
// the overshoot arcs, progress for the operator, and the errors of an incomplete stream.
#include "cal/daq/ballbar.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "cal/analysis/error.hpp"

namespace {

using cal::daq::BallbarPhase;
using cal::daq::BallbarProgram;
using cal::daq::BallbarSegmenter;

// R 100 mm at 1000 mm/min: 16.667 mm/s along the arc, 0.16667 rad/s = 9.5493 deg/s.
// With 45 deg overshoot each arc sweeps 450 deg in 47.124 s; the measured 360 deg take
// 37.699 s, i.e. 3770 samples at 100 Hz.
const BallbarProgram kProgram{.radius_mm = 100.0,
                              .feed_mm_per_min = 1000.0,
                              .sample_rate_hz = 100.0,
                              .feed_in_mm = 1.5,
                              .dwell_s = 1.0,
                              .overshoot_deg = 45.0,
                              .start_deg = 30.0};
constexpr double kRateDegS = 1000.0 / 60.0 / 100.0 * 180.0 / std::numbers::pi;  // 9.5493
constexpr double kArcS = 450.0 / kRateDegS;                                     // 47.124

// The bar's signal as a function of the true angle: an ellipse of 2 um (scale mismatch).
double bar_mm(double angle_deg) { return 0.002 * std::cos(2 * angle_deg * std::numbers::pi / 180); }

// The stream a bar would give: at rest, the feed-in (out by 1.5 mm, back to 0), dwell, ccw
// arc, dwell, cw arc; the angle of sample i after the feed-in is written out independently.
std::vector<double> stream(std::size_t after_feed_in) {
  std::vector<double> v(30, 0.0);
  for (int i = 0; i < 20; ++i) v.push_back(1.5);
  for (std::size_t i = 0; i < after_feed_in; ++i) {
    const double t = static_cast<double>(i) / 100.0;
    double a = 30.0;  // start
    if (t >= 1.0 && t < 1.0 + kArcS) a = 30.0 + kRateDegS * (t - 1.0);
    if (t >= 1.0 + kArcS) a = 30.0 + 450.0;
    if (t >= 2.0 + kArcS) a = 480.0 - kRateDegS * (t - 2.0 - kArcS);
    v.push_back(bar_mm(a));
  }
  return v;
}

TEST(BallbarSegmenter, FindsTheFeedInAndCutsBothArcsWithoutTheOvershoot) {
  BallbarSegmenter seg(kProgram);
  const auto s = stream(static_cast<std::size_t>((2.0 + 2 * kArcS) * 100) + 10);
  for (double v : s) seg.add(v);
  ASSERT_TRUE(seg.complete());
  EXPECT_EQ(*seg.feed_in_end(), 50u);  // 30 at rest + 20 out: the first settled sample
  const auto traces = seg.traces();
  ASSERT_EQ(traces.size(), 2u);
  EXPECT_EQ(traces[0].direction, cal::circle::Direction::ccw);
  EXPECT_EQ(traces[1].direction, cal::circle::Direction::cw);
  for (const auto& t : traces) {
    EXPECT_NEAR(static_cast<double>(t.angle_deg.size()), 3770, 1);
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i)
      ASSERT_NEAR(t.deviation_um[i], 1e3 * bar_mm(t.angle_deg[i]), 1e-9) << i;
  }
  // ccw runs 75 -> 435 deg (start 30 + 45 overshoot), cw 435 -> 75, one sample apart.
  EXPECT_NEAR(traces[0].angle_deg.front(), 75.0, kRateDegS / 100);
  EXPECT_NEAR(traces[0].angle_deg.back(), 435.0, kRateDegS / 100);
  EXPECT_NEAR(traces[1].angle_deg.front(), 435.0, kRateDegS / 100);
  EXPECT_NEAR(traces[1].angle_deg.back(), 75.0, kRateDegS / 100);
}

TEST(BallbarSegmenter, ProgressFollowsThePhases) {
  BallbarSegmenter seg(kProgram);
  EXPECT_EQ(seg.progress().phase, BallbarPhase::feed_in);
  const auto s = stream(static_cast<std::size_t>((2.0 + 2 * kArcS) * 100) + 10);
  auto feed = [&](double t_after_s) {
    BallbarSegmenter g(kProgram);
    for (std::size_t i = 0; i < 50 + static_cast<std::size_t>(t_after_s * 100) + 1; ++i)
      g.add(s[i]);
    return g.progress();
  };
  EXPECT_EQ(feed(0.5).phase, BallbarPhase::dwell);
  const auto mid = feed(1.0 + 10.0);  // 10 s into the ccw arc: 30 + 95.49 deg
  EXPECT_EQ(mid.phase, BallbarPhase::ccw_arc);
  EXPECT_NEAR(mid.angle_deg, 30.0 + 10.0 * kRateDegS, 1e-6);
  EXPECT_NEAR(mid.fraction, 11.0 / (2.0 + 2 * kArcS), 1e-6);
  EXPECT_EQ(feed(1.5 + kArcS).phase, BallbarPhase::dwell);
  // About 5 s into the cw arc; the latest sample is at floor(54.124 x 100) / 100 = 54.12 s.
  const auto cw = feed(2.0 + kArcS + 5.0);
  EXPECT_EQ(cw.phase, BallbarPhase::cw_arc);
  EXPECT_NEAR(cw.angle_deg, 480.0 - (54.12 - 2.0 - kArcS) * kRateDegS, 1e-6);
  for (double v : s) seg.add(v);
  EXPECT_EQ(seg.progress().phase, BallbarPhase::complete);
  EXPECT_DOUBLE_EQ(seg.progress().fraction, 1.0);
}

TEST(BallbarSegmenter, AnIncompleteStreamSaysWhatIsMissing) {
  BallbarSegmenter none(kProgram);
  for (int i = 0; i < 100; ++i) none.add(0.0);  // no feed-in move at all
  EXPECT_THROW(
      {
        try {
          (void)none.traces();
        } catch (const cal::InputError& e) {
          EXPECT_NE(std::string(e.what()).find("no feed-in"), std::string::npos) << e.what();
          throw;
        }
      },
      cal::InputError);
  BallbarSegmenter half(kProgram);
  for (double v : stream(5000)) half.add(v);
  EXPECT_FALSE(half.complete());
  try {
    (void)half.traces();
    FAIL() << "an incomplete stream gave traces";
  } catch (const cal::InputError& e) {
    // 5000 samples after the feed-in of (2 + 2 x 47.124) s x 100 Hz = 9624 needed.
    EXPECT_NE(std::string(e.what()).find("5000 samples after the feed-in, 9624 needed"),
              std::string::npos)
        << e.what();
  }
}

TEST(BallbarSegmenter, RefusesABadProgram) {
  auto bad = kProgram;
  bad.feed_mm_per_min = 0;
  EXPECT_THROW(BallbarSegmenter{bad}, cal::InputError);
  bad = kProgram;
  bad.overshoot_deg = -1;
  EXPECT_THROW(BallbarSegmenter{bad}, cal::InputError);
}

TEST(BallbarSegmenter, APartialArcOverTheTop) {
  // The ZX test of the standard set: the ccw move starts at -120 deg, runs 10 deg of overshoot,
  // the 220 deg arc and 10 more (240 deg, 25.133 s at 9.5493 deg/s), dwells 1 s, and runs back.
  // The traces hold the measured -110 .. 110 deg only: 220 / 9.5493 x 100 Hz = 2303.8 samples.
  BallbarProgram p = kProgram;
  p.start_deg = -120.0, p.overshoot_deg = 10.0, p.arc_deg = 220.0;
  const double arc_s = 240.0 / kRateDegS;
  std::vector<double> v(30, 0.0);
  for (int i = 0; i < 20; ++i) v.push_back(1.5);
  for (int i = 0; i < static_cast<int>((2.0 + 2 * arc_s) * 100) + 5; ++i) {
    const double t = i / 100.0;
    double a = -120.0;
    if (t >= 1.0 && t < 1.0 + arc_s) a = -120.0 + kRateDegS * (t - 1.0);
    if (t >= 1.0 + arc_s) a = 120.0;
    if (t >= 2.0 + arc_s) a = 120.0 - kRateDegS * (t - 2.0 - arc_s);
    v.push_back(bar_mm(a));
  }
  BallbarSegmenter seg(p);
  for (double x : v) seg.add(x);
  ASSERT_TRUE(seg.complete());
  EXPECT_NEAR(seg.arc_duration_s(), arc_s, 1e-9);
  const auto traces = seg.traces();
  for (const auto& t : traces) {
    EXPECT_NEAR(static_cast<double>(t.angle_deg.size()), 2304, 1);
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i) {
      ASSERT_GE(t.angle_deg[i], -110.0 - 1e-9);
      ASSERT_LE(t.angle_deg[i], 110.0 + 1e-9);
      ASSERT_NEAR(t.deviation_um[i], 1e3 * bar_mm(t.angle_deg[i]), 1e-9) << i;
    }
  }
  EXPECT_NEAR(traces[0].angle_deg.front(), -110.0, kRateDegS / 100);
  EXPECT_NEAR(traces[1].angle_deg.front(), 110.0, kRateDegS / 100);
  BallbarProgram bad = kProgram;
  bad.arc_deg = 170.0;
  EXPECT_THROW(BallbarSegmenter{bad}, cal::InputError);
}

}  // namespace
