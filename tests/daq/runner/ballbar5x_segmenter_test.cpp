// The five-axis ballbar run's segmenter (runner/ballbar5x_run.hpp): a stream built here by
// hand from the program's timing (not by the simulated shop) is cut into each test's stops.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "ballbar5x_run.hpp"
#include "cal/analysis/error.hpp"

namespace {

namespace kin = cal::kinematics;

kin::RotaryBallbarTest test_of(std::string name, std::vector<double> angles) {
  kin::RotaryBallbarTest t;
  t.name = std::move(name);
  t.angles_deg = std::move(angles);
  return t;
}

// One test as the program runs it, sampled at 100 Hz: 2 s out at +1.5 mm, the feed-in over
// 0.5 s, each stop's dwell of 2 s at its value, the moves at 10 deg/s reading far off (0.09 mm:
// a stop's window that slid onto a move would show it), the feed-out.
void append_test(std::vector<double>& s, const std::vector<double>& angles,
                 const std::vector<double>& stop_mm) {
  const auto n = [](double seconds) { return static_cast<int>(std::lround(seconds * 100)); };
  for (int i = 0; i < n(2.0); ++i) s.push_back(1.5);
  for (int i = 0; i < n(0.5); ++i) s.push_back(1.5 * (1.0 - (i + 1) / 50.0));
  for (std::size_t k = 0; k < angles.size(); ++k) {
    for (int i = 0; i < n(2.0); ++i) s.push_back(stop_mm[k]);
    if (k + 1 < angles.size())
      for (int i = 0; i < n(std::abs(angles[k + 1] - angles[k]) / 10.0); ++i) s.push_back(0.09);
  }
  for (int i = 0; i < n(0.5); ++i) s.push_back(1.5 * (i + 1) / 50.0);
}

TEST(RotaryBallbarSegmenter, EachStopIsTheMeanOfItsDwellAndNothingOfTheMoves) {
  const std::vector<double> a1{0, 90}, a2{-30, 0, 30};
  const std::vector<double> v1{0.012, -0.034}, v2{0.001, 0.002, -0.0456};
  std::vector<double> stream;
  append_test(stream, a1, v1);
  append_test(stream, a2, v2);
  daq::RotaryBallbarSegmenter seg({test_of("C-radial", a1), test_of("A-axial", a2)}, {});
  for (double v : stream) seg.add(v);
  ASSERT_TRUE(seg.complete());
  const auto stops = seg.stops();
  ASSERT_EQ(stops.size(), 2u);
  ASSERT_EQ(stops[0].size(), 2u);
  ASSERT_EQ(stops[1].size(), 3u);
  const std::vector<std::vector<double>> want{v1, v2};
  const std::vector<std::vector<double>> angles{a1, a2};
  for (std::size_t t = 0; t < 2; ++t)
    for (std::size_t k = 0; k < stops[t].size(); ++k) {
      EXPECT_NEAR(stops[t][k].reading_um, 1e3 * want[t][k], 1e-9) << t << " " << k;
      EXPECT_NEAR(stops[t][k].spread_um, 0.0, 1e-6);
      EXPECT_EQ(stops[t][k].angle_deg, angles[t][k]);
      // The window: from 0.5 s after the dwell's start to 0.25 s before its end, 1.25 s at
      // 100 Hz (the feed-in's end is found up to 7 samples early, the ramp's last 0.2 mm).
      EXPECT_EQ(stops[t][k].samples, 125u);
    }
}

TEST(RotaryBallbarSegmenter, AStreamThatEndsEarlyNamesTheTestItWaitedFor) {
  const std::vector<double> a1{0, 90};
  std::vector<double> stream;
  append_test(stream, a1, {0.0, 0.0});
  daq::RotaryBallbarSegmenter seg({test_of("C-radial", a1), test_of("C-axial", a1)}, {});
  for (double v : stream) seg.add(v);
  EXPECT_FALSE(seg.complete());
  try {
    (void)seg.stops();
    FAIL() << "no error";
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test C-axial (2 of 2) never fed in"), std::string::npos)
        << e.what();
  }
}

}  // namespace
