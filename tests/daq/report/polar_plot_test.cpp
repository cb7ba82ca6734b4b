// The polar plot of the ballbar reports (daq/src/report/plot.cpp), read back from its SVG: the
// nominal circle is drawn as a circle, and the legend stands below the plot, not on it. Both
// were wrong before (an ellipse 8 % flatter than wide; the legend inside, over the 300 deg label).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <regex>
#include <sstream>

#include "report/plot.hpp"

namespace {

using cal::daq::report::Line;
using cal::daq::report::PolarChart;

struct Box {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  void add(double x, double y) {
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
};

struct Polyline {
  std::string stroke;
  std::vector<std::pair<double, double>> points;
};

std::vector<Polyline> polylines(const std::string& svg) {
  static const std::regex element(
      R"re(<polyline[^>]*stroke="(#[0-9A-Fa-f]{6})"[^>]*points="([^"]*)")re");
  std::vector<Polyline> out;
  for (std::sregex_iterator it(svg.begin(), svg.end(), element), end; it != end; ++it) {
    Polyline p{(*it)[1].str(), {}};
    std::istringstream in((*it)[2].str());
    for (std::string xy; in >> xy;) {
      const auto comma = xy.find(',');
      p.points.emplace_back(std::stod(xy.substr(0, comma)), std::stod(xy.substr(comma + 1)));
    }
    out.push_back(std::move(p));
  }
  return out;
}

PolarChart chart(int traces) {
  PolarChart c{.title = "test"};
  for (int k = 0; k < traces; ++k) {
    Line l{.label = "run " + std::to_string(k + 1) + " 11-23 21:51, counter-clockwise",
           .colour = cal::daq::report::palette(static_cast<std::size_t>(k))};
    for (int a = 0; a <= 360; a += 5) l.x.push_back(a), l.y.push_back(3.0 * std::sin(a * 0.1));
    c.traces.push_back(l);
  }
  return c;
}

TEST(PolarPlot, TheNominalCircleIsACircle) {
  for (int traces : {0, 2, 6}) {
    const auto lines = polylines(cal::daq::report::svg(chart(traces)));
    // The nominal ring: the darker grey ring (reference colour), the one many-point polyline.
    const auto ring = std::find_if(lines.begin(), lines.end(), [](const Polyline& p) {
      return p.stroke == "#8C8C8C" && p.points.size() > 50;
    });
    ASSERT_NE(ring, lines.end()) << traces;
    Box b;
    for (auto [x, y] : ring->points) b.add(x, y);
    EXPECT_NEAR((b.x1 - b.x0) / (b.y1 - b.y0), 1.0, 0.005) << traces << " traces";
  }
}

TEST(PolarPlot, TheLegendStandsBelowThePlot) {
  const auto lines = polylines(cal::daq::report::svg(chart(6)));
  Box plot;  // every ring and spoke (grid and reference colours)
  for (const auto& p : lines)
    if (p.stroke == "#E1E1E1" || p.stroke == "#8C8C8C")
      for (auto [x, y] : p.points) plot.add(x, y);
  int legend_lines = 0;  // a legend entry's sample: a two-point horizontal line in a trace colour
  for (const auto& p : lines)
    if (p.points.size() == 2 && p.points[0].second == p.points[1].second && p.stroke != "#E1E1E1" &&
        p.stroke != "#8C8C8C" && p.stroke != "#000000") {
      ++legend_lines;
      // PLplot's SVG has y growing upwards (a flipping transform): below is smaller. 30 pt
      // leaves the 270 deg label and the scale's line between the plot and the legend.
      EXPECT_LT(p.points[0].second, plot.y0 - 30) << p.stroke;
    }
  EXPECT_EQ(legend_lines, 6);
}

}  // namespace
