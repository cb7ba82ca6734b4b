#include "plot.hpp"

#include <fmt/format.h>
#include <plplot/plplot.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "markup.hpp"

namespace cal::daq::report {

Rgb palette(std::size_t i) {
  static constexpr Rgb colours[] = {blue, vermilion, green, orange, purple, sky, black, grey};
  return colours[i % std::size(colours)];
}

SeriesStyle paired_style(std::size_t pair, bool second) {
  // Filled for the first of a pair, open for the second; the shape by the palette's round.
  static constexpr std::string_view filled[] = {"▲", "■", "◆", "●"}, open[] = {"▽", "□", "◇", "○"};
  constexpr std::size_t colours = 8;  // palette()'s
  const std::size_t shape = (pair / colours) % std::size(filled);
  return {.colour = palette(pair),
          .dashed = second,
          .marker = std::string(second ? open[shape] : filled[shape])};
}

namespace {

// Colour map 0: 0 background, 1 axes, 2 grid, 3 reference lines; the rest per item.
constexpr PLINT axes_colour = 1, grid_colour = 2, reference_colour = 3, first_free = 4;
constexpr PLINT colour_count = 64;

// One PLplot stream writing SVG into memory. PLplot's svg device closes the FILE itself at
// plend1, which also finalises the memory stream's buffer.
class SvgStream {
 public:
  SvgStream(int width_pt, int height_pt) {
    file_ = open_memstream(&buffer_, &length_);
    if (file_ == nullptr) throw std::runtime_error("plot: cannot open a memory stream");
    plmkstrm(&stream_);
    plsdev("svg");
    plsfile(file_);
    plspage(0, 0, width_pt, height_pt, 0, 0);
    plscmap0n(colour_count);
    plscol0(0, 255, 255, 255);
    plscol0(axes_colour, 0, 0, 0);
    plscol0(grid_colour, 225, 225, 225);
    plscol0(reference_colour, 140, 140, 140);
    plinit();
    pladv(0);
    plschr(0, 1.05);
  }
  ~SvgStream() {
    if (!ended_) plend1();
    std::free(buffer_);
  }
  SvgStream(const SvgStream&) = delete;
  SvgStream& operator=(const SvgStream&) = delete;

  PLINT colour(Rgb c, double alpha = 1.0) {
    const PLINT i = next_ < colour_count ? next_++ : colour_count - 1;
    plscol0a(i, c.r, c.g, c.b, alpha);
    return i;
  }

  // The <svg> element only (no XML prolog or DOCTYPE, which cannot sit inside HTML), sized
  // by the page's CSS through its viewBox.
  std::string finish(std::string_view title, std::string_view cls = "plot") {
    plend1();
    ended_ = true;
    std::string s(buffer_, length_);
    const auto at = s.find("<svg");
    if (at == std::string::npos) throw std::runtime_error("plot: PLplot wrote no SVG");
    s.erase(0, at);
    for (const char* attr : {"width=\"", "height=\""}) {
      const auto a = s.find(attr);
      const auto end = a == std::string::npos ? a : s.find('"', a + std::strlen(attr));
      if (end != std::string::npos) s.erase(a, end + 1 - a);
    }
    s.insert(
        4, fmt::format(" class=\"{}\" role=\"img\" aria-label=\"{}\"", cls, html_attribute(title)));
    return unique_ids(std::move(s));
  }

  // Prefixes every id="..." of the SVG and its references (url(#...), href="#...") with a
  // number unique in the process, so plots inlined together keep their own clip paths.
  static std::string unique_ids(std::string s) {
    static std::atomic<int> counter{0};
    const std::string prefix = fmt::format("plot{}-", ++counter);
    std::vector<std::string> ids;
    for (std::size_t at = s.find(" id=\""); at != std::string::npos;
         at = s.find(" id=\"", at + 1)) {
      const auto begin = at + 5, end = s.find('"', begin);
      if (end == std::string::npos) break;
      ids.push_back(s.substr(begin, end - begin));
    }
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    for (const auto& id : ids)
      for (const auto& [from, to] :
           {std::pair{"id=\"" + id + "\"", "id=\"" + prefix + id + "\""},
            std::pair{"url(#" + id + ")", "url(#" + prefix + id + ")"},
            std::pair{"href=\"#" + id + "\"", "href=\"#" + prefix + id + "\""}})
        for (std::size_t at = s.find(from); at != std::string::npos;
             at = s.find(from, at + to.size()))
          s.replace(at, from.size(), to);
    return s;
  }

