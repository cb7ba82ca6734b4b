#include "report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>

#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/squareness.hpp"
#include "cal/analysis/straightness.hpp"
#include "cal/analysis/uncertainty.hpp"
#include "cal/daq/ballbar.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "iso230_2_output.hpp"
#include "plot.hpp"

namespace cal::daq::report {
namespace {

using nlohmann::json;
namespace st = cal::storage;
using Q = cal::drivers::Quantity;

// --- HTML helpers ----------------------------------------------------------------------------

std::string esc(std::string_view s) { return html_escape(s); }

std::string um(double v) { return fmt::format("{:.3f}", v); }

std::string iso_time(std::int64_t unix_ms) {
  const std::time_t s = unix_ms / 1000;
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf;
}

// `align`: one letter per column, 'r' right-aligns (numbers), anything else left; columns
// beyond it are right-aligned in a "num" table.
std::string table(const std::vector<std::string>& head,
                  const std::vector<std::vector<std::string>>& rows, std::string_view cls = "",
                  std::string_view align = "") {
  std::string h =
      fmt::format("<table{}><thead><tr>", cls.empty() ? "" : fmt::format(" class=\"{}\"", cls));
  for (const auto& c : head) h += "<th>" + c + "</th>";
  h += "</tr></thead><tbody>";
  const bool num = cls.find("num") != std::string_view::npos;
  for (const auto& r : rows) {
    h += "<tr>";
    for (std::size_t i = 0; i < r.size(); ++i) {
      const bool right = i < align.size() ? align[i] == 'r' : num;
      h += (right ? "<td class=\"r\">" : "<td>") + r[i] + "</td>";
    }
    h += "</tr>";
  }
  return h + "</tbody></table>\n";
}

std::string figure(std::string svg, std::string_view caption) {
  return fmt::format("<figure>{}<figcaption>{}</figcaption></figure>\n", svg, esc(caption));
}

// --- what is stored about a run ----------------------------------------------------------------

struct Series {
  std::string label;
  std::vector<double> t_min, value;
};

struct Environment {
  std::vector<Series> air_temperature, material_temperature, pressure_hpa, humidity, index;
  std::int64_t t0_ns = 0;
  bool empty() const {
    return air_temperature.empty() && material_temperature.empty() && pressure_hpa.empty() &&
           humidity.empty();
  }
};

struct RunView {
  st::RunRecord run;
  std::string machine;
  std::vector<st::InstrumentRecord> instruments;
  json settings;
  Environment env;
};

std::string instrument_name(const RunView& v, int device) {
  for (const auto& i : v.instruments)
    if (i.device == device) return i.driver;
  return fmt::format("device {}", device);
}

Environment load_environment(const st::Store& store, const RunView& v) {
  static constexpr std::uint8_t wanted[] = {
      static_cast<std::uint8_t>(Q::air_temperature_degc),
      static_cast<std::uint8_t>(Q::air_pressure_pa), static_cast<std::uint8_t>(Q::air_humidity_pct),
      static_cast<std::uint8_t>(Q::refractive_index),
      static_cast<std::uint8_t>(Q::material_temperature_degc)};
  const auto readings = store.readings(v.run.id, wanted);
  Environment env;
  if (readings.empty()) return env;
  env.t0_ns = readings.front().time_ns;
  std::map<std::tuple<int, int, int>, Series> by_source;
  for (const auto& r : readings) {
    if (r.status != 0) continue;  // flagged values are not measurements
    auto& s = by_source[{r.quantity, r.device, r.channel}];
    s.t_min.push_back(static_cast<double>(r.time_ns - env.t0_ns) / 60e9);
    s.value.push_back(static_cast<Q>(r.quantity) == Q::air_pressure_pa ? r.value / 100.0 : r.value);
  }
  for (auto& [key, s] : by_source) {
    const auto [q, device, channel] = key;
    s.label = fmt::format("{} ch {}", instrument_name(v, device), channel);
    switch (static_cast<Q>(q)) {
      case Q::air_temperature_degc:
        env.air_temperature.push_back(std::move(s));
        break;
      case Q::air_pressure_pa:
        env.pressure_hpa.push_back(std::move(s));
        break;
      case Q::air_humidity_pct:
        env.humidity.push_back(std::move(s));
        break;
      case Q::refractive_index:
        env.index.push_back(std::move(s));
        break;
      default:
        env.material_temperature.push_back(std::move(s));
        break;
    }
  }
  return env;
}

RunView load(const st::Store& store, std::int64_t id) {
  const auto run = store.run(id);
  if (!run)
    throw cal::InputError(fmt::format("{}: no run {} (see daq runs)", store.path().string(), id));
  RunView v{.run = *run};
  if (run->machine_id > 0)
    if (const auto m = store.machine(run->machine_id)) v.machine = m->name;
  v.instruments = store.instruments(id);
  v.settings = json::parse(run->settings_json, nullptr, false);
  if (v.settings.is_discarded()) v.settings = json::object();
  v.env = load_environment(store, v);
  return v;
}

struct Stats {
  double min = 0, mean = 0, max = 0;
  std::size_t n = 0;
};
Stats stats(const std::vector<Series>& series) {
  Stats s{.min = INFINITY, .max = -INFINITY};
  double sum = 0;
  for (const auto& x : series)
    for (double v : x.value) {
      s.min = std::min(s.min, v);
      s.max = std::max(s.max, v);
      sum += v;
      ++s.n;
    }
  if (s.n) s.mean = sum / static_cast<double>(s.n);
  return s;
}

// At most `limit` points per series in a plot (every k-th): a plot cannot show more.
std::vector<Line> lines_of(const std::vector<Series>& series, std::size_t first_colour,
                           std::size_t limit = 1500) {
  std::vector<Line> out;
  for (std::size_t i = 0; i < series.size(); ++i) {
    const auto& s = series[i];
    const std::size_t step = std::max<std::size_t>(1, s.t_min.size() / limit);
    Line l{.label = s.label, .colour = palette(first_colour + i), .width = 1.2};
    for (std::size_t k = 0; k < s.t_min.size(); k += step) {
      l.x.push_back(s.t_min[k]);
      l.y.push_back(s.value[k]);
    }
    out.push_back(std::move(l));
  }
  return out;
}

// --- sections shared by every kind ---------------------------------------------------------------

std::string run_title(const RunView& v) {
  const std::string what = v.run.kind == "linear"    ? "Positioning test (ISO 230-2)"
                           : v.run.kind == "circle"  ? "Circular test (ISO 230-4, ballbar)"
                           : v.run.kind == "dynamic" ? "Dynamic capture"
                                                     : v.run.kind + " test";
  return fmt::format("Run {}: {}, axis {}", v.run.id, what, v.run.axis);
}

// A setting as an engineer reads it: strings without quotes, numbers without binary noise
// (42.678000000000004 is 42.678), arrays as lists.
std::string setting_text(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) return fmt::format("{:.10g}", v.get<double>());
  if (v.is_array()) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + setting_text(x);
    return s;
  }
  return v.dump();
}

