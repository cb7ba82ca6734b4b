// The unit of a report's time axis (daq/src/report/plot.cpp, time_unit): the largest of h, min,
// s, ms and µs the run's span holds at least twice. An imported run of three samples (2 ms) was
// drawn in minutes, its ticks 0.00000 to 3.00000 "(x10⁻⁵)".
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>
#include <vector>

#include "report/plot.hpp"

namespace {

using cal::daq::report::time_unit;

TEST(TimeAxis, EachSpanInTheLargestUnitItHoldsTwice) {
  // By hand: 2 ms holds 2 ms but not 2 s; 90 s holds 2 s, not 2 min (120 s); 7199 s holds
  // 2 min, not 2 h (7200 s).
  const struct {
    double span_s;
    const char* name;
    double seconds;
  } cases[] = {{40e-6, "µs", 1e-6},   {1.999e-3, "µs", 1e-6}, {2e-3, "ms", 1e-3},
               {0.5, "ms", 1e-3},     {1.999, "ms", 1e-3},    {2.0, "s", 1.0},
               {90.0, "s", 1.0},      {119.9, "s", 1.0},      {120.0, "min", 60.0},
               {7199.0, "min", 60.0}, {7200.0, "h", 3600.0},  {86400.0, "h", 3600.0},
               {1e-9, "µs", 1e-6}};
  for (const auto& c : cases) {
    const auto u = time_unit(c.span_s);
    EXPECT_EQ(u.name, c.name) << c.span_s << " s";
    EXPECT_EQ(u.seconds, c.seconds) << c.span_s << " s";
  }
}

TEST(TimeAxis, NoSpanIsInSeconds) {
  // A single sample, or times that are not numbers: seconds, never a division by 0.
  for (const double span : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    const auto u = time_unit(span);
    EXPECT_EQ(u.name, "s") << span;
    EXPECT_EQ(u.seconds, 1.0) << span;
  }
}

// The texts PLplot writes (each <text> element, its tspans joined, its characters written as
// "&#x32;"): the tick labels, and "(x10" where it scales them. Characters past ASCII read "?".
std::vector<std::string> texts(const std::string& svg) {
  static const std::regex text(R"re(<text[^>]*>([\s\S]*?)</text>)re");
  static const std::regex tag("<[^>]+>"), character("&#x([0-9a-fA-F]+);");
  std::vector<std::string> out;
  for (std::sregex_iterator it(svg.begin(), svg.end(), text), end; it != end; ++it) {
    const std::string inner = std::regex_replace((*it)[1].str(), tag, "");
    std::string plain;
    for (std::sregex_iterator c(inner.begin(), inner.end(), character), e; c != e; ++c) {
      const unsigned long code = std::stoul((*c)[1].str(), nullptr, 16);
      plain += code < 128 ? static_cast<char>(code) : '?';
    }
    out.push_back(plain);
  }
  return out;
}

TEST(TimeAxis, ThreeSamplesOfAnImportAreTickedInPlainNumbers) {
  // The imported run's three samples at 1 kHz: 0, 1 and 2 ms. In the unit chosen the ticks are
  // 0.0 to 2.0, no "x10" scale; in minutes (as drawn before) PLplot scaled them.
  const std::vector<double> t_s{0.0, 1e-3, 2e-3};
  const auto draw = [&](double seconds) {
    cal::daq::report::Line l{.y = {1.0, -2.5, 0.0}};
    for (const double t : t_s) l.x.push_back(t / seconds);
    return texts(cal::daq::report::svg(
        cal::daq::report::XyChart{.title = "displacement", .x_label = "time", .lines = {l}}));
  };
  const auto u = time_unit(t_s.back() - t_s.front());
  ASSERT_EQ(u.name, "ms");
  const auto shown = draw(u.seconds);
  const auto has = [](const std::vector<std::string>& v, const std::string& s) {
    for (const auto& x : v)
      if (x.find(s) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(has(shown, "2.0")) << "the last sample's tick, 2.0 ms";
  EXPECT_FALSE(has(shown, "x10"));
  EXPECT_TRUE(has(draw(60.0), "x10")) << "minutes: PLplot's scale, the case this unit avoids";
}

}  // namespace
