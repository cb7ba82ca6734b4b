// The volumetric error page of a machine model (see model_report.hpp). Kept apart from
// report.cpp: it shares only the plots (plot.hpp) and the look.
#include "report/model_report.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <ctime>

#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "report/markup.hpp"
#include "report/plot.hpp"
#include "result_rows.hpp"

namespace cal::daq::report {
namespace {

namespace kin = cal::kinematics;
using kin::Vec3;
using ErrorOf = std::function<Vec3(const Vec3&)>;

constexpr std::array kAxis{"X", "Y", "Z"};
constexpr int kSliceNodes = 11;

std::string esc(std::string_view s) { return html_text(s); }

double norm(const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

std::string table(const std::vector<std::string>& head,
                  const std::vector<std::vector<std::string>>& rows, std::string_view cls = "") {
  std::string h = fmt::format("<table class=\"{}\"><thead><tr>", cls);
  for (const auto& c : head) h += "<th>" + c + "</th>";
  h += "</tr></thead><tbody>";
  for (const auto& r : rows) {
    h += "<tr>";
    for (const auto& c : r) h += "<td>" + c + "</td>";
    h += "</tr>";
  }
  return h + "</tbody></table>\n";
}

std::string figure(const std::string& svg_text, std::string_view caption) {
  return fmt::format("<figure>{}<figcaption>{}</figcaption></figure>\n", svg_text, esc(caption));
}

// 1, 2 or 5 times a power of ten, at most v (a magnification that reads well).
double nice_floor(double v) {
  if (!(v > 0) || !std::isfinite(v)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(v)));
  double best = p;
  for (double m : {1.0, 2.0, 5.0})
    if (m * p <= v) best = m * p;
  return best;
}

struct Slice {
  std::size_t a = 0, b = 1, c = 2;  // plotted axes a (horizontal), b (vertical); fixed c
  double at_mm = 0.0;               // the position of c
  std::vector<Vec3> nodes;          // kSliceNodes x kSliceNodes, a fastest
  std::vector<Vec3> errors_um;
};

double lerp(double lo, double hi, int i, int n) {
  return n <= 1 ? lo : lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(n - 1);
}

std::vector<Slice> slices(const kin::Grid& g, const ErrorOf& error) {
  std::vector<Slice> out;
  for (auto [a, b, c] : {std::array<std::size_t, 3>{0, 1, 2}, {0, 2, 1}, {1, 2, 0}}) {
    if (!(g.max_mm[a] > g.min_mm[a]) || !(g.max_mm[b] > g.min_mm[b])) continue;
    Slice s{a, b, c, 0.5 * (g.min_mm[c] + g.max_mm[c]), {}, {}};
    for (int j = 0; j < kSliceNodes; ++j) {
      for (int i = 0; i < kSliceNodes; ++i) {
        Vec3 p{};
        p[a] = lerp(g.min_mm[a], g.max_mm[a], i, kSliceNodes);
        p[b] = lerp(g.min_mm[b], g.max_mm[b], j, kSliceNodes);
        p[c] = s.at_mm;
        s.nodes.push_back(p);
        s.errors_um.push_back(error(p));
      }
    }
    out.push_back(std::move(s));
  }
  return out;
}

// Magnification so that the largest in-plane displacement is about 8 % of the larger span.
double magnification(const std::vector<Slice>& ss) {
  double m = std::numeric_limits<double>::infinity();
  for (const auto& s : ss) {
    double largest = 0.0, span = 0.0;
    for (std::size_t k = 0; k < s.nodes.size(); ++k)
      largest = std::max(largest, std::hypot(s.errors_um[k][s.a], s.errors_um[k][s.b]));
    span = std::max(s.nodes.back()[s.a] - s.nodes.front()[s.a],
                    s.nodes.back()[s.b] - s.nodes.front()[s.b]);
    if (largest > 0) m = std::min(m, 0.08 * span / (largest * 1e-3));
  }
  return std::isfinite(m) ? nice_floor(m) : 1.0;
}

std::string slice_chart(const Slice& s, double mag, std::string_view what) {
  XyChart c;
  c.title = fmt::format("{}{} slice at {} = {:g} mm", kAxis[s.a], kAxis[s.b], kAxis[s.c], s.at_mm);
  c.x_label = fmt::format("{} (mm)", kAxis[s.a]);
  c.y_label = fmt::format("{} (mm)", kAxis[s.b]);
  const double span_a = s.nodes.back()[s.a] - s.nodes.front()[s.a];
  const double span_b = s.nodes.back()[s.b] - s.nodes.front()[s.b];
  c.width_pt = 760;
  c.height_pt = static_cast<int>(std::clamp(560.0 * span_b / span_a, 260.0, 620.0));
  auto node = [&](int i, int j) { return static_cast<std::size_t>(i + kSliceNodes * j); };
  for (int along = 0; along < 2; ++along) {
    for (int k = 0; k < kSliceNodes; ++k) {
      Line nominal, moved;
      nominal.colour = grey;
      nominal.width = 0.6;
      nominal.dashed = true;
      moved.colour = blue;
      moved.width = 1.4;
      for (int t = 0; t < kSliceNodes; ++t) {
        const std::size_t n = along == 0 ? node(t, k) : node(k, t);
        const Vec3& p = s.nodes[n];
        const Vec3& e = s.errors_um[n];
        nominal.x.push_back(p[s.a]);
        nominal.y.push_back(p[s.b]);
        moved.x.push_back(p[s.a] + mag * e[s.a] * 1e-3);
        moved.y.push_back(p[s.b] + mag * e[s.b] * 1e-3);
      }
      if (along == 0 && k == 0) {
        nominal.label = "nominal";
        moved.label = fmt::format("{} x{:g}", what, mag);
      }
      c.lines.push_back(std::move(nominal));
      c.lines.push_back(std::move(moved));
    }
  }
  return svg(c);
}

struct Stats {
  double max_norm_um = 0.0, rms_um = 0.0;
  Vec3 at_mm{}, min_um{}, max_um{};
};

Stats stats_over(const kin::Grid& g, const ErrorOf& error) {
  Stats s;
  s.min_um.fill(std::numeric_limits<double>::infinity());
  s.max_um.fill(-std::numeric_limits<double>::infinity());
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < g.count[2]; ++k)
    for (std::size_t j = 0; j < g.count[1]; ++j)
      for (std::size_t i = 0; i < g.count[0]; ++i) {
        const Vec3 p{
            lerp(g.min_mm[0], g.max_mm[0], static_cast<int>(i), static_cast<int>(g.count[0])),
            lerp(g.min_mm[1], g.max_mm[1], static_cast<int>(j), static_cast<int>(g.count[1])),
            lerp(g.min_mm[2], g.max_mm[2], static_cast<int>(k), static_cast<int>(g.count[2]))};
        const Vec3 e = error(p);
        const double en = norm(e);
        if (en > s.max_norm_um) s.max_norm_um = en, s.at_mm = p;
        for (std::size_t a = 0; a < 3; ++a) {
          s.min_um[a] = std::min(s.min_um[a], e[a]);
          s.max_um[a] = std::max(s.max_um[a], e[a]);
        }
        sum += en * en;
        ++n;
      }
  s.rms_um = std::sqrt(sum / static_cast<double>(std::max<std::size_t>(n, 1)));
  return s;
}

// The grid's statistics, one column per map (the model; after a compensation, the residual
// beside it): the answer, on page one.
std::string stats_table(const std::vector<std::string>& head, const std::vector<Stats>& maps) {
  std::vector<std::vector<std::string>> rows(5);
  rows[0] = {"largest |e|"};
  rows[1] = {"RMS |e| over the grid"};
  for (std::size_t a = 0; a < 3; ++a) rows[2 + a] = {fmt::format("e<sub>{}</sub> range", kAxis[a])};
  for (const auto& s : maps) {
    rows[0].push_back(fmt::format("{:.3f} µm at ({:g}, {:g}, {:g}) mm", s.max_norm_um, s.at_mm[0],
                                  s.at_mm[1], s.at_mm[2]));
    rows[1].push_back(fmt::format("{:.3f} µm", s.rms_um));
    for (std::size_t a = 0; a < 3; ++a)
      rows[2 + a].push_back(fmt::format("{} .. {} µm (span {})", ::daq::number_text(s.min_um[a]),
                                        ::daq::number_text(s.max_um[a]),
                                        ::daq::number_text(s.max_um[a] - s.min_um[a])));
  }
  return table(head, rows, maps.size() > 1 ? "stats" : "kv");
}

// `mag` 0: the magnification that shows this map's errors; else the one given (a residual is
// drawn at the model's scale, so that what is left reads against what was there: drawn at its
// own, 0.000 µm of rounding noise was magnified 1e+08 times into a distorted grid).
std::string slices_section(const kin::Grid& g, const ErrorOf& error, std::string_view what,
                           double mag = 0.0) {
  const auto ss = slices(g, error);
  if (ss.empty())
    return "<p class=\"note\">The grid is flat in at least two axes: no slice to draw.</p>\n";
  if (mag <= 0.0) mag = magnification(ss);
  std::string h;
  for (const auto& s : ss)
    h += figure(slice_chart(s, mag, what),
                fmt::format("Error vectors in the {}{} plane through the middle of the volume: "
                            "each node of the dashed nominal grid is moved by {:g} times its "
                            "error (the {} component is not shown).",
                            kAxis[s.a], kAxis[s.b], mag, kAxis[s.c]));
  return h;
}

std::string contributions_section(const ModelPage& p) {
  const auto cs = kin::contributions(p.machine, p.grid);
  const double top = cs.empty() ? 0.0 : cs.front().max_norm_um;
  std::vector<std::vector<std::string>> rows;
  for (std::size_t k = 0; k < cs.size(); ++k) {
    const auto& c = cs[k];
    const double w = top > 0 ? 100.0 * c.max_norm_um / top : 0.0;
    rows.push_back({std::to_string(k + 1), esc(c.name), kAxis[c.axis],
                    fmt::format("{:.3f}", c.max_norm_um), fmt::format("{:.3f}", c.rms_um),
                    fmt::format("<div class=\"bar\" style=\"width:{:.1f}%\"></div>", w)});
  }
  return "<h3>Contributions, ranked</h3>\n<p>What each error alone gives over the grid (first "
         "order: the contributions add up to the whole map): the first are the ones to correct "
         "first. Squareness is listed under the axis it tilts.</p>\n" +
         table({"rank", "error", "axis", "largest |e| (µm)", "RMS (µm)", ""}, rows, "rank");
}

constexpr std::string_view kCss = R"(
body { font-family: "DejaVu Sans", system-ui, sans-serif; margin: 2rem auto; max-width: 60rem;
       color: #111; line-height: 1.4; padding: 0 1rem; }
h1 { font-size: 1.6rem; border-bottom: 2px solid #0072b2; padding-bottom: .3rem; }
h2 { font-size: 1.3rem; margin-top: 2.5rem; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: .5rem 0 1rem; font-size: .9rem; }
th, td { border: 1px solid #ccc; padding: .2rem .5rem; vertical-align: top; }
th { background: #f0f4f8; text-align: left; }
table.kv thead { display: none; } table.kv td:first-child { color: #555; }
table.rank td:nth-child(4), table.rank td:nth-child(5) { text-align: right;
  font-variant-numeric: tabular-nums; }
table.rank td:last-child { width: 14rem; }
div.bar { background: #0072b2; height: .8rem; min-width: 1px; }
figure { margin: 1rem 0; break-inside: avoid; }
svg.plot { width: 100%; height: auto; max-width: 52rem; display: block; }
figcaption { font-size: .85rem; color: #444; }
.note { color: #444; font-size: .9rem; }
.simulated { background: #fff3cd; border: 1px solid #e0b000; padding: .5rem; }
footer { margin-top: 3rem; font-size: .8rem; color: #666; border-top: 1px solid #ccc; }
h3 { font-size: 1.1rem; margin-top: 1.2rem; break-after: avoid; }
table.stats td:not(:first-child) { white-space: nowrap; }
.appendix { break-before: page; }
@media print { html, body { font-size: 10pt; } body { margin: 0; padding: 0; max-width: none; }
  h2 { margin-top: 1rem; } figure { margin: .4rem 0; } }
)";

// The printed page's margins: the title at the top (data: css_string keeps it inside its
// string), "page n of m" at the bottom, as the run reports print.
std::string print_css(std::string_view title) {
  return fmt::format(
      "@page {{ size: A4; margin: 16mm 14mm 16mm 14mm;\n"
      "  @top-left {{ content: {}; font: 8pt \"DejaVu Sans\", sans-serif; color: #555; }}\n"
      "  @bottom-right {{ content: \"page \" counter(page) \" of \" counter(pages); "
      "font: 8pt \"DejaVu Sans\", sans-serif; color: #555; }} }}\n",
      css_string(title));
}

std::string now_utc() {
  return cal::text::utc_text(std::chrono::system_clock::to_time_t(std::chrono::system_clock::now()),
                             "%Y-%m-%d %H:%M:%S UTC");
}

}  // namespace

std::string model_page(const ModelPage& p) {
  const kin::Method method = p.method;
  const ErrorOf before = [&](const Vec3& q) {
    return kin::volumetric_error_um(p.machine, q, method);
  };
  std::string body;
  // A compensation of a model not (all) measured on the machine must not reach a real control.
  const std::string not_to_load =
      p.compensated ? " Do not load its compensation into a real control." : "";
  if (p.origin == "MIXED") {
    std::map<std::string, std::vector<std::string>> by_origin;
    for (const auto& [name, of] : p.origins) by_origin[of].push_back(esc(name));
    std::string which;
    for (const auto& [of, names] : by_origin)
      which += fmt::format("{}{}: {}", which.empty() ? "" : "; ", esc(of), fmt::join(names, ", "));
    body += fmt::format(
        "<p class=\"simulated\"><strong>MIXED</strong>: some errors of this model come from "
        "runs not measured on real instruments{}: it is not a model of a real machine.{}</p>\n",
        which.empty() ? " (see each error's source)" : " (" + which + ")", not_to_load);
  } else if (p.simulated) {
    body += fmt::format(
        "<p class=\"simulated\">This model describes the <strong>simulated</strong> machine: "
        "the numbers show what the software computes, not a real machine.{}</p>\n",
        not_to_load);
  }
  // Page one is the answer: how large the error is (and after a compensation, what is left),
  // and which errors make it; then the slices; the model itself is the appendix.
  const auto model_stats = stats_over(p.grid, before);
  body +=
      "<h2>Volumetric error</h2>\n<p>The error of the tool tip relative to the workpiece "
      "(actual minus commanded), over the grid";
  if (p.compensated) {
    const auto& c = *p.compensated;
    body += fmt::format(
        ", as the model gives it and with the compensation applied ({}: the "
        "exact model driven to the corrected position):</p>\n",
        esc(c.what));
    body += stats_table({"", "the model", "after the compensation"},
                        {model_stats, stats_over(p.grid, c.residual_um)});
    for (const auto& n : c.notes) body += "<p class=\"note\">" + esc(n) + "</p>\n";
  } else {
    body += ":</p>\n" + stats_table({"", ""}, {model_stats});
  }
  body += contributions_section(p);
  const auto model_slices = slices(p.grid, before);
  const double mag = model_slices.empty() ? 1.0 : magnification(model_slices);
  body +=
      "<h3>The error over the volume</h3>\n" + slices_section(p.grid, before, "with error", mag);
  if (p.compensated) {
    const auto& c = *p.compensated;
    body += fmt::format("<h2>After compensation: {}</h2>\n", esc(c.what));
    body += fmt::format(
        "<p>What the tool tip does relative to the commanded position with the compensation "
        "applied, drawn at the model's scale ({:g} times) so that what is left reads against what "
        "was there.</p>\n",
        mag);
    body += slices_section(p.grid, c.residual_um, "residual", mag);
  }
  body += "<div class=\"appendix\">\n<h2>Appendix: the model</h2>\n";
  std::vector<std::vector<std::string>> facts{{"file", esc(p.source)}};
  for (const auto& [k, v] : p.facts) facts.push_back({esc(k), esc(v)});
  facts.push_back({"method", method == kin::Method::htm ? "exact (homogeneous transformations)"
                                                        : "first order"});
  facts.push_back({"grid", fmt::format("{} x {} x {} points over ({:g} .. {:g}, {:g} .. {:g}, {:g} "
                                       ".. {:g}) mm",
                                       p.grid.count[0], p.grid.count[1], p.grid.count[2],
                                       p.grid.min_mm[0], p.grid.max_mm[0], p.grid.min_mm[1],
                                       p.grid.max_mm[1], p.grid.min_mm[2], p.grid.max_mm[2])});
  body += table({"", ""}, facts, "kv");
  if (!p.components.empty()) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& r : p.components) {
      std::vector<std::string> e;
      for (const auto& c : r) e.push_back(esc(c));
      rows.push_back(e);
    }
    body += table({"error", "given as", "values", "source"}, rows);
  }
  body += "</div>\n";
  const std::string title = p.title.empty() ? "Volumetric error" : "Volumetric error: " + p.title;
  return fmt::format(
      "<!doctype html>\n<html lang=\"en\">\n<head>\n{}\n<meta charset=\"utf-8\">\n"
      "<title>{}</title>\n<style>{}{}</style>\n</head>\n<body>\n<h1>{}</h1>\n{}<footer>Generated "
      "by {} on {}. Plots drawn with PLplot. Self-contained: no external resources.</footer>\n"
      "</body>\n</html>\n",
      csp_meta(), esc(title), kCss, print_css(title), esc(title), body, esc(p.software), now_utc());
}

}  // namespace cal::daq::report