std::string setup_section(const RunView& v) {
  std::vector<std::vector<std::string>> rows = {
      {"Machine", esc(v.machine.empty() ? "(not recorded)" : v.machine)},
      {"Campaign", esc(v.run.campaign)},
      {"Started", iso_time(v.run.started_unix_ms)},
      {"Ended", v.run.ended_unix_ms ? iso_time(*v.run.ended_unix_ms) : "(not ended)"},
      {"Status", std::string(st::to_string(v.run.status)) +
                     (v.run.note.empty() ? "" : " &mdash; " + esc(v.run.note))},
      {"Software", esc(v.run.software_version)},
      {"Capture file", esc(v.run.capture_path.empty() ? "(none)" : v.run.capture_path)}};
  std::string h = "<h3>Test set-up</h3>\n" + table({"", ""}, rows, "kv");
  std::vector<std::vector<std::string>> settings;
  for (const auto& [k, val] : v.settings.items()) {
    if (val.is_object()) {
      for (const auto& [k2, v2] : val.items())
        settings.push_back({esc(k + "." + k2), esc(setting_text(v2))});
    } else {
      settings.push_back({esc(k), esc(setting_text(val))});
    }
  }
  if (!settings.empty()) h += "<h4>Settings</h4>\n" + table({"setting", "value"}, settings, "kv");
  std::vector<std::vector<std::string>> inst;
  for (const auto& i : v.instruments)
    inst.push_back({std::to_string(i.device), esc(i.driver), esc(i.transport)});
  if (!inst.empty())
    h += "<h4>Instruments</h4>\n" + table({"device", "instrument", "connection"}, inst);
  return h;
}

std::string environment_section(const Environment& env) {
  std::string h = "<h3>Environment</h3>\n";
  if (env.empty()) return h + "<p>No environment readings were stored with this run.</p>\n";
  std::vector<std::vector<std::string>> rows;
  const auto row = [&](const char* name, const std::vector<Series>& s, const char* unit, int d) {
    if (s.empty()) return;
    const auto x = stats(s);
    rows.push_back({name, fmt::format("{:.{}f}", x.min, d), fmt::format("{:.{}f}", x.mean, d),
                    fmt::format("{:.{}f}", x.max, d), unit, std::to_string(x.n)});
  };
  row("Air temperature", env.air_temperature, "°C", 3);
  row("Material temperature", env.material_temperature, "°C", 3);
  row("Air pressure", env.pressure_hpa, "hPa", 2);
  row("Relative humidity", env.humidity, "%RH", 1);
  row("Refractive index (instrument)", env.index, "", 9);
  h += table({"quantity", "min", "mean", "max", "unit", "samples"}, rows, "num", "lrrrlr");
  auto temps = lines_of(env.air_temperature, 0);
  for (auto& l : lines_of(env.material_temperature, 1)) {
    l.label = "material " + l.label;
    l.dashed = true;
    temps.push_back(std::move(l));
  }
  for (auto& l : temps)
    if (!l.dashed) l.label = "air " + l.label;
  h += figure(svg(XyChart{.title = "Temperatures",
                          .x_label = "time (min)",
                          .y_label = "temperature (°C)",
                          .lines = temps,
                          .height_pt = 300}),
              "Air and material temperature during the run.");
  if (!env.pressure_hpa.empty())
    h += figure(svg(XyChart{.title = "Air pressure",
                            .x_label = "time (min)",
                            .y_label = "pressure (hPa)",
                            .lines = lines_of(env.pressure_hpa, 2),
                            .height_pt = 260}),
                "Air pressure during the run.");
  if (!env.humidity.empty())
    h += figure(svg(XyChart{.title = "Relative humidity",
                            .x_label = "time (min)",
                            .y_label = "humidity (%RH)",
                            .lines = lines_of(env.humidity, 5),
                            .height_pt = 260}),
                "Relative humidity during the run.");
  return h;
}