 private:
  FILE* file_ = nullptr;
  char* buffer_ = nullptr;
  std::size_t length_ = 0;
  PLINT stream_ = 0;
  PLINT next_ = first_free;
  bool ended_ = false;
};

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(lo <= hi); }
  // Some room around the data; a flat series still gets a visible span.
  Range padded(double fraction) const {
    if (empty()) return {0.0, 1.0};
    const double span = hi - lo;
    const double pad = span > 0 ? span * fraction : std::max(std::abs(lo) * 0.1, 1.0);
    return {lo - pad, hi + pad};
  }
};

struct LegendEntry {
  std::string text;  // as PLplot reads it (plot_text)
  PLINT colour = 1;
  PLINT opt = PL_LEGEND_LINE;
  PLINT style = 1;
  double width = 1.5;
  std::string symbol;  // a glyph beside the line sample (PL_LEGEND_SYMBOL)
};

// How many columns of legend entries fit under a viewport `viewport_pt` wide. PLplot makes each
// column as wide as its estimate of the longest label, which grows with the label's bytes of
// UTF-8, not its characters ("x̄↑ ± 2s" is 7 characters in 12 bytes): measured on the SVGs,
// about 0.66 of a character's height per byte plus 4 for the text's offset and spacing. Then
// the line sample, 0.05 of the viewport (the plot_width draw_legend passes). Counted in
// characters and without the sample, three columns ran past the canvas, which cut the box's
// right edge off. Some room for the box's own margins.
PLINT legend_columns(std::size_t labelled, std::size_t longest_bytes, double viewport_pt,
                     double char_pt, std::size_t most) {
  if (labelled == 0) return 0;
  const double column_pt =
      0.66 * char_pt * static_cast<double>(longest_bytes + 4) + 0.05 * viewport_pt;
  const auto fit = static_cast<std::size_t>(std::max(0.0, viewport_pt - char_pt) / column_pt);
  return static_cast<PLINT>(std::clamp<std::size_t>(fit, 1, std::min(labelled, most)));
}

// `columns` 0: one column; `y` the offset from the position, in the viewport's height.
// text_scale: the legend's text against PLplot's default size (pllegend does not follow plschr).
// Returns the legend's width in the viewport's width (0: none drawn).
PLFLT draw_legend(const std::vector<LegendEntry>& entries, PLINT position, PLINT columns = 0,
                  PLFLT y = 0.0, PLFLT text_scale = 1.0, PLFLT x = 0.015) {
  if (entries.empty()) return 0.0;
  const auto n = static_cast<PLINT>(entries.size());
  std::vector<PLINT> opt, colours, text_colours, styles, box_patterns, symbol_numbers;
  std::vector<PLFLT> widths, scales;
  std::vector<const char*> texts, symbols;
  for (const auto& e : entries) {
    opt.push_back(e.opt);
    colours.push_back(e.colour);
    text_colours.push_back(axes_colour);
    styles.push_back(e.style);
    widths.push_back(e.width);
    box_patterns.push_back(0);
    scales.push_back(0.8);
    symbol_numbers.push_back(e.symbol.empty() ? 0 : 2);
    texts.push_back(e.text.c_str());
    symbols.push_back(e.symbol.c_str());
  }
  PLFLT w = 0, h = 0;
  const PLINT rows = columns > 0 ? (n + columns - 1) / columns : 0;
  pllegend(&w, &h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, position, x, y, 0.05, 0,
           axes_colour, 1, rows, columns, n, opt.data(), 0.6, text_scale, 1.8, 0.0,
           text_colours.data(), texts.data(), colours.data(), box_patterns.data(), scales.data(),
           widths.data(), colours.data(), styles.data(), widths.data(), colours.data(),
           scales.data(), symbol_numbers.data(), symbols.data());
  return w;
}

