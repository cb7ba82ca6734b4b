#pragma once
// Report plots as SVG text, drawn by PLplot (Debian's libplplot, its svg device writing to
// memory), so the report can inline them and open offline. PLplot stays out of this header.
// PLplot keeps global state: call these from one thread at a time.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace cal::daq::report {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
};

// A palette that stays distinguishable in print and for the common colour-vision deficiencies
// (Okabe & Ito).
inline constexpr Rgb blue{0, 114, 178}, orange{230, 159, 0}, green{0, 158, 115},
    vermilion{213, 94, 0}, purple{204, 121, 167}, sky{86, 180, 233}, black{0, 0, 0},
    grey{120, 120, 120};
Rgb palette(std::size_t i);

struct Line {
  std::vector<double> x, y;
  std::string label;  // empty: not in the legend
  Rgb colour = blue;
  double width = 1.5;
  bool dashed = false;
  bool markers = false;  // a dot at each point
  // The glyph drawn at each point instead of the dot, and beside the line in the legend ("▲"):
  // series that share a colour stay apart by their marks.
  std::string marker;
};

// The style of one series of a chart whose series come in pairs (a run's approach in each
// direction, run by run): the pair's colour, the first of a pair solid with filled marks, the
// second dashed with open ones, the marks' shape changing once the palette's colours are used
// up, so that no two of up to 64 series share their colour, line and mark.
struct SeriesStyle {
  Rgb colour;
  bool dashed = false;
  std::string marker;
};
SeriesStyle paired_style(std::size_t pair, bool second);

// The unit of a time axis spanning `span_s` seconds: the largest of h, min, s, ms and µs the
// span holds at least twice, so that its ticks are plain numbers (an imported run of three
// samples, 40 µs, drawn in minutes had its ticks labelled "(x10⁻⁵)"; a two-minute run in hours,
// 0.01 to 0.03). Seconds for a span of 0 or less (a single sample).
struct TimeUnit {
  double seconds = 1.0;         // one unit in seconds (60 for "min")
  std::string_view name = "s";  // as an axis label gives it: "time (ms)"
};
TimeUnit time_unit(double span_s);

// A filled band between lo and hi (e.g. mean +/- 2 s).
struct Band {
  std::vector<double> x, lo, hi;
  std::string label;
  Rgb colour = blue;
  double alpha = 0.2;
};

struct XyChart {
  std::string title, x_label, y_label;
  std::vector<Band> bands;
  std::vector<Line> lines;
  int width_pt = 600, height_pt = 300;
  bool zero_line = false;  // a grey line at y = 0
  // Categories instead of numbers on x: the lines' x are 0, 1, ... and tick k is labelled
  // x_labels[k] (e.g. the dates of runs).
  std::vector<std::string> x_labels;
  bool legend = true;  // false: no legend even for labelled lines (small multiples)
  // The y axis spans at least this much (0: as the data need): a trend of values that differ by
  // 0.0001 um is drawn flat, not as a cliff across the whole plot.
  double min_y_span = 0.0;
  double text_scale = 1.0;  // > 1 for a small plot shown small (its text stays readable)
};

// A polar plot of radial deviations around a nominal circle: each line's x is the angle in
// degrees (counter-clockwise from the first axis), y the radial deviation in um. The
// deviations are magnified about the nominal circle; the rings are labelled in um.
struct PolarChart {
  std::string title;
  std::string first_axis = "X", second_axis = "Y";
  std::vector<Line> traces;
  int size_pt = 400;
  std::string centre_text;  // written at the centre, e.g. "G = 6.96 µm"
  bool mark_start = true;   // each trace's first point marked, an arrow in its direction
  double text_scale = 1.0;  // > 1 for a plot shown narrow (beside a table: its text stays 9 pt)
};

// Every text of a chart (titles, axis labels, legends, category labels) is data-safe: it is
// passed through plot_text (markup.hpp) here, and PLplot writes it as SVG text.
// Every SVG gets its own prefix on the element ids PLplot writes (its text clip paths are
// always "text-clipping0", "text-clipping1"...): several plots inlined in one HTML page would
// otherwise share the first plot's clip path, and lose their text outside it.
// Throws std::runtime_error if PLplot cannot produce the SVG. Empty lines are skipped; a
// chart with no data gives an SVG that says so.
std::string svg(const XyChart& chart);
std::string svg(const PolarChart& chart);

}  // namespace cal::daq::report