// Headline numbers of a run, for the campaign summary and the comparison trends.
struct Headline {
  std::vector<std::pair<std::string, double>> values_um;  // symbol, value
  std::string standard;
};

// --- ISO 230-2
// ------------------------------------------------------------------------------------

struct Linear {
  std::vector<st::CapturedTarget> targets;
  cal::iso230_2::Evaluation e;
};

Linear evaluate_linear(const st::Store& store, const RunView& v, const Options& o) {
  Linear l{.targets = store.targets(v.run.id)};
  if (l.targets.empty())
    throw cal::InputError(fmt::format("{}: run {} has no captured targets to report",
                                      store.path().string(), v.run.id));
  const std::string key =
      !o.standard.empty() ? o.standard : v.settings.value("standard", "iso230-2:2014");
  try {
    l.e = cal::iso230_2::evaluate(::daq::measurements(l.targets),
                                  cal::iso230_2::standard_from_string(key));
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: run {} ({} captured stops): {}", store.path().string(),
                                      v.run.id, l.targets.size(), e.what()));
  }
  return l;
}

// The budget of ISO 230-2 Annex A for this run's travel and measured air; what was not
// measured is stated in the report, not hidden.
cal::unc::Budget linear_budget(const RunView& v, const Linear& l, double& length_m) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& t : l.targets) lo = std::min(lo, t.nominal_mm), hi = std::max(hi, t.nominal_mm);
  length_m = std::max((hi - lo) * 1e-3, 1e-3);
  cal::unc::PositioningSetup s{.length_m = length_m};
  const auto& env = v.settings.contains("environment") ? v.settings["environment"] : json::object();
  s.equation = cal::air::equation_from_string(env.value("equation", "ciddor"));
  s.alpha_per_k = env.value("expansion_ppm_per_k", 11.5) * 1e-6;
  if (!v.env.air_temperature.empty()) s.air.temperature_degc = stats(v.env.air_temperature).mean;
  if (!v.env.pressure_hpa.empty()) s.air.pressure_pa = stats(v.env.pressure_hpa).mean * 100.0;
  if (!v.env.humidity.empty())
    s.air.humidity = cal::air::Humidity::relative_pct(stats(v.env.humidity).mean);
  s.air.co2_umol_per_mol = env.value("co2_umol_per_mol", 450.0);
  s.air.wavelength_vacuum_nm = env.value("wavelength_nm", 632.991);
  if (!v.env.material_temperature.empty()) s.material_degc = stats(v.env.material_temperature).mean;
  return cal::unc::positioning_budget(s);
}

std::string linear_plots(const Linear& l) {
  const auto& e = l.e;
  std::vector<double> x, up, down, bi, up_lo, up_hi, down_lo, down_hi;
  for (const auto& t : e.targets) {
    x.push_back(t.target_mm);
    up.push_back(t.mean_up_um);
    up_lo.push_back(t.mean_up_um - 2 * t.s_up_um);
    up_hi.push_back(t.mean_up_um + 2 * t.s_up_um);
    down.push_back(t.mean_down_um);
    down_lo.push_back(t.mean_down_um - 2 * t.s_down_um);
    down_hi.push_back(t.mean_down_um + 2 * t.s_down_um);
    bi.push_back(t.mean_bi_um);
  }
  XyChart means{.title = "Mean positional deviation with ±2s",
                .x_label = "target position (mm)",
                .y_label = "deviation (µm)",
                .zero_line = true};
  means.bands.push_back({.x = x, .lo = up_lo, .hi = up_hi, .label = "↑ ±2s", .colour = blue});
  means.lines.push_back({.x = x, .y = up, .label = "x̄↑", .colour = blue, .markers = true});
  if (e.bidirectional) {
    means.bands.push_back(
        {.x = x, .lo = down_lo, .hi = down_hi, .label = "↓ ±2s", .colour = vermilion});
    means.lines.push_back({.x = x, .y = down, .label = "x̄↓", .colour = vermilion, .markers = true});
    means.lines.push_back({.x = x,
                           .y = bi,
                           .label = "x̄ (bidirectional)",
                           .colour = black,
                           .width = 1.0,
                           .dashed = true});
  }
  std::string h = figure(svg(means),
                         "Mean unidirectional positional deviations x̄i↑ and x̄i↓ at each target, "
                         "with the bands x̄ ± 2s (s: the estimator of the unidirectional "
                         "repeatability), and the mean bidirectional deviation.");
  // Run by run: one line per run and direction, in the order of the targets.
  std::map<std::pair<int, char>, std::vector<std::pair<double, double>>> runs;
  for (const auto& t : l.targets)
    runs[{t.run_number, t.direction}].push_back({t.nominal_mm, t.deviation_um});
  XyChart traces{.title = "Run-by-run deviations",
                 .x_label = "target position (mm)",
                 .y_label = "deviation (µm)",
                 .zero_line = true};
  for (auto& [key, pts] : runs) {
    std::sort(pts.begin(), pts.end());
    Line line{.label = fmt::format("run {} {}", key.first, key.second == '+' ? "↑" : "↓"),
              .colour = palette(static_cast<std::size_t>(key.first - 1)),
              .width = 1.0,
              .dashed = key.second == '-',
              .markers = true};
    for (const auto& [px, py] : pts) line.x.push_back(px), line.y.push_back(py);
    traces.lines.push_back(std::move(line));
  }
  return h + figure(svg(traces),
                    "Every captured deviation x_ij: solid lines approach in the "
                    "positive direction (↑), dashed lines in the negative (↓).");
}