void draw_line(SvgStream& s, const Line& l, std::vector<LegendEntry>& legend) {
  const auto n = static_cast<PLINT>(std::min(l.x.size(), l.y.size()));
  if (n == 0) return;
  const PLINT c = s.colour(l.colour);
  plcol0(c);
  plwidth(l.width);
  pllsty(l.dashed ? 2 : 1);
  plline(n, l.x.data(), l.y.data());
  const std::string marker = plot_text(l.marker);
  if (l.markers && marker.empty()) plpoin(n, l.x.data(), l.y.data(), 17);
  if (l.markers && !marker.empty()) {
    // A mark about as large as the dot (at the text's size a triangle hid its neighbours).
    PLFLT default_mm = 0, height_mm = 0;
    plgchr(&default_mm, &height_mm);
    const PLFLT scale = default_mm > 0 ? height_mm / default_mm : 1.0;
    plschr(0, 0.6 * scale);
    plstring(n, l.x.data(), l.y.data(), marker.c_str());
    plschr(0, scale);
  }
  pllsty(1);
  if (!l.label.empty())
    legend.push_back({plot_text(l.label), c,
                      marker.empty() ? PL_LEGEND_LINE : PL_LEGEND_LINE | PL_LEGEND_SYMBOL,
                      l.dashed ? 2 : 1, l.width, marker});
}

}  // namespace

TimeUnit time_unit(double span_s) {
  static constexpr TimeUnit units[] = {
      {3600.0, "h"}, {60.0, "min"}, {1.0, "s"}, {1e-3, "ms"}, {1e-6, "µs"}};
  if (!(span_s > 0) || !std::isfinite(span_s)) return {};
  for (const auto& u : units)
    if (span_s >= 2 * u.seconds) return u;
  return units[std::size(units) - 1];
}

namespace {

// A tick interval of 1, 2 or 5 times a power of ten giving about `ticks` intervals over a
// span, and the decimals its labels need (0.2 -> 1): PLplot's own choice printed 1006.8 and
// 1007.0 hPa both as "1007".
std::pair<double, int> ticks_for(double span, int ticks) {
  const double raw = span / ticks;
  if (!(raw > 0) || !std::isfinite(raw)) return {0.0, 0};
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * p;
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= raw) {
      step = m * p;
      break;
    }
  return {step, std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)))};
}

// Tick labels of a category axis: the label of the category at an integer position.
void category_label(PLINT axis, PLFLT value, char* out, PLINT length, PLPointer data) {
  const auto& labels = *static_cast<const std::vector<std::string>*>(data);
  const long k = std::lround(value);
  std::string text;
  if (axis == PL_X_AXIS && k >= 0 && static_cast<std::size_t>(k) < labels.size() &&
      std::abs(value - static_cast<double>(k)) < 1e-6)
    text = plot_text(labels[static_cast<std::size_t>(k)]);
  std::snprintf(out, static_cast<std::size_t>(length), "%s", text.c_str());
}

// An XY chart drawn with at most `max_columns` legend columns, the legend's centre `legend_x`
// from the viewport's (in its width); told the legend's width and where the viewport is, in
// the canvas's width.
struct XyDrawn {
  std::string svg;
  PLINT columns = 0;
  double legend_w = 0.0;  // in the viewport's width
  double left = 0.0, right = 0.97;
};

