// The comparison report's small trend plots (daq/src/report/plot.cpp), read back from their SVG
// (issue 30): a change of 0.0001 um is drawn flat within the minimum span, not as a cliff from
// the bottom of the plot to its top; category labels (the runs' dates) never overlap.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "report/plot.hpp"

namespace {

using cal::daq::report::Line;
using cal::daq::report::XyChart;

// The y coordinates (SVG units) of the polylines drawn in a colour.
std::vector<double> ys_of(const std::string& svg, const std::string& stroke) {
  static const std::regex element(
      R"re(<polyline[^>]*stroke="(#[0-9A-Fa-f]{6})"[^>]*points="([^"]*)")re");
  std::vector<double> out;
  for (std::sregex_iterator it(svg.begin(), svg.end(), element), end; it != end; ++it) {
    if ((*it)[1].str() != stroke) continue;
    std::istringstream in((*it)[2].str());
    for (std::string xy; in >> xy;) out.push_back(std::stod(xy.substr(xy.find(',') + 1)));
  }
  return out;
}

XyChart small(std::vector<std::string> labels, std::vector<double> y) {
  XyChart c{.title = "E (µm)",
            .width_pt = 300,
            .height_pt = 200,
            .x_labels = std::move(labels),
            .legend = false,
            .text_scale = 1.65};
  Line l{.colour = cal::daq::report::blue, .markers = true};
  for (std::size_t i = 0; i < y.size(); ++i) l.x.push_back(static_cast<double>(i));
  l.y = std::move(y);
  c.lines.push_back(l);
  return c;
}

TEST(TrendPlot, AMinimumSpanDrawsATinyChangeFlat) {
  auto c = small({"a", "b"}, {9.2, 9.2001});
  const auto steep = ys_of(cal::daq::report::svg(c), "#0072B2");
  ASSERT_GE(steep.size(), 2u);
  // Without a minimum the 0.0001 um fill the plot's height (the old drawing).
  EXPECT_GT(std::abs(steep[1] - steep[0]), 50.0);
  c.min_y_span = 1.0;
  const auto flat = ys_of(cal::daq::report::svg(c), "#0072B2");
  ASSERT_GE(flat.size(), 2u);
  EXPECT_LT(std::abs(flat[1] - flat[0]), 1.0);
}

struct Label {
  std::string text;
  double x = 0, font = 0;
};

// The texts drawn centred (PLplot's tick labels of x), with their x and font size.
std::vector<Label> centred_texts(const std::string& svg) {
  static const std::regex text(
      R"re(<text[^>]*font-size="([0-9.]+)"[^>]*matrix\([-0-9. ]*? ([-0-9.]+) [-0-9.]+\)"[^>]*text-anchor="middle"[^>]*>([\s\S]*?)</text>)re");
  static const std::regex tag("<[^>]+>");
  std::vector<Label> out;
  for (std::sregex_iterator it(svg.begin(), svg.end(), text), end; it != end; ++it) {
    // Count characters: each is one character reference or one plain character.
    const std::string inner = std::regex_replace((*it)[3].str(), tag, "");
    std::size_t chars = 0;
    for (std::size_t i = 0; i < inner.size(); ++i) {
      if (inner[i] == '&') i = inner.find(';', i);
      if (inner[i] != '\n' && inner[i] != ' ') ++chars;
    }
    out.push_back({std::to_string(chars), std::stod((*it)[2].str()), std::stod((*it)[1].str())});
  }
  return out;
}

TEST(TrendPlot, CategoryLabelsDoNotOverlap) {
  // Two runs on one day, labelled with their time: each label wider than its category.
  const auto svg =
      cal::daq::report::svg(small({"run 1 11-27 21:24", "run 3 11-27 21:24"}, {9.2, 9.3}));
  std::vector<Label> labels;
  for (const auto& l : centred_texts(svg))
    if (std::stoul(l.text) >= 12) labels.push_back(l);  // the dates, not the title
  ASSERT_GE(labels.size(), 1u) << svg;
  for (std::size_t i = 1; i < labels.size(); ++i) {
    // Half a character height per character is the narrowest a digit is drawn.
    const double half_widths = 0.25 * labels[i].font * std::stod(labels[i].text) +
                               0.25 * labels[i - 1].font * std::stod(labels[i - 1].text);
    EXPECT_GE(std::abs(labels[i].x - labels[i - 1].x), half_widths)
        << "labels " << i - 1 << " and " << i << " overlap";
  }
}

}  // namespace

namespace {

// The baselines (SVG units above the bottom edge: PLplot's group flips y) and font sizes of
// every text of a plot.
std::vector<std::pair<double, double>> text_baselines(const std::string& svg) {
  static const std::regex text(
      R"re(<text[^>]*font-size="([0-9.]+)"[^>]*matrix\([-0-9. ]*? ([-0-9.]+)\)")re");
  std::vector<std::pair<double, double>> out;
  for (std::sregex_iterator it(svg.begin(), svg.end(), text), end; it != end; ++it)
    out.emplace_back(std::stod((*it)[2].str()), std::stod((*it)[1].str()));
  return out;
}

TEST(TrendPlot, NoEmptyBandUnderTheLabels) {
  // A small multiple has no x axis label: its lowest text (the runs under x) sits near the
  // bottom edge, so the caption under the figure reads with its plot (it was 70 of 200 units
  // below, a third of the plot empty).
  const auto svg = cal::daq::report::svg(small({"run 1", "run 3"}, {9.2, 9.3}));
  const auto texts = text_baselines(svg);
  ASSERT_GE(texts.size(), 3u) << svg;
  const auto lowest = *std::min_element(texts.begin(), texts.end());
  EXPECT_GT(lowest.first, 0.2 * lowest.second) << "the lowest text is cut by the edge";
  EXPECT_LT(lowest.first, 1.5 * lowest.second) << "an empty band under the lowest text";
}

}  // namespace

namespace {

// The largest x of any line or shape drawn (polyline and polygon points; a clip path, the whole
// canvas, is not drawn), and the canvas width.
std::pair<double, double> rightmost_drawn(const std::string& svg_text) {
  static const std::regex points(R"re(points="([^"]*)")re");
  static const std::regex view_box(R"re(viewBox="0 0 ([0-9.]+) )re");
  static const std::regex clip(R"re(<clipPath[^]*?</clipPath>)re");
  const std::string svg = std::regex_replace(svg_text, clip, "");
  std::smatch vb;
  const double width = std::regex_search(svg, vb, view_box) ? std::stod(vb[1].str()) : 0.0;
  double right = 0.0;
  for (std::sregex_iterator it(svg.begin(), svg.end(), points), end; it != end; ++it) {
    std::istringstream in((*it)[1].str());
    for (std::string xy; in >> xy;) right = std::max(right, std::stod(xy.substr(0, xy.find(','))));
  }
  return {right, width};
}

}  // namespace

TEST(XyPlot, TheLegendFrameStaysOnTheCanvas) {
  // The environment plot of a run (report.cpp): three instruments in one row of the legend.
  // PLplot's legend came out wider than the canvas and its frame was cut at the right edge
  // (drawn up to x = 600 of 600, the right side of the box missing in the printed report).
  XyChart c{.title = "Temperatures",
            .x_label = "time (min)",
            .y_label = "temperature (°C)",
            .height_pt = 240};
  const char* labels[] = {"air: ids3010", "air: ptu300", "material: gauge"};
  for (std::size_t i = 0; i < 3; ++i)
    c.lines.push_back(Line{.x = {0.0, 0.5, 1.0},
                           .y = {20.6, 20.61, 20.6 - 0.3 * static_cast<double>(i)},
                           .label = labels[i],
                           .colour = cal::daq::report::palette(i),
                           .dashed = i == 2});
  const auto svg = cal::daq::report::svg(c);
  const auto [right, width] = rightmost_drawn(svg);
  ASSERT_GT(width, 0.0) << svg.substr(0, 400);
  EXPECT_LT(right, width - 1.0) << "the legend's frame reaches the canvas's edge (cut off)";
  // Every label still in the legend (PLplot writes each character as a reference).
  for (const std::string l : labels) {
    std::string refs;
    for (const char ch : l) {
      std::ostringstream ref;
      ref << "&#x" << std::hex << static_cast<int>(ch) << ';';
      refs += ref.str();
    }
    EXPECT_NE(svg.find(refs), std::string::npos) << l;
  }
}