std::string linear_section(const st::Store& store, const RunView& v, const Options& o,
                           Headline& headline) {
  const auto l = evaluate_linear(store, v, o);
  const auto& e = l.e;
  headline.standard = std::string(e.standard.title);
  std::string h = fmt::format(
      "<h3>Results: {}</h3>\n<p class=\"standard\">Evaluated by <strong>{}</strong> ({}). {} "
      "targets, {} runs per direction, {}.</p>\n",
      esc(e.standard.title), esc(e.standard.title), esc(e.standard.note), e.targets.size(), e.runs,
      e.bidirectional ? "bidirectional" : "unidirectional");
  std::vector<std::vector<std::string>> axis;
  for (const auto& a : e.axis) {
    axis.push_back({esc(a.symbol), um(a.value_um), esc(a.description)});
    headline.values_um.push_back({a.symbol, a.value_um});
  }
  h += table({"symbol", "value (µm)", "meaning"}, axis, "num results", "lrl");
  h += linear_plots(l);
  std::vector<std::string> head{"target (mm)"};
  for (const auto& p : e.per_target) head.push_back(esc(p.symbol) + " (µm)");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < e.targets.size(); ++i) {
    std::vector<std::string> r{fmt::format("{:.3f}", e.targets[i].target_mm)};
    for (const auto& p : e.per_target) r.push_back(um(p.values_um[i]));
    rows.push_back(std::move(r));
  }
  h += "<h4>Per target</h4>\n" + table(head, rows, "num");
  for (const auto& w : e.warnings) h += "<p class=\"warning\">Warning: " + esc(w) + "</p>\n";

  double length_m = 0;
  const auto b = linear_budget(v, l, length_m);
  std::vector<std::vector<std::string>> contrib;
  for (const auto& c : b.contributors)
    contrib.push_back({esc(c.name), fmt::format("{:.4f}", c.u_um), esc(c.model)});
  h += fmt::format(
      "<h3>Measurement uncertainty</h3>\n<p>Of a positional deviation at the measured travel "
      "L = {:.3f} m (ISO 230-2 Annex A, ISO/TR 230-9): combined standard uncertainty "
      "u<sub>c</sub> = {:.4f} µm, <strong>expanded uncertainty U = {:.3f} µm (k = {:g})</strong>."
      "</p>\n",
      length_m, b.u_combined_um, b.expanded_um, b.k);
  h += table({"contributor", "u (µm)", "model"}, contrib, "num", "lrl");
  h += "<p class=\"note\">Air and material values are the means measured during this run. "
       "Assumed, not measured with the run: laser certificate 0.1 ppm (k = 2), sensor standard "
       "uncertainties 0.1 K, 10 Pa, 2 %RH, expansion coefficient ±1 ppm/K; no environmental "
       "variation (drift) test, misalignment or dead path was recorded, so they are not in the "
       "budget. Use <code>daq uncertainty</code> with the actual values to revise it.</p>\n";
  for (const auto& w : b.warnings) h += "<p class=\"warning\">Warning: " + esc(w) + "</p>\n";
  headline.values_um.push_back({"U (k=2)", b.expanded_um});
  return h;
}

// --- ISO 230-4
// --------------------------------------------------------------------------------------

struct Circle {
  cal::daq::BallbarProgram program;
  ::daq::BallbarAnalysis analysis;
  std::vector<cal::circle::Trace> traces;
  cal::circle::Result result;
};

Circle analyse_circle(const st::Store& store, const RunView& v) {
  if (!v.settings.contains("radius_mm"))
    throw cal::InputError(fmt::format("{}: run {}: its circle settings are missing",
                                      store.path().string(), v.run.id));
  auto [program, analysis] = ::daq::circle_settings_from_json(v.settings);
  static constexpr std::uint8_t bar[] = {static_cast<std::uint8_t>(Q::length_m)};
  std::vector<double> bar_mm;
  for (const auto& r : store.readings(v.run.id, bar)) bar_mm.push_back(r.value * 1e3);
  Circle c{.program = program, .analysis = analysis};
  try {
    cal::daq::BallbarSegmenter segmenter(program);
    for (double x : bar_mm) segmenter.add(x);
    c.traces = segmenter.traces();
    c.result = ::daq::analyse_ballbar(program, analysis, bar_mm);
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: run {} ({} bar readings): {}", store.path().string(),
                                      v.run.id, bar_mm.size(), e.what()));
  }
  return c;
}