XyDrawn draw_xy(const XyChart& chart, std::size_t max_columns, double legend_x = 0.015) {
  Range x, y;
  for (const auto& b : chart.bands) {
    for (double v : b.x) x.add(v);
    for (double v : b.lo) y.add(v);
    for (double v : b.hi) y.add(v);
  }
  for (const auto& l : chart.lines) {
    for (double v : l.x) x.add(v);
    for (double v : l.y) y.add(v);
  }
  if (chart.zero_line) y.add(0.0);
  // The legend goes to the right of the plot, outside the data.
  const bool has_legend = std::any_of(chart.lines.begin(), chart.lines.end(),
                                      [](const Line& l) { return !l.label.empty(); }) ||
                          std::any_of(chart.bands.begin(), chart.bands.end(),
                                      [](const Band& b) { return !b.label.empty(); });
  const bool legend = chart.legend && has_legend;
  // The legend goes below the plot, in as many columns of the longest label as fit the width:
  // to the right it took a quarter of the width and clipped long instrument names. The page
  // grows by its rows, so the plot keeps its height.
  std::size_t labelled = 0, longest = 0;
  for (const auto& l : chart.lines)
    if (!l.label.empty()) ++labelled, longest = std::max(longest, l.label.size());
  for (const auto& b : chart.bands)
    if (!b.label.empty()) ++labelled, longest = std::max(longest, b.label.size());
  const double char_pt = 13.0 * chart.text_scale;
  // Room on the left for the widest tick label and the axis label beyond it ("1006.8" needs
  // more than "2"): the label is placed past the ticks, never over them.
  Range yr = y.padded(0.08);
  if (chart.min_y_span > 0 && !y.empty() && yr.hi - yr.lo < chart.min_y_span) {
    const double mid = (y.lo + y.hi) / 2;  // the data in the middle of the span asked for
    yr = {mid - chart.min_y_span / 2, mid + chart.min_y_span / 2};
  }
  const auto [ystep, ydigits] = ticks_for(yr.hi - yr.lo, 6);
  const std::size_t tick_chars = std::max(fmt::format("{:.{}f}", yr.lo, ydigits).size(),
                                          fmt::format("{:.{}f}", yr.hi, ydigits).size());
  const double label_disp = 0.8 * static_cast<double>(tick_chars) + 1.6;  // character heights
  // Without an axis label only the tick labels need room (a small multiple): the room for the
  // label left a third of the plot empty, and its caption far below it. PLplot draws a text
  // about half char_pt high, the tick labels within 2.5 of those heights of the axis.
  const double left =
      chart.y_label.empty()
          ? (0.62 * static_cast<double>(tick_chars) + 1.2) * 0.52 * char_pt / chart.width_pt + 0.01
          : std::min(0.3, (label_disp + 1.4) * char_pt / chart.width_pt + 0.01);
  // The legend as wide as the plot's frame at most (it is centred under it).
  const PLINT columns = legend ? legend_columns(labelled, longest, (0.97 - left) * chart.width_pt,
                                                char_pt, max_columns)
                               : 0;
  const PLINT rows = columns > 0 ? (static_cast<PLINT>(labelled) + columns - 1) / columns : 0;
  const double legend_pt = legend ? (1.6 * rows + 0.8) * char_pt : 0.0;
  const double total_pt = chart.height_pt + legend_pt;
  SvgStream s(chart.width_pt, static_cast<int>(total_pt));
  plschr(0, 1.05 * chart.text_scale);
  // Room on every side: no point or marker sits on the frame.
  const Range xr = x.empty() ? Range{0, 1}
                   : !chart.x_labels.empty()
                       ? Range{-0.5, static_cast<double>(chart.x_labels.size()) - 0.5}
                       : x.padded(0.04);
  const auto [xstep, xdigits] = ticks_for(xr.hi - xr.lo, 6);
  const double bottom =
      ((chart.x_label.empty() && !legend ? 1.35 : 4.0) * char_pt + legend_pt) / total_pt;
  const double top = 1.0 - (chart.x_label.empty() && !legend ? 1.6 : 2.2) * char_pt / total_pt;
  plvpor(left, 0.97, bottom, top);
  plwind(xr.lo, xr.hi, yr.lo, yr.hi);
  const bool categories = !chart.x_labels.empty();
  if (categories)
    plslabelfunc(category_label, const_cast<std::vector<std::string>*>(&chart.x_labels));
  // A category label every k-th category where they would overlap (their width estimated as
  // the existing legend's: 0.62 of a character's height per character).
  double category_step = 1.0;
  if (categories) {
    std::size_t widest = 0;
    for (const auto& l : chart.x_labels) widest = std::max(widest, plot_text(l).size());
    const double label_pt = 0.62 * char_pt * static_cast<double>(widest) + 0.5 * char_pt;
    const double each_pt =
        (0.97 - left) * chart.width_pt / static_cast<double>(chart.x_labels.size());
    category_step = std::max(1.0, std::ceil(label_pt / each_pt));
  }
  const double xtick = categories ? category_step : xstep;
  const PLINT nxsub = categories ? 1 : 0;
  plcol0(grid_colour);
  plwidth(0.5);
  plbox("g", xtick, nxsub, "g", ystep, 0);
  std::vector<LegendEntry> entries;
  for (const auto& b : chart.bands) {
    const std::size_t n = std::min({b.x.size(), b.lo.size(), b.hi.size()});
    if (n == 0) continue;
    std::vector<PLFLT> px, py;
    for (std::size_t i = 0; i < n; ++i) px.push_back(b.x[i]), py.push_back(b.hi[i]);
    for (std::size_t i = n; i-- > 0;) px.push_back(b.x[i]), py.push_back(b.lo[i]);
    const PLINT c = s.colour(b.colour, b.alpha);
    plcol0(c);
    plfill(static_cast<PLINT>(px.size()), px.data(), py.data());
    if (!b.label.empty()) entries.push_back({plot_text(b.label), c, PL_LEGEND_COLOR_BOX});
  }
  if (chart.zero_line) {
    plcol0(reference_colour);
    plwidth(1.0);
    const PLFLT zx[] = {xr.lo, xr.hi}, zy[] = {0.0, 0.0};
    plline(2, zx, zy);
  }
  for (const auto& l : chart.lines) draw_line(s, l, entries);
  plcol0(axes_colour);
  plwidth(1.0);
  // Each axis labelled with the decimals its ticks need (plprec applies to both: the axes are
  // drawn one at a time).
  plprec(1, xdigits);
  plbox(categories ? "bcnto" : "bcnst", xtick, nxsub, "", 0, 0);
  plprec(1, ydigits);
  plbox("", 0, 0, "bcnstv", ystep, 0);
  plprec(0, 0);
  if (categories) plslabelfunc(nullptr, nullptr);
  plmtex("b", 3.0, 0.5, 0.5, plot_text(chart.x_label).c_str());
  plmtex("l", label_disp, 0.5, 0.5, plot_text(chart.y_label).c_str());
  plmtex("t", 1.5, 0.5, 0.5, plot_text(chart.title).c_str());
  if (x.empty()) plptex(0.5, 0.5, 1, 0, 0.5, "no data");
  const double legend_w =
      legend ? draw_legend(entries, PL_POSITION_BOTTOM | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT,
                           columns, 3.7 * char_pt / ((top - bottom) * total_pt), chart.text_scale,
                           legend_x)
             : 0.0;
  return {s.finish(chart.title), columns, legend_w, left, 0.97};
}

}  // namespace

