// Series in pairs (a linear run's run-by-run plot: each run up and down) each get their own
// style (daq/src/report/plot.cpp, issue 30): the lead's rendered report showed 10 series in 5
// colours, each direction of a run told from the other only by a dash the marks hid.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <tuple>

#include "report/plot.hpp"

namespace {

using cal::daq::report::paired_style;

std::tuple<int, int, int, bool, std::string> key(const cal::daq::report::SeriesStyle& s) {
  return {s.colour.r, s.colour.g, s.colour.b, s.dashed, s.marker};
}

TEST(SeriesStyle, NoTwoSeriesShareColourLineAndMark) {
  // 5 runs (the demo's) and 20 (past the palette's 8 colours): every series its own style.
  for (const std::size_t runs : {5u, 20u}) {
    std::set<std::tuple<int, int, int, bool, std::string>> seen;
    for (std::size_t r = 0; r < runs; ++r)
      for (const bool down : {false, true}) seen.insert(key(paired_style(r, down)));
    EXPECT_EQ(seen.size(), 2 * runs) << runs << " runs";
  }
}

TEST(SeriesStyle, UpAndDownOfARunDifferInLineAndMark) {
  for (std::size_t r = 0; r < 12; ++r) {
    const auto up = paired_style(r, false), down = paired_style(r, true);
    EXPECT_FALSE(up.dashed);
    EXPECT_TRUE(down.dashed);
    EXPECT_NE(up.marker, down.marker);
    EXPECT_FALSE(up.marker.empty());
  }
  // The demo's 5 runs: 5 colours, each of the 5 up series a filled triangle, each down an open one.
  std::set<std::tuple<int, int, int>> colours;
  for (std::size_t r = 0; r < 5; ++r) {
    const auto c = paired_style(r, false).colour;
    colours.insert({c.r, c.g, c.b});
    EXPECT_EQ(paired_style(r, false).marker, "▲");
    EXPECT_EQ(paired_style(r, true).marker, "▽");
  }
  EXPECT_EQ(colours.size(), 5u);
}

TEST(SeriesStyle, TheMarksAreDrawnAndInTheLegend) {
  // Two series of one colour: drawn with their marks at each point (3 each) and one pair of
  // marks per legend entry beside its line (PL_LEGEND_SYMBOL, 2 glyphs).
  cal::daq::report::XyChart c{.title = "runs", .x_label = "x", .y_label = "y"};
  for (const bool down : {false, true}) {
    const auto s = paired_style(0, down);
    c.lines.push_back({.x = {0, 1, 2},
                       .y = {down ? 1.0 : 0.0, 2, 3},
                       .label = down ? "run 1 down" : "run 1 up",
                       .colour = s.colour,
                       .dashed = s.dashed,
                       .markers = true,
                       .marker = s.marker});
  }
  const auto svg = cal::daq::report::svg(c);
  const auto count = [&](const std::string& glyph) {
    std::size_t n = 0;
    for (auto at = svg.find(glyph); at != std::string::npos; at = svg.find(glyph, at + 1)) ++n;
    return n;
  };
  // PLplot writes each character as a numeric reference: ▲ U+25B2, ▽ U+25BD.
  EXPECT_EQ(count("&#x25b2;"), 3u + 2u) << svg.substr(0, 2000);
  EXPECT_EQ(count("&#x25bd;"), 3u + 2u);
}

}  // namespace