PolarChart polar_of(const Circle& c, std::string_view title, std::size_t colour_offset,
                    std::string_view label_prefix) {
  const std::string plane = c.analysis.plane.size() == 2 ? c.analysis.plane : "XY";
  PolarChart p{.title = std::string(title),
               .first_axis = plane.substr(0, 1),
               .second_axis = plane.substr(1, 1)};
  // The least-squares centre is a set-up error (where the pivot was put), not the
  // machine's: it is removed, as ISO 230-4 evaluates about that centre.
  const double cu = c.result.iso.centre_u_um, cv = c.result.iso.centre_v_um;
  for (const auto& t : c.traces) {
    Line l{
        .label = std::string(label_prefix) +
                 (t.direction == cal::circle::Direction::ccw ? "counter-clockwise" : "clockwise"),
        .colour = palette(colour_offset + (t.direction == cal::circle::Direction::ccw ? 0 : 1)),
        .width = 1.2};
    // At most ~3600 points a trace (0.1 degree): more cannot be seen, and would bloat the file.
    const std::size_t step = std::max<std::size_t>(1, t.angle_deg.size() / 3600);
    for (std::size_t i = 0; i < t.angle_deg.size(); i += step) {
      const double th = t.angle_deg[i] * std::numbers::pi / 180.0;
      l.x.push_back(t.angle_deg[i]);
      l.y.push_back(t.deviation_um[i] - cu * std::cos(th) - cv * std::sin(th));
    }
    p.traces.push_back(std::move(l));
  }
  return p;
}

std::string circle_section(const st::Store& store, const RunView& v, Headline& headline) {
  const auto c = analyse_circle(store, v);
  const auto& r = c.result;
  headline.standard = "ISO 230-4:2005";
  std::string h = fmt::format(
      "<h3>Results: ISO 230-4:2005</h3>\n<p class=\"standard\">Evaluated by <strong>ISO "
      "230-4:2005</strong> (circular tests for numerically controlled machine tools); radius "
      "{:g} mm, feed {:g} mm/min, plane {}, both directions from the stored bar readings.</p>\n",
      c.program.radius_mm, c.program.feed_mm_per_min, esc(c.analysis.plane));
  const std::vector<std::vector<std::string>> iso = {
      {"G", um(r.iso.G_bi_um), "circular deviation, both directions"},
      {"G (cw)", um(r.iso.G_cw_um), "circular deviation, clockwise"},
      {"G (ccw)", um(r.iso.G_ccw_um), "circular deviation, counter-clockwise"},
      {"H", um(r.iso.H_um), "circular hysteresis"},
      {"F max", um(r.iso.F_max_um), "largest radial deviation from the nominal radius"},
      {"F min", um(r.iso.F_min_um), "smallest radial deviation from the nominal radius"},
      {"centre", fmt::format("{} / {}", um(r.iso.centre_u_um), um(r.iso.centre_v_um)),
       "least-squares centre relative to the pivot (set-up)"}};
  headline.values_um = {{"G", r.iso.G_bi_um}, {"H", r.iso.H_um}};
  h += table({"symbol", "value (µm)", "meaning"}, iso, "num results", "lrl");
  h += figure(svg(polar_of(c, "Polar plot, least-squares centre removed", 0, "")),
              "Radial deviation of both directions around the nominal circle (magnified; the "
              "scale is the deviation per ring).");
  std::vector<std::vector<std::string>> diag;
  for (std::size_t i = 0; i < r.diagnostics.size(); ++i) {
    const auto& d = r.diagnostics[i];
    diag.push_back({std::to_string(i + 1), esc(d.name), fmt::format("{:.3f} {}", d.value, d.unit),
                    um(d.pv_um), fmt::format("{:.1f}", d.share_pct), um(d.g_reduction_um)});
    if (i < 4) headline.values_um.push_back({d.name, d.pv_um});
  }
  h += "<h4>Diagnostics, ranked</h4>\n" +
       table({"rank", "error", "value", "PV (µm)", "share of G (%)", "G gained if removed (µm)"},
             diag, "num", "rlrrrr");
  for (const auto& n : r.notes) h += "<p class=\"note\">" + esc(n) + "</p>\n";
  h += fmt::format(
      "<h3>Measurement uncertainty</h3>\n<p>The error model leaves a residual of {:.3f} µm rms "
      "(noise and what the model does not describe). The ballbar's calibration (its "
      "calibrated length and transducer certificate) is not recorded with the run, so an "
      "expanded uncertainty of G is not evaluated here; {}.</p>\n",
      r.residual_rms_um,
      c.analysis.calibrated_radius_mm ? fmt::format("the calibrated length {:.4f} mm was used",
                                                    *c.analysis.calibrated_radius_mm)
      : c.analysis.uncalibrated
          ? "the radius was not calibrated: F and the radius error are not valid"
          : "the nominal radius was taken as the bar length");
  return h;
}

// --- other runs (e.g. imported dynamic captures)
// --------------------------------------------------

std::string generic_section(const st::Store& store, const RunView& v) {
  const auto readings = store.readings(v.run.id);
  std::map<std::tuple<int, int, int>, Series> by;
  const std::int64_t t0 = readings.empty() ? 0 : readings.front().time_ns;
  for (const auto& r : readings) {
    auto& s = by[{r.quantity, r.device, r.channel}];
    s.label = fmt::format("{} {} ch {}", instrument_name(v, r.device),
                          cal::drivers::to_string(static_cast<Q>(r.quantity)), r.channel);
    s.t_min.push_back(static_cast<double>(r.time_ns - t0) / 60e9);
    s.value.push_back(r.value);
  }
  std::string h = fmt::format("<h3>Readings</h3>\n<p>{} readings stored.</p>\n", readings.size());
  std::size_t i = 0;
  for (auto& [key, s] : by) {
    const auto q = static_cast<Q>(std::get<0>(key));
    if (q == Q::air_temperature_degc || q == Q::air_pressure_pa || q == Q::air_humidity_pct ||
        q == Q::material_temperature_degc || q == Q::refractive_index)
      continue;
    h += figure(svg(XyChart{.title = s.label,
                            .x_label = "time (min)",
                            .y_label = std::string(cal::drivers::to_string(q)),
                            .lines = lines_of({s}, i++, 4000)}),
                s.label + " over the run.");
  }
  return h;
}