// The legend's columns are estimated from the labels' lengths; PLplot measures the text itself,
// and a legend wider than the plot, centred under it, lost its right edge past the canvas's (the
// environment plot's frame was cut off after "material: gauge"). Such a legend is drawn again
// centred on the canvas (the room left of the plot, under the y axis's labels, is free), and
// only when it is wider than the canvas with a column fewer (a row more moved the plot of a
// report off its page one).
std::string svg(const XyChart& chart) {
  auto drawn = draw_xy(chart, 4);
  for (;;) {
    const double span = drawn.right - drawn.left;  // the viewport, in the canvas's width
    const double width = drawn.legend_w * span;    // the legend, in the canvas's width
    if (drawn.legend_w <= 0 || drawn.left + span * (0.5 + 0.015) + width / 2 <= 0.995)
      return std::move(drawn.svg);
    if (width <= 0.99)  // centred on the canvas: its centre 0.5, in the viewport's width
      return std::move(
          draw_xy(chart, static_cast<std::size_t>(drawn.columns), (0.5 - drawn.left) / span - 0.5)
              .svg);
    if (drawn.columns <= 1) return std::move(drawn.svg);
    drawn = draw_xy(chart, static_cast<std::size_t>(drawn.columns - 1));
  }
}

namespace {

// 1, 2 or 5 times a power of ten, at least v.
double nice_step(double v) {
  if (!(v > 0)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= v) return m * p;
  return 10 * p;
}

// The first point of a drawn trace (plot coordinates) as an open circle, and an arrowhead a
// little further along it pointing the way the machine moved.
void mark_start(const Line& l, bool ccw) {
  (void)ccw;  // the trace's own order of points gives the direction
  const PLFLT x0 = l.x.front(), y0 = l.y.front();
  plwidth(1.6);
  plarc(x0, y0, 0.045, 0.045, 0, 360, 0, 0);  // an open circle
  // The arrow at the point ~0.12 along the trace from the start.
  std::size_t k = 1;
  double run = 0;
  while (k + 1 < l.x.size() && run < 0.2) {
    run += std::hypot(l.x[k] - l.x[k - 1], l.y[k] - l.y[k - 1]);
    ++k;
  }
  const double dx = l.x[k] - l.x[k - 1], dy = l.y[k] - l.y[k - 1], n = std::hypot(dx, dy);
  if (!(n > 0)) return;
  const double ux = dx / n, uy = dy / n, size = 0.09;
  const PLFLT ax[] = {l.x[k] - size * (ux - 0.5 * uy), l.x[k], l.x[k] - size * (ux + 0.5 * uy)};
  const PLFLT ay[] = {l.y[k] - size * (uy + 0.5 * ux), l.y[k], l.y[k] - size * (uy - 0.5 * ux)};
  plline(3, ax, ay);
}

}  // namespace