// --- pages ---------------------------------------------------------------------------------------

constexpr std::string_view css = R"(
body { font-family: "DejaVu Sans", system-ui, sans-serif; margin: 2rem auto; max-width: 60rem;
       color: #111; line-height: 1.4; padding: 0 1rem; }
h1 { font-size: 1.6rem; border-bottom: 2px solid #0072b2; padding-bottom: .3rem; }
h2 { font-size: 1.3rem; margin-top: 2.5rem; border-bottom: 1px solid #ccc; }
h3 { font-size: 1.1rem; margin-top: 1.8rem; } h4 { font-size: 1rem; }
table { border-collapse: collapse; margin: .5rem 0 1rem; font-size: .9rem; }
th, td { border: 1px solid #ccc; padding: .2rem .5rem; vertical-align: top; }
th { background: #f0f4f8; text-align: left; }
td.r { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td { overflow-wrap: anywhere; }
table.kv td:first-child { color: #555; }
table.kv thead { display: none; }
table.results td:first-child { font-weight: bold; }
figure { margin: 1rem 0; page-break-inside: avoid; break-inside: avoid; }
svg.plot { width: 100%; height: auto; max-width: 52rem; display: block; }
figcaption { font-size: .85rem; color: #444; }
.warning { color: #a40; } .note { color: #444; font-size: .9rem; }
.simulated { background: #fff3cd; border: 1px solid #e0b000; padding: .5rem; }
footer { margin-top: 3rem; font-size: .8rem; color: #666; border-top: 1px solid #ccc; }
@page { size: A4; margin: 14mm; }
@media print { body { margin: 0; max-width: none; } h2 { page-break-before: always; } }
)";

std::string page(std::string_view title, const std::string& body, const Options& o) {
  const auto now_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                          std::chrono::system_clock::now().time_since_epoch())
                          .count();
  return fmt::format(
      "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n"
      "<style>{}</style>\n</head>\n<body>\n<h1>{}</h1>\n{}<footer>Generated by {} on {}. Plots "
      "drawn with PLplot. Self-contained: no external resources.</footer>\n</body>\n</html>\n",
      esc(title), css, esc(title), body, esc(o.software), iso_time(now_ms));
}

bool simulated(const RunView& v) {
  const auto has = [](std::string_view s) {
    return s.find("SIMULATED") != std::string::npos || s.find("simulated") != std::string::npos;
  };
  if (has(v.machine) || has(v.run.campaign)) return true;
  return std::any_of(v.instruments.begin(), v.instruments.end(),
                     [&](const auto& i) { return has(i.driver) || has(i.transport); });
}

std::string run_body(const st::Store& store, const RunView& v, const Options& o, Headline& hl) {
  std::string h;
  if (simulated(v))
    h += "<p class=\"simulated\">This run was made on the <strong>simulated</strong> machine "
         "and instruments: the numbers show what the software measures, not a real machine.</p>\n";
  if (v.run.status != st::RunStatus::complete)
    h += fmt::format(
        "<p class=\"warning\">This run is {}{}: the results cover only what was "
        "stored.</p>\n",
        st::to_string(v.run.status), v.run.note.empty() ? "" : " (" + esc(v.run.note) + ")");
  h += setup_section(v);
  // An aborted or interrupted run may hold too little to evaluate: the report still shows what
  // was stored, and says why there are no results.
  try {
    if (v.run.kind == "linear")
      h += linear_section(store, v, o, hl);
    else if (v.run.kind == "circle")
      h += circle_section(store, v, hl);
    else
      h += generic_section(store, v);
  } catch (const cal::InputError& e) {
    h += fmt::format(
        "<h3>Results</h3>\n<p class=\"warning\">The results cannot be evaluated: "
        "{}</p>\n",
        esc(e.what()));
  }
  h += environment_section(v.env);
  return h;
}

std::string date_of(const RunView& v) { return iso_time(v.run.started_unix_ms).substr(0, 10); }

}  // namespace

std::string run_report(const st::Store& store, std::int64_t run, const Options& o) {
  const auto v = load(store, run);
  Headline hl;
  return page(run_title(v), run_body(store, v, o, hl), o);
}

std::string campaign_report(const st::Store& store, std::span<const std::int64_t> runs,
                            std::string_view title, const Options& o) {
  if (runs.empty()) throw cal::InputError("campaign report: no runs to report");
  std::vector<std::vector<std::string>> summary;
  std::string sections;
  for (const auto id : runs) {
    const auto v = load(store, id);
    Headline hl;
    const auto body = run_body(store, v, o, hl);
    std::string numbers;
    for (const auto& [k, val] : hl.values_um)
      if (numbers.size() < 400) numbers += fmt::format("{} {} µm; ", esc(k), um(val));
    summary.push_back({fmt::format("<a href=\"#run-{}\">{}</a>", id, id), date_of(v),
                       esc(v.run.kind), esc(v.run.axis), std::string(st::to_string(v.run.status)),
                       esc(hl.standard), numbers});
    sections += fmt::format("<h2 id=\"run-{}\">{}</h2>\n{}", id, esc(run_title(v)), body);
  }
  const std::string body =
      fmt::format("<p>{} runs.</p>\n", runs.size()) +
      table({"run", "date", "test", "axis", "status", "standard", "results"}, summary, "", "r") +
      sections;
  return page(title, body, o);
}

std::string comparison_report(const st::Store& store, std::span<const std::int64_t> runs,
                              const Options& o) {
  if (runs.size() < 2) throw cal::InputError("comparison report: give at least two runs");
  std::vector<RunView> views;
  for (const auto id : runs) views.push_back(load(store, id));
  std::sort(views.begin(), views.end(), [](const auto& a, const auto& b) {
    return a.run.started_unix_ms < b.run.started_unix_ms;
  });
  const auto& first = views.front();
  for (const auto& v : views)
    if (v.run.kind != first.run.kind || v.run.axis != first.run.axis)
      throw cal::InputError(fmt::format(
          "comparison report: run {} is a {} test of axis {}, run {} a {} test of axis {}; "
          "compare the same test",
          first.run.id, first.run.kind, first.run.axis, v.run.id, v.run.kind, v.run.axis));
  if (first.run.kind != "linear" && first.run.kind != "circle")
    throw cal::InputError(
        fmt::format("comparison report: {} runs cannot be compared (linear and circle runs can)",
                    first.run.kind));

  const double day0_ms = static_cast<double>(first.run.started_unix_ms);
  std::map<std::string, Line> trends;  // symbol -> value over days
  std::vector<std::string> trend_order;
  std::vector<std::vector<std::string>> rows;
  std::string overlays;
  XyChart overlay{.title = "Mean bidirectional deviation, run by run",
                  .x_label = "target position (mm)",
                  .y_label = "deviation (µm)",
                  .zero_line = true};
  std::vector<PolarChart> polars;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const auto& v = views[i];
    Headline hl;
    const std::string label = fmt::format("run {} ({})", v.run.id, date_of(v));
    if (v.run.kind == "linear") {
      const auto l = evaluate_linear(store, v, o);
      Line line{.label = label, .colour = palette(i), .width = 1.4, .markers = true};
      for (const auto& t : l.e.targets)
        line.x.push_back(t.target_mm), line.y.push_back(t.mean_bi_um);
      overlay.lines.push_back(std::move(line));
      hl.standard = std::string(l.e.standard.title);
      for (const auto& a : l.e.axis) hl.values_um.push_back({a.symbol, a.value_um});
    } else {
      const auto c = analyse_circle(store, v);
      polars.push_back(polar_of(c, "", 2 * i, label + " "));
      hl.values_um = {{"G", c.result.iso.G_bi_um}, {"H", c.result.iso.H_um}};
      for (const auto& d : c.result.diagnostics)
        if (d.key == "squareness" || d.key == "backlash_X" || d.key == "backlash_Y" ||
            d.key == "servo_mismatch" || d.key == "scale_mismatch")
          hl.values_um.push_back({d.name + " (PV)", d.pv_um});
    }
    const double day = (static_cast<double>(v.run.started_unix_ms) - day0_ms) / 86'400'000.0;
    std::vector<std::string> row{std::to_string(v.run.id), date_of(v)};
    for (const auto& [k, val] : hl.values_um) {
      if (!trends.count(k)) {
        trend_order.push_back(k);
        trends[k] = Line{.label = k, .colour = palette(trend_order.size() - 1), .markers = true};
      }
      trends[k].x.push_back(day);
      trends[k].y.push_back(val);
      row.push_back(um(val));
    }
    const auto air = stats(v.env.air_temperature), mat = stats(v.env.material_temperature);
    row.push_back(air.n ? fmt::format("{:.2f}", air.mean) : "&ndash;");
    row.push_back(mat.n ? fmt::format("{:.2f}", mat.mean) : "&ndash;");
    rows.push_back(std::move(row));
  }
  std::vector<std::string> head{"run", "date"};
  for (const auto& k : trend_order) head.push_back(esc(k) + " (µm)");
  head.push_back("air (°C)");
  head.push_back("material (°C)");
  std::string body = fmt::format(
      "<p>The same test ({} of axis {}) on {} occasions, from {} to {}.</p>\n", esc(first.run.kind),
      esc(first.run.axis), views.size(), date_of(first), date_of(views.back()));
  body += table(head, rows, "num");
  if (first.run.kind == "linear") {
    body += figure(svg(overlay),
                   "The mean bidirectional positional deviation x̄i of each run "
                   "at each target: a change of shape or slope shows wear, a "
                   "changed compensation or a thermal state.");
  } else {
    PolarChart all{.title = "Polar plots overlaid (least-squares centres removed)"};
    if (!polars.empty()) {
      all.first_axis = polars.front().first_axis;
      all.second_axis = polars.front().second_axis;
    }
    for (auto& p : polars)
      for (auto& t : p.traces) all.traces.push_back(std::move(t));
    body += figure(svg(all), "Both directions of every run on one scale.");
  }
  XyChart trend{.title = "Results over time",
                .x_label = fmt::format("days since {}", date_of(first)),
                .y_label = "value (µm)"};
  for (const auto& k : trend_order) trend.lines.push_back(trends[k]);
  body += figure(svg(trend), "Each result of the standard against the date of its run.");
  return page(fmt::format("Comparison: {} test of axis {}", first.run.kind, first.run.axis), body,
              o);
}

namespace {

struct Lines {
  std::vector<Line> lines;
  std::vector<std::vector<std::string>> rows;
};

// The profile and its reference lines: least squares and end point as lines, the minimum zone
// as its two parallel bounding lines.
Lines reference_lines(const Profile& p, std::size_t colour, std::string_view prefix) {
  namespace sl = cal::straightness;
  Lines out;
  double lo = INFINITY, hi = -INFINITY;
  for (double x : p.position_mm) lo = std::min(lo, x), hi = std::max(hi, x);
  out.lines.push_back({.x = p.position_mm,
                       .y = p.deviation_um,
                       .label = std::string(prefix) + "measured",
                       .colour = palette(colour),
                       .width = 1.6,
                       .markers = true});
  const struct {
    sl::Reference ref;
    Rgb colour;
    const char* name;
  } refs[] = {{sl::Reference::least_squares, grey, "least squares"},
              {sl::Reference::end_point, orange, "end point"},
              {sl::Reference::minimum_zone, green, "minimum zone"}};
  for (const auto& r : refs) {
    const auto res = sl::evaluate(p.position_mm, p.deviation_um, r.ref);
    const auto at = [&](double x_mm, double offset) {
      return res.intercept_um + res.slope_um_per_m * x_mm * 1e-3 + offset;
    };
    const double rmin = *std::min_element(res.residual_um.begin(), res.residual_um.end());
    const double rmax = *std::max_element(res.residual_um.begin(), res.residual_um.end());
    if (r.ref == sl::Reference::minimum_zone) {
      for (const double off : {rmin, rmax})
        out.lines.push_back({.x = {lo, hi},
                             .y = {at(lo, off), at(hi, off)},
                             .label = off == rmin ? std::string(prefix) + r.name : "",
                             .colour = r.colour,
                             .width = 1.0,
                             .dashed = true});
    } else {
      out.lines.push_back({.x = {lo, hi},
                           .y = {at(lo, 0), at(hi, 0)},
                           .label = std::string(prefix) + r.name,
                           .colour = r.colour,
                           .width = 1.0});
    }
    out.rows.push_back({std::string(prefix) + r.name, um(res.straightness_um),
                        fmt::format("{:.3f}", res.slope_um_per_m), um(res.intercept_um)});
  }
  return out;
}

}  // namespace

std::string straightness_report(const Profile& p, const Options& o) {
  const auto l = reference_lines(p, 0, "");
  std::string body = fmt::format(
      "<p class=\"standard\">Straightness by <strong>ISO 230-1:2012</strong> from {} points "
      "measured in <code>{}</code>: the range of the deviations from each reference line.</p>\n",
      p.position_mm.size(), esc(p.source));
  body += table({"reference line", "straightness (µm)", "slope (µm/m)", "intercept (µm)"}, l.rows,
                "num results", "lrrr");
  body += figure(svg(XyChart{.title = "Straightness deviations and reference lines",
                             .x_label = "position (mm)",
                             .y_label = "deviation (µm)",
                             .lines = l.lines}),
                 "The measured deviations with the least-squares and end-point lines, and the two "
                 "parallel lines of the minimum zone (dashed) that enclose every point.");
  return page("Straightness", body, o);
}

std::string squareness_report(const Profile& a, const Profile& b, double square_error,
                              const Options& o) {
  const auto r = cal::squareness::from_straightness({a.position_mm, a.deviation_um},
                                                    {b.position_mm, b.deviation_um}, square_error);
  const auto la = reference_lines(a, 0, "A: "), lb = reference_lines(b, 1, "B: ");
  std::string body = fmt::format(
      "<p class=\"standard\">Squareness by <strong>ISO 230-1:2012</strong> from two straightness "
      "runs against one square: <code>{}</code> moving A (deviation in +B) and <code>{}</code> "
      "moving B (deviation in +A); the square's own error {:+.3f} µm/m is removed.</p>\n",
      esc(a.source), esc(b.source), square_error);
  body += table({"result", "value", ""},
                {{"squareness", fmt::format("{:+.3f} µm/m", r.squareness_um_per_m),
                  "positive: the angle between the positive axis directions exceeds 90°"},
                 {"", fmt::format("{:+.3f}″", r.arcsec()), "arc seconds"}},
                "num results", "lrl");
  auto rows = la.rows;
  rows.insert(rows.end(), lb.rows.begin(), lb.rows.end());
  body += "<h3>The two runs</h3>\n" +
          table({"run, reference line", "straightness (µm)", "slope (µm/m)", "intercept (µm)"},
                rows, "num", "lrrr");
  body += figure(svg(XyChart{.title = "Run A: deviation in +B while A moves",
                             .x_label = "position along A (mm)",
                             .y_label = "deviation (µm)",
                             .lines = la.lines}),
                 "The slope of the least-squares line of each run enters the squareness.");
  body += figure(svg(XyChart{.title = "Run B: deviation in +A while B moves",
                             .x_label = "position along B (mm)",
                             .y_label = "deviation (µm)",
                             .lines = lb.lines}),
                 "The second run, with its reference lines.");
  return page("Squareness", body, o);
}

}  // namespace cal::daq::report