std::string svg(const PolarChart& chart) {
  double max_abs_um = 0.0;
  for (const auto& t : chart.traces)
    for (double v : t.y)
      if (std::isfinite(v)) max_abs_um = std::max(max_abs_um, std::abs(v));
  // Two divisions out and two in: the nominal circle at radius 1, a division 0.2.
  const double div_um = std::max(nice_step(max_abs_um / 2.0), 0.1);
  const auto radius = [&](double dev_um) {
    return std::clamp(1.0 + 0.2 * dev_um / div_um, 0.05, 1.55);
  };

  // The legend goes below the plot in up to three columns, and the page grows by its rows: the
  // plot itself stays square (a circle drawn as a circle, not an ellipse) and no legend sits
  // on the angle labels.
  const auto labelled = std::count_if(chart.traces.begin(), chart.traces.end(),
                                      [](const Line& l) { return !l.label.empty(); });
  std::size_t longest = 0;
  for (const auto& t : chart.traces) longest = std::max(longest, t.label.size());
  // PLplot's text grows with the canvas: about 11 pt on 400 pt, times text_scale.
  const double char_pt = 11.0 * chart.size_pt / 400.0 * chart.text_scale;
  const double width = chart.size_pt, side = 0.88 * width,
               top = std::max(0.07 * width, 2.4 * char_pt);
  // As many columns of the longest label as fit under the plot, up to 3 (two of
  // "counter-clockwise" beside a table ran past both sides of the canvas).
  const PLINT columns =
      legend_columns(static_cast<std::size_t>(labelled), longest, side, char_pt, 3);
  const int rows = columns > 0 ? static_cast<int>((labelled + columns - 1) / columns) : 0;
  // Under the plot: two lines (the rings' scale and the nominal one, the start marks), then the
  // legend's rows.
  const int notes = chart.mark_start ? 2 : 1;
  // 1.5 lines apart: at 1.25 the "µ" of the first touched the "○" of the second.
  const double legend_top_pt = (1.5 * notes + 0.35) * char_pt;
  const double height =
      top + side + legend_top_pt + (rows > 0 ? 1.7 * char_pt * rows + 0.6 * char_pt : 0.0);
  SvgStream s(chart.size_pt, static_cast<int>(height));
  const double left = (width - side) / 2;
  plvpor(left / width, (left + side) / width, (height - top - side) / height,
         (height - top) / height);
  // Room for the angle labels at radius 1.6: PLplot clips text at the window, and "180°" lost
  // its "1" in a window of +-1.7.
  plwind(-1.85, 1.85, -1.85, 1.85);
  plschr(0, 1.05 * chart.text_scale);
  plcol0(axes_colour);
  plmtex("t", 1.5, 0.5, 0.5, plot_text(chart.title).c_str());
  // Rings every division, the nominal circle darker; spokes every 30 degrees.
  for (int k = -2; k <= 2; ++k) {
    const double r = 1.0 + 0.2 * k;
    plcol0(k == 0 ? reference_colour : grid_colour);
    plwidth(k == 0 ? 1.2 : 0.6);
    plarc(0, 0, r, r, 0, 360, 0, 0);
  }
  for (int a = 0; a < 360; a += 30) {
    const double t = a * std::numbers::pi / 180.0;
    const PLFLT sx[] = {0.5 * std::cos(t), 1.5 * std::cos(t)},
                sy[] = {0.5 * std::sin(t), 1.5 * std::sin(t)};
    plcol0(grid_colour);
    plwidth(0.6);
    plline(2, sx, sy);
    plcol0(reference_colour);
    plptex(1.6 * std::cos(t), 1.6 * std::sin(t) - 0.03, 1, 0, 0.5, fmt::format("{}°", a).c_str());
  }
  plcol0(axes_colour);
  // The axes' names beside their angle labels: under 0°, right of 90° (inside the labels they
  // ran into "0°" once the text was drawn larger).
  plptex(1.6, -0.03 - 0.16 * chart.text_scale, 1, 0, 0.5,
         plot_text("+" + chart.first_axis).c_str());
  plptex(0.14 + 0.06 * chart.text_scale, 1.57, 1, 0, 0, plot_text("+" + chart.second_axis).c_str());
  std::vector<LegendEntry> legend;
  for (const auto& t : chart.traces) {
    Line l = t;
    l.x.clear();
    l.y.clear();
    const std::size_t n = std::min(t.x.size(), t.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(t.y[i])) continue;
      const double th = t.x[i] * std::numbers::pi / 180.0, r = radius(t.y[i]);
      l.x.push_back(r * std::cos(th));
      l.y.push_back(r * std::sin(th));
    }
    draw_line(s, l, legend);
    if (chart.mark_start && l.x.size() > 2) mark_start(l, t.x.front() < t.x.back());
  }
  plcol0(axes_colour);
  if (!chart.centre_text.empty()) plptex(0, -0.03, 1, 0, 0.5, plot_text(chart.centre_text).c_str());
  // The rings' values under the plot, with the scale: in the corner they sat on the 120° label
  // once the plot was drawn narrow enough to stand beside a table.
  plmtex("b", 1.2, 0.0, 0.0,
         fmt::format("rings every {:g} µm, the dark one nominal", div_um).c_str());
  if (chart.mark_start) plmtex("b", 2.7, 0.0, 0.0, "○ start, arrow: direction of travel");
  if (max_abs_um == 0.0 && chart.traces.empty()) plptex(0, 0, 1, 0, 0.5, "no data");
  // Below the scale's line.
  draw_legend(legend, PL_POSITION_BOTTOM | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, columns,
              legend_top_pt / side, chart.text_scale);
  return s.finish(chart.title, "plot polar");
}

}  // namespace cal::daq::report
