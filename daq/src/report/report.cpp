#include "report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <ctime>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <regex>
#include <span>

#include "ballbar_campaign.hpp"
#include "cal/analysis/air.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/squareness.hpp"
#include "cal/analysis/straightness.hpp"
#include "cal/analysis/text.hpp"
#include "cal/analysis/uncertainty.hpp"
#include "cal/daq/ballbar.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "compensation/compensation_check.hpp"
#include "iso230_2_output.hpp"
#include "json_input.hpp"
#include "markup.hpp"
#include "model/model_build.hpp"
#include "model/stored_model.hpp"
#include "plot.hpp"
#include "provenance.hpp"
#include "result_rows.hpp"
#include "roles.hpp"
#include "run_quality.hpp"
#include "stored_profile.hpp"
#include "verdict.hpp"

namespace cal::daq::report {
namespace {

using nlohmann::json;
namespace st = cal::storage;
using Q = cal::drivers::Quantity;

// --- HTML helpers ----------------------------------------------------------------------------

// Every value from outside that goes into the HTML goes through this (markup.hpp).
std::string esc(std::string_view s) { return html_text(s); }

// Numbers and units as every output prints them (result_rows.hpp): never "-0.000".
std::string fixed(double v, int decimals) { return ::daq::number_text(v, decimals); }
std::string signed_text(double v, int decimals) { return ::daq::signed_number_text(v, decimals); }
std::string um(double v) { return fixed(v, 3); }
std::string unit_text(std::string_view u) { return ::daq::unit_html(u); }

std::string iso_time(std::int64_t unix_ms) {
  return cal::text::utc_text(unix_ms / 1000, "%Y-%m-%d %H:%M:%S UTC");
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
  std::string short_label;         // for a plot half the page wide ("PTU300 (SIM-PTU-0001)")
  int device = -1;                 // the instrument's (the same sensor in several plots)
  std::vector<double> t_s, value;  // t_s: seconds since the run's first reading
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
  json context;  // settings["context"] (provenance.hpp), or an empty object for older runs
  Environment env;
  std::vector<st::ResultRecord> results;
  std::vector<st::MissedStop> missed;
  std::vector<st::OperatorAction> actions;  // what the operator did during the run (issue 29)
  std::vector<st::Approval> approvals;      // sign-off of its results (issue 35)
  ::daq::CompensationUsed used;  // linear runs: what the stored deviations were made with
};

// How a positioning run's report names its units: a linear axis's mm and µm; a rotary axis's
// deg and arcsec (the runner carries its angles in the *_mm fields and stores each stop's
// deviation in arcsec: kinds/rotary.cpp).
struct AxisText {
  std::string_view position, deviation, x_label;
};
constexpr AxisText linear_text{"mm", "µm", "target position (mm)"};
constexpr AxisText rotary_text{"deg", "arcsec", "target angle (deg)"};

const AxisText& axis_text(const RunView& v) {
  return v.run.kind == "rotary" ? rotary_text : linear_text;
}

std::string ctx(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : "";
}

std::string instrument_name(const RunView& v, int device) {
  for (const auto& i : v.instruments)
    if (i.device == device) return i.driver;
  return fmt::format("device {}", device);
}

// The serial number a run stored with its instrument `device` itself, not from a configuration:
// an imported file's ("Serial No" of a Renishaw .rtx header, daq import); "" when none.
std::string stored_serial(const RunView& v, int device) {
  for (const auto& i : v.instruments)
    if (i.device == device) {
      const json s = json::parse(i.settings_json, nullptr, false);
      return s.is_object() ? ctx(s, "serial") : "";
    }
  return "";
}

// The configured instrument (the run's context) that stored instrument `device` is, or an empty
// object: by the name the run stored it under (its configured id), by its driver (a replay), or
// by its role where one configured instrument has it (a linear or circle run stores each
// instrument under its role: [devices.ids] with role "laser" is stored as "laser", and read
// "laser laser" in a legend). Two of one role (material thermometers) are not told apart here.
json configured_instrument(const RunView& v, int device) {
  const std::string stored = instrument_name(v, device);
  const auto list = v.context.value("instruments", json::array());
  if (!list.is_array()) return json::object();
  for (const char* key : {"id", "driver"})
    for (const auto& i : list)
      if (i.is_object() && ctx(i, key) == stored) return i;
  const auto same_role = [&](const json& i) { return ctx(i, "role") == stored; };
  const auto role = std::find_if(list.begin(), list.end(), same_role);
  if (role != list.end() && std::count_if(list.begin(), list.end(), same_role) == 1) return *role;
  return json::object();
}

// An instrument as a legend names it: its driver and serial number from the run's context
// ("ptu300 SIM-PTU-0001"), else the name it was given in the configuration.
std::string instrument_label(const RunView& v, int device) {
  const json i = configured_instrument(v, device);
  if (ctx(i, "driver").empty()) return instrument_name(v, device);
  const std::string serial = ctx(i, "serial_number");
  return ctx(i, "driver") + (serial.empty() ? "" : " " + serial);
}

// A plot's legend entry for a series of `device`: the instrument by its role, its product and
// serial number, and for an environment quantity the sensor ("air sensor PTU300 (serial
// SIM-PTU-0001)"; the laser's own air sensor "air sensor of laser IDS3010 (serial ...)", which
// read "air: ids3010"). `sensor`: "air" or "material" for those quantities, else "".
// `compact`: for a plot half the page wide, whose title names the quantity: the instrument and
// its serial number only ("laser IDS3010 (SIM-IDS-0001)", "PTU300 (SIM-PTU-0001)"); the full
// label (50 characters) was wider than such a plot.
std::string legend_label(const RunView& v, int device, int channel, std::string_view sensor,
                         bool compact = false) {
  const std::string stored = instrument_name(v, device);
  const json inst = configured_instrument(v, device);
  // No configured instrument names it (a simulated run of daq model, an imported file): its
  // stored name once, as its product where that is known ("IDS3010"), and the serial number its
  // file stated. The stored name is its role, or its file's instrument: taken as the product too,
  // it read "ballbar ballbar".
  if (inst.empty()) {
    const std::string product = ::daq::product_name(stored);
    const std::string name = product.empty() ? stored : product;
    std::string label =
        sensor.empty() || name == sensor ? name : fmt::format("{} sensor of {}", sensor, name);
    if (sensor == name) label += " sensor";
    const std::string serial = stored_serial(v, device);
    if (!serial.empty()) label += (compact ? " (" : " (serial ") + serial + ")";
    return label + (channel ? fmt::format(", channel {}", channel) : "");
  }
  const std::string id = ctx(inst, "id").empty() ? stored : ctx(inst, "id");
  const std::string role = ctx(inst, "role").empty() ? id : ctx(inst, "role");
  const std::string product =
      ::daq::product_name(ctx(inst, "driver").empty() ? stored : ctx(inst, "driver"));
  // The instrument's own name where the role does not say it ("spindle" on a material gauge).
  const std::string named = id != role && id != ctx(inst, "driver") ? " " + id : "";
  std::string label;
  if (compact && !product.empty())
    label = (sensor.empty() || role == sensor ? "" : role + " ") + product + named;
  else if (sensor.empty())
    label = role + named + (product.empty() ? "" : " " + product);
  else if (role == sensor)
    label = std::string(sensor) + " sensor" + named + (product.empty() ? "" : " " + product);
  else  // the sensor of another instrument (a laser's environmental unit)
    label = fmt::format("{} sensor of {}{}{}", sensor, role, named,
                        product.empty() ? "" : " " + product);
  const std::string serial = ctx(inst, "serial_number");
  if (!serial.empty()) label += (compact ? " (" : " (serial ") + serial + ")";
  return label + (channel ? fmt::format(", channel {}", channel) : "");
}

Environment load_environment(const st::RunReader& store, const RunView& v) {
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
    s.t_s.push_back(static_cast<double>(r.time_ns - env.t0_ns) * 1e-9);
    s.value.push_back(static_cast<Q>(r.quantity) == Q::air_pressure_pa ? r.value / 100.0 : r.value);
  }
  for (auto& [key, s] : by_source) {
    const auto [q, device, channel] = key;
    const auto sensor_of = static_cast<Q>(q) == Q::material_temperature_degc ? "material"
                           : static_cast<Q>(q) == Q::refractive_index        ? ""
                                                                             : "air";
    s.label = legend_label(v, device, channel, sensor_of);
    s.short_label = legend_label(v, device, channel, sensor_of, true);
    s.device = device;
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

RunView load(const st::RunReader& store, std::int64_t id) {
  const auto run = store.run(id);
  if (!run) throw cal::InputError(fmt::format("{}: no run {} (see daq runs)", store.name(), id));
  RunView v{.run = *run};
  if (run->machine_id > 0)
    if (const auto m = store.machine(run->machine_id)) v.machine = m->name;
  v.instruments = store.instruments(id);
  v.settings = json::parse(run->settings_json, nullptr, false);
  if (v.settings.is_discarded()) v.settings = json::object();
  v.context = v.settings.value("context", json::object());
  if (!v.context.is_object()) v.context = json::object();
  v.env = load_environment(store, v);
  v.results = store.results(id);
  v.missed = store.missed_stops(id);
  v.actions = store.operator_actions(id);
  v.approvals = store.approvals(id);
  v.used = ::daq::compensation_used(v.settings, v.results);
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

// The times of the series plotted against one time axis, and the axis's unit for them
// (time_unit: a run of seconds in seconds, not in minutes written "x10⁻²").
struct TimeSpan {
  double lo = INFINITY, hi = -INFINITY;
  void add(const Series& s) {
    for (const double t : s.t_s) lo = std::min(lo, t), hi = std::max(hi, t);
  }
  TimeUnit unit() const { return time_unit(hi >= lo ? hi - lo : 0.0); }
};

// "time (min)".
std::string time_label(const TimeUnit& unit) { return fmt::format("time ({})", unit.name); }

// At most `limit` points per series in a plot (every k-th): a plot cannot show more. Their time
// in `unit`.
std::vector<Line> lines_of(const std::vector<Series>& series, const TimeUnit& unit,
                           std::size_t first_colour, std::size_t limit = 1500) {
  std::vector<Line> out;
  for (std::size_t i = 0; i < series.size(); ++i) {
    const auto& s = series[i];
    const std::size_t step = std::max<std::size_t>(1, s.t_s.size() / limit);
    Line l{.label = s.label, .colour = palette(first_colour + i), .width = 1.2};
    for (std::size_t k = 0; k < s.t_s.size(); k += step) {
      l.x.push_back(s.t_s[k] / unit.seconds);
      l.y.push_back(s.value[k]);
    }
    out.push_back(std::move(l));
  }
  return out;
}

// --- sections shared by every kind ---------------------------------------------------------------

// "Positioning test (ISO 230-2), axis X".
// The standard a positioning test is reported by, as its title names it: "ISO 230-2" for every
// edition, else the one asked for (`daq report -s vdi3441`: the title said ISO 230-2 over a page
// evaluated by VDI/DGQ 3441).
// An unknown key is named by the results' own error, not here.
std::string positioning_standard(std::string_view standard_key) {
  if (standard_key.empty()) return "ISO 230-2";
  try {
    const std::string_view title =
        cal::iso230_2::info(cal::iso230_2::standard_from_string(standard_key)).title;
    return title.starts_with("ISO 230-2") ? "ISO 230-2" : std::string(title);
  } catch (const cal::InputError&) {
    return "ISO 230-2";
  }
}

// The standard a linear run's report evaluates by: the one asked for, else the run's own.
std::string linear_standard_key(const RunView& v, const Options& o) {
  if (v.run.kind != "linear") return "";
  if (!o.standard.empty()) return o.standard;
  const auto standard = v.settings.value("standard", json());
  return standard.is_string() ? standard.get<std::string>() : "";
}

std::string and_list(const std::vector<std::string>& items);

// standard_key: the standard the report evaluates by when it is not the run's own (-s).
std::string test_name(const RunView& v, std::string_view standard_key = {}) {
  const json m = v.settings.value("measure", json::object());
  const std::string component =
      m.is_object() && m.contains("component") && m["component"].is_string()
          ? " " + m["component"].get<std::string>()
          : "";
  const std::string what =
      v.run.kind == "linear"    ? "Positioning test (" + positioning_standard(standard_key) + ")"
      : v.run.kind == "rotary"  ? "Rotary positioning test (ISO 230-2)" + component
      : v.run.kind == "circle"  ? "Circular test (ISO 230-4, ballbar)"
      : v.run.kind == "dynamic" ? "Dynamic capture"
      : v.run.kind == "straightness" ? "Straightness test (ISO 230-1)" + component
      : v.run.kind == "angular"      ? "Angular test (ISO 230-1)" + component
      : v.run.kind == "roll"         ? "Roll test (ISO 230-1)" + component
                                     : v.run.kind + " test";
  if (v.run.kind == "ballbar5x") {  // its axes, "CA": each rotary axis tested
    std::vector<std::string> axes;
    for (char c : v.run.axis) axes.emplace_back(1, c);
    return fmt::format("Five-axis ballbar test (rotary axes' location errors), {} {}",
                       axes.size() > 1 ? "axes" : "axis", and_list(axes));
  }
  return fmt::format("{}, axis {}", what, v.run.axis);
}

std::string run_title(const RunView& v, std::string_view standard_key = {}) {
  // The origin leads the title, so it is on every printed page's running header too.
  const auto label = ::daq::run_origin(v.run, v.instruments, v.machine).label();
  return fmt::format("{}Run {}: {}", label.empty() ? "" : label + " — ", v.run.id,
                     test_name(v, standard_key));
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

std::string missed_text(const RunView& v, const st::MissedStop& m) {
  return fmt::format("run {} {} target {} ({:.3f} {})", m.run_number,
                     m.direction == '+' ? "↑" : "↓", m.target_index + 1, m.nominal_mm,
                     axis_text(v).position);
}

std::string connections_table(const RunView& v);

// The operator's actions during the run (stops captured by hand, skipped, measured again, the
// run paused): when, which stop, from where, by whom, and what happened.
std::string operator_actions_section(const RunView& v) {
  if (v.actions.empty()) return {};
  std::vector<std::vector<std::string>> rows;
  for (const auto& a : v.actions)
    rows.push_back(
        {iso_time(a.time_unix_ms), esc(a.action), a.stop ? esc(missed_text(v, *a.stop)) : "",
         esc(a.source) + (a.operator_name.empty() ? "" : " (" + esc(a.operator_name) + ")"),
         esc(a.detail)});
  return "<h4>Operator actions (" + std::to_string(v.actions.size()) + ")</h4>\n" +
         table({"time (UTC)", "action", "stop", "from (by)", "what happened"}, rows, "", "lllll");
}

std::string setup_section(const RunView& v) {
  std::vector<std::vector<std::string>> rows = {
      {"Machine", esc(v.machine.empty() ? "(not recorded)" : v.machine)},
      {"Campaign", esc(v.run.campaign)},
      {"Started", iso_time(v.run.started_unix_ms)},
      {"Ended", v.run.ended_unix_ms ? iso_time(*v.run.ended_unix_ms) : "(not ended)"},
      {"Status", std::string(st::to_string(v.run.status)) +
                     (v.run.note.empty() ? "" : " &mdash; " + esc(v.run.note))},
      {"Origin of the readings", esc(::daq::run_origin(v.run, v.instruments, v.machine).text)},
      {"Software", esc(v.run.software_version)},
      {"Capture file", "<span class=\"path\">" +
                           esc(v.run.capture_path.empty() ? "(none)" : v.run.capture_path) +
                           "</span>"}};
  if (!v.missed.empty()) {
    std::string list;
    for (const auto& m : v.missed) list += (list.empty() ? "" : "; ") + missed_text(v, m);
    rows.insert(rows.begin() + 6, {"Missed stops", fmt::format("<span class=\"fail\">{} never "
                                                               "captured:</span> {}",
                                                               v.missed.size(), esc(list))});
  }
  return "<h3>Test set-up</h3>\n" + table({"", ""}, rows, "kv") + connections_table(v);
}

// A setting's label and unit as an engineer reads it (docs/reports.md, "Settings"); a key not
// listed here is shown by its name.
struct SettingLabel {
  std::string_view key, label, unit;
};
constexpr SettingLabel setting_labels[] = {
    {"axis", "Axis", ""},
    {"standard", "Standard", ""},
    {"cycle", "Cycle", ""},
    {"bidirectional", "Approach in both directions", ""},
    {"runs", "Runs per target", ""},
    {"targets_mm", "Targets", "mm"},
    {"datum_mm", "Datum", "mm"},
    {"feed_mm_per_min", "Feed", "mm/min"},
    {"dwell_s", "Dwell at each target", "s"},
    {"machine", "Machine", ""},
    {"trigger.dwell_s", "Stop detection: still for", "s"},
    {"trigger.tolerance_um", "Stop detection: within", "µm"},
    {"trigger.window_mm", "Stop detection: window around the target", "mm"},
    {"environment.equation", "Refractive index equation", ""},
    {"environment.expansion_ppm_per_k", "Expansion coefficient", "ppm/K"},
    {"environment.co2_umol_per_mol", "CO2 content of the air", "µmol/mol"},
    {"environment.wavelength_nm", "Laser vacuum wavelength", "nm"},
    {"environment.stale_after_s", "Environment readings stale after", "s"},
    {"environment.on_stale", "When they go stale", ""},
    {"measure.kind", "Measurement", ""},
    {"measure.component", "Error component", ""},
    {"measure.unit", "Unit of the result", ""},
    {"measure.direction", "Direction of the deviation", ""},
    {"measure.beams", "Interferometer beams", ""},
    {"measure.separation_mm", "Beam separation", "mm"},
    {"measure.sign", "Sign of the reading", ""},
    {"measure.square", "Against a square", ""},
    {"measure.reference", "Angular reference", ""},
    {"measure.stationary_mm", "Stationary position", "mm"},
    {"measure.probe_offset_mm", "Probe offset", "mm"},
    {"machine_model.topology", "Machine model: kinematic chain", ""},
    {"machine_model.table_offset_mm", "Machine model: table offset", "mm"},
    {"machine_model.tool_offset_mm", "Machine model: tool offset", "mm"},
    {"plane", "Plane", ""},
    {"radius_mm", "Radius (bar length)", "mm"},
    {"arc_deg", "Arc", "°"},
    {"start_deg", "Start angle", "°"},
    {"overshoot_deg", "Overshoot arc", "°"},
    {"feed_in_mm", "Feed-in", "mm"},
    {"sample_rate_hz", "Sample rate", "Hz"},
    {"uncalibrated", "Bar uncalibrated", ""},
    {"uncalibrated_reason", "Why uncalibrated", ""},
    {"calibrated_radius_mm", "Calibrated bar length", "mm"},
};

// Whether a setting says anything for this run: not an empty text or list, not an offset of
// zero, not a positioning run's angular-only keys.
bool setting_applies(const RunView& v, const std::string& key, const json& val) {
  if (val.is_null() || (val.is_string() && val.get<std::string>().empty())) return false;
  if (val.is_array() && val.empty()) return false;
  if (v.run.kind == "ballbar5x" && key == "tests") return false;  // page one's table of the tests
  if (val.is_array() && key.ends_with("_mm") && key != "targets_mm" &&
      std::all_of(val.begin(), val.end(),
                  [](const json& x) { return x.is_number() && x.get<double>() == 0.0; }))
    return false;
  const json measure = v.settings.value("measure", json::object());
  // The laser's beams and the square apply neither to positioning nor to a rotary axis read by
  // its angular reference (whose reading's sign does).
  const std::string kind = measure.is_object() ? measure.value("kind", "") : "";
  if ((kind == "positioning" || kind == "rotary") &&
      (key == "measure.beams" || key == "measure.separation_mm" || key == "measure.square" ||
       (key == "measure.sign" && kind == "positioning")))
    return false;
  // A rotary axis read by a reference other than a laser's optics reads no wavelength in air:
  // the refractive index's equation, CO2 and wavelength, and the scale's expansion, say nothing.
  if (kind == "rotary" && measure.value("reference", "") != "laser" &&
      (key == "environment.equation" || key == "environment.co2_umol_per_mol" ||
       key == "environment.wavelength_nm" || key == "environment.expansion_ppm_per_k"))
    return false;
  if (key == "uncalibrated" && val.is_boolean() && !val.get<bool>()) return false;
  return true;
}

// A rotary run's plan and trigger are in degrees (kinds/rotary.cpp): its keys named in mm read
// as degrees, the trigger's tolerance_um as millidegrees.
std::string_view setting_unit(const RunView& v, std::string_view key, std::string_view unit) {
  if (v.run.kind != "rotary") return unit;
  if (key == "trigger.tolerance_um") return "millidegrees";
  if (key == "feed_mm_per_min") return "deg/min";
  if (key == "targets_mm" || key == "datum_mm" || key == "trigger.window_mm") return "deg";
  return unit;
}

// A refractive-index equation by the name its authors gave it ("ciddor" is Ciddor (1996)).
std::string equation_name(const std::string& key) {
  try {
    switch (cal::air::equation_from_string(key)) {
      case cal::air::Equation::edlen:
        return "Edlén (Birch and Downs)";
      case cal::air::Equation::ciddor:
        return "Ciddor (1996)";
      case cal::air::Equation::shop_floor:
        return "NIST shop floor";
    }
  } catch (const cal::InputError&) {
  }
  return key;  // not one caldaq knows: as recorded
}

// A setting whose recorded value is a key, as the reader knows it: the standard by its title
// ("ISO 230-2:2014", not "iso230-2:2014"), the equation by its name.
json shown_setting(const RunView& v, const std::string& key, const json& val) {
  if (!val.is_string()) return val;
  const std::string text = val.get<std::string>();
  try {
    if (key == "standard" && v.run.kind == "circle")
      return cal::circle::info(cal::circle::circular_standard_from_key(text)).label;
    if (key == "standard" && (v.run.kind == "linear" || v.run.kind == "rotary"))
      return std::string(cal::iso230_2::info(cal::iso230_2::standard_from_string(text)).title);
    // A straightness, angular or roll run moves through the targets of a positioning test; its
    // result is ISO 230-1's (the appendix read "iso230-2:2014", a key, as if it were judged so).
    if (key == "standard" && ::daq::is_profile_kind(v.run.kind))
      return fmt::format("{} (its targets and cycle; the result is evaluated by ISO 230-1:2012)",
                         cal::iso230_2::info(cal::iso230_2::standard_from_string(text)).title);
  } catch (const cal::InputError&) {
    return val;  // not one caldaq knows: as recorded
  }
  if (key == "environment.equation") return equation_name(text);
  return val;
}

std::string setting_value(const json& val, std::string_view unit) {
  if (val.is_boolean()) return val.get<bool>() ? "yes" : "no";
  // A unit as a value (measure.unit = "um") as documents print it (µm).
  const std::string text =
      esc(val.is_string() ? ::daq::unit_html(val.get<std::string>()) : setting_text(val));
  // A plane angle's degree sign follows the number without a space (360°, not 360 °).
  return unit.empty() ? text : text + (unit == "°" ? "" : " ") + esc(unit);
}

// The settings as recorded at the start, as an appendix: labels and units, only the keys that
// apply; a coefficient the current result used differently (re-compensation) is shown with both.
std::string settings_appendix(const RunView& v) {
  const auto used_note = [&](const std::string& key, const json& value) -> std::string {
    if (v.run.kind != "linear" || !v.used.recompensated) return "";
    const std::string name = key.substr(key.find('.') + 1);
    if (!key.starts_with("environment.") || !v.used.coefficients.contains(name)) return "";
    if (v.used.coefficients[name] == value) return "";
    return fmt::format(" <span class=\"changed\">(as acquired; the current result uses {})</span>",
                       esc(setting_text(v.used.coefficients[name])));
  };
  std::vector<std::pair<std::string, json>> flat;
  for (const auto& [k, val] : v.settings.items()) {
    if (k == "context") continue;  // shown in its own sections
    if (val.is_object() && !(k == "calibration" && v.run.kind == "circle")) {
      for (const auto& [k2, v2] : val.items()) flat.emplace_back(k + "." + k2, v2);
    } else {
      flat.emplace_back(k, val);
    }
  }
  // Known keys in their reading order, then the others by name.
  const auto rank = [](const std::string& key) {
    for (std::size_t i = 0; i < std::size(setting_labels); ++i)
      if (setting_labels[i].key == key) return i;
    return std::size(setting_labels);
  };
  std::stable_sort(flat.begin(), flat.end(),
                   [&](const auto& a, const auto& b) { return rank(a.first) < rank(b.first); });
  std::vector<std::vector<std::string>> rows;
  for (const auto& [key, val] : flat) {
    if (key == "calibration") {  // the section "Bar calibration"
      rows.push_back({"Bar calibration", fmt::format("record {} (see Bar calibration)",
                                                     val.value("id", std::int64_t{0}))});
      continue;
    }
    if (!setting_applies(v, key, val)) continue;
    const auto i = rank(key);
    const bool known = i < std::size(setting_labels);
    rows.push_back({known ? esc(setting_labels[i].label) : "<code>" + esc(key) + "</code>",
                    setting_value(shown_setting(v, key, val),
                                  known ? setting_unit(v, key, setting_labels[i].unit) : "") +
                        used_note(key, val)});
  }
  if (rows.empty()) return "";
  // The appendix flows on after the environment: starting a page of its own, it left the page
  // before it as full as the environment's plots made it (the suspect demo run's 29 %, when
  // the pressure and humidity plots did not fit under the temperatures).
  return std::string("<h3 class=\"appendix\">") +
         "Appendix: settings of the run</h3>\n<p class=\"note\">As recorded "
         "at the start "
         "of the run; settings that do not apply to this test are left out.</p>\n" +
         table({"setting", "value"}, rows, "kv");
}

std::string stated(const std::string& s);

// What is known of an instrument's model and serial number, never a blank cell (it read as
// data missing): the configured driver and serial number, else for an instrument no
// configuration named (a run of daq model ballbar5x-run, an imported file) that it is a
// simulated twin, or the serial number its file stated; else that none was stated.
std::string model_cell(const RunView& v, const st::InstrumentRecord& i) {
  const std::string model = instrument_label(v, i.device);
  if (model != i.driver) return esc(model);
  if (i.origin == "simulated") return "<span class=\"unstated\">none: a simulated twin</span>";
  if (const auto serial = stored_serial(v, i.device); !serial.empty())
    return "serial " + esc(serial) + " <span class=\"unstated\">(model not stated)</span>";
  return stated("");
}

// The instruments and their connections, by the names the set-up gave them and their model and
// serial number. Not by the acquisition's device numbers: those have gaps where a configured
// device was not used (0, 1, 2, 4 on a straightness run) and mean nothing to the reader.
std::string connections_table(const RunView& v) {
  std::string h;
  std::vector<std::vector<std::string>> inst;
  for (const auto& i : v.instruments)
    inst.push_back({esc(i.driver), model_cell(v, i), esc(i.transport)});
  if (!inst.empty())
    h += "<h4>Instruments</h4>\n" +
         table({"instrument", "model and serial number", "connection"}, inst);
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
  // The legends say which sensor ("air sensor PTU300 ...", "material sensor ..."), so the
  // quantity needs no prefix of its own ("air: ids3010" named neither).
  // One time unit for the section's plots (they share the run's time).
  TimeSpan span;
  for (const auto* g :
       {&env.air_temperature, &env.material_temperature, &env.pressure_hpa, &env.humidity})
    for (const auto& s : *g) span.add(s);
  const auto unit = span.unit();
  auto temps = lines_of(env.air_temperature, unit, 0);
  std::map<int, Rgb> colour_of;  // an air sensor's device -> its colour in the temperature plot
  for (std::size_t i = 0; i < temps.size(); ++i)
    colour_of.emplace(env.air_temperature[i].device, temps[i].colour);
  for (auto& l : lines_of(env.material_temperature, unit, env.air_temperature.size())) {
    l.dashed = true;
    temps.push_back(std::move(l));
  }
  // Plots of the run's time, sharing the axis: the temperatures across the page, then pressure
  // and humidity side by side, each half the page wide (one under the other at full width, the
  // pressure plot fell to the next page: the demo's environment page was 71 % full, the next
  // 60 %). Half as wide, a plot's text is drawn 1.6 times larger (PLplot's shrinks with its
  // canvas: 7.5 at 320 x 290 against 11 at 600 x 290), so it prints at 9 pt or more (12 x 253 /
  // 320 = 9.5 pt). Each air sensor keeps its colour of the temperature plot, whose legend names
  // it, so the pair needs no legends of their own (two rows of legend took a third of each).
  const auto time_chart = [&unit](const char* title, const char* y_label, std::vector<Line> lines,
                                  int width_pt, int height_pt, double text_scale, bool legend) {
    return svg(XyChart{.title = title,
                       .x_label = time_label(unit),
                       .y_label = y_label,
                       .lines = std::move(lines),
                       .width_pt = width_pt,
                       .height_pt = height_pt,
                       .legend = legend,
                       .text_scale = text_scale});
  };
  h += figure(time_chart("Temperatures", "temperature (°C)", std::move(temps), 600, 170, 1.0, true),
              "Air and material temperature during the run.");
  // The pair's lines in the temperature plot's colours; `keyed` false when a sensor is not in
  // that plot (then each plot has its own colours and a legend naming the instruments short).
  bool keyed = true;
  const auto air_lines = [&](const std::vector<Series>& series, std::size_t colour) {
    auto lines = lines_of(series, unit, colour);
    for (std::size_t i = 0; i < lines.size(); ++i) {
      lines[i].label = series[i].short_label;
      if (const auto it = colour_of.find(series[i].device); it != colour_of.end())
        lines[i].colour = it->second;
      else
        keyed = false;
    }
    return lines;
  };
  auto pressure = air_lines(env.pressure_hpa, 2);
  auto humidity = air_lines(env.humidity, 5);
  if (!keyed)
    pressure = lines_of(env.pressure_hpa, unit, 2), humidity = lines_of(env.humidity, unit, 5);
  const bool both = !env.pressure_hpa.empty() && !env.humidity.empty();
  const char* key = keyed ? " (each sensor in its colour of the temperature plot)" : "";
  std::string plots;
  if (!env.pressure_hpa.empty())
    plots += figure(both ? time_chart("Air pressure", "pressure (hPa)", std::move(pressure), 320,
                                      240, 1.6, !keyed)
                         : time_chart("Air pressure", "pressure (hPa)",
                                      lines_of(env.pressure_hpa, unit, 2), 600, 200, 1.0, true),
                    fmt::format("Air pressure during the run{}.", both ? key : ""));
  if (!env.humidity.empty())
    plots += figure(both ? time_chart("Relative humidity", "humidity (%RH)", std::move(humidity),
                                      320, 240, 1.6, !keyed)
                         : time_chart("Relative humidity", "humidity (%RH)",
                                      lines_of(env.humidity, unit, 5), 600, 200, 1.0, true),
                    fmt::format("Relative humidity during the run{}.", both ? key : ""));
  // The figures are the pair's own children (no wrapping div), each a grid cell.
  if (both) plots = "<div class=\"pair\">" + plots.substr(0, plots.size() - 1) + "</div>\n";
  h += plots;
  return h;
}

// --- what a customer report states ------------------------------------------------------------

std::string stated(const std::string& s) {
  return s.empty() ? "<span class=\"unstated\">not stated</span>" : esc(s);
}

// Customer, site, machine identity, operator, date: from the run's context.
std::string customer_section(const RunView& v) {
  const json c = v.context.value("customer", json::object());
  const json m = v.context.value("machine", json::object());
  std::string make_model = ctx(m, "make");
  if (!ctx(m, "model").empty()) make_model += (make_model.empty() ? "" : " ") + ctx(m, "model");
  const std::vector<std::vector<std::string>> rows = {
      {"Customer", stated(ctx(c, "name"))},
      {"Site", stated(ctx(c, "site"))},
      {"Machine", esc(v.machine.empty() ? ctx(m, "name") : v.machine)},
      {"Make and model", stated(make_model)},
      {"Serial number", stated(ctx(m, "serial_number"))},
      {"Operator", stated(ctx(v.context, "operator"))},
      {"Test date", iso_time(v.run.started_unix_ms)}};
  return "<h3>Customer and machine</h3>\n" + table({"", ""}, rows, "kv");
}

// YYYY-MM-DD of a unix time, to compare with a calibration due date.
std::string ymd(std::int64_t unix_ms) { return iso_time(unix_ms).substr(0, 10); }

// Why a run holds no configured instrument's serial number and calibration, for what its
// instruments are (without the "is"/"are" and what follows): every one simulated ("the ballbar
// is simulated (a twin of ...)"), every one imported from a file (which states a serial number
// or not); nullopt for any other run, which should have had them in its configuration. "Give
// serial_number ... in the configuration" asked a simulated run of daq model, made without any,
// for a calibration its twin cannot have.
struct Untraceable {
  std::string what;     // "the ballbar is simulated (a twin of ...)"
  std::string because;  // ": a simulated instrument has no serial number, ..."
};
std::optional<Untraceable> untraceable(const RunView& v) {
  if (v.instruments.empty()) return std::nullopt;
  const auto all = [&](std::string_view origin) {
    return std::all_of(v.instruments.begin(), v.instruments.end(),
                       [&](const st::InstrumentRecord& i) { return i.origin == origin; });
  };
  std::vector<std::string> names, details, serials;
  for (const auto& i : v.instruments) {
    names.push_back(i.driver);
    if (!i.origin_detail.empty() &&
        std::find(details.begin(), details.end(), i.origin_detail) == details.end())
      details.push_back(i.origin_detail);
    if (const auto serial = stored_serial(v, i.device); !serial.empty())
      serials.push_back(v.instruments.size() == 1 ? serial : serial + " of " + i.driver);
  }
  const bool one = names.size() == 1;
  const std::string detail =
      details.empty() ? "" : " (" + fmt::format("{}", fmt::join(details, "; ")) + ")";
  if (all("simulated"))
    return Untraceable{
        fmt::format("the {} {} simulated{}", and_list(names), one ? "is" : "are", detail),
        ": a simulated instrument has no serial number, certificate or calibration due date"};
  // The detail names the file ("Renishaw .rtx file X (the file does not say ...)").
  if (all("imported"))
    return Untraceable{
        fmt::format(
            "the readings of {} were imported from {}", and_list(names),
            details.empty() ? "another tool's file" : fmt::format("{}", fmt::join(details, "; "))),
        serials.empty()
            ? std::string(", which states no serial number, certificate or calibration due date")
            : fmt::format(", which states the serial number {} but no certificate or "
                          "calibration due date",
                          and_list(serials))};
  return std::nullopt;
}

// The instruments with their serial numbers and calibration; a due date before the test is
// flagged (the instrument was out of calibration when it measured). The warnings themselves
// are on page one (traceability_warnings).
std::string instruments_section(const RunView& v) {
  const auto list = v.context.value("instruments", json::array());
  std::string h = "<h3>Instruments and calibration</h3>\n";
  if (list.empty()) {
    if (const auto u = untraceable(v)) {
      std::string text = u->what + u->because + ".";
      text[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
      return h + "<p class=\"unstated\">" + esc(text) + "</p>\n";
    }
    return h +
           "<p class=\"unstated\">The instruments' serial numbers and calibration "
           "certificates were not recorded with this run (give serial_number, certificate "
           "and calibration_due of each device in the configuration).</p>\n";
  }
  std::vector<std::vector<std::string>> rows;
  const std::string test_day = ymd(v.run.started_unix_ms);
  for (const auto& i : list) {
    const std::string due = ctx(i, "calibration_due");
    std::string due_cell = stated(due);
    if (!due.empty() && due < test_day)
      due_cell = "<span class=\"fail\">" + esc(due) + " &mdash; PAST DUE</span>";
    // The instrument by the name the Instruments table and the plots' legends give it, its
    // role only where it differs ("air | air | ptu300" said the name twice).
    const std::string id = ctx(i, "id"), role = ctx(i, "role");
    rows.push_back({esc(id.empty() ? role : id) +
                        (role.empty() || role == id || id.empty() ? "" : " (" + esc(role) + ")"),
                    esc(ctx(i, "driver")), stated(ctx(i, "serial_number")),
                    stated(ctx(i, "certificate")), due_cell});
  }
  return h +
         table({"instrument", "model", "serial number", "certificate", "calibration due"}, rows);
}

// The gaps in the traceability of the readings other than a calibration past due (past_due),
// a warning per gap shared by several instruments: a serial number, certificate or due date
// not stated. Without them a
// reader cannot tell whether the instrument was calibrated when it measured.
std::vector<std::string> traceability_gaps(const RunView& v) {
  const auto list = v.context.value("instruments", json::array());
  if (!list.is_array() || list.empty()) {
    if (const auto u = untraceable(v)) return {u->what + u->because};
    return {
        "the instruments' serial numbers, certificates and calibration due dates were not "
        "recorded with this run"};
  }
  std::vector<std::string> out;
  // The instruments that lack the same things, in one warning ("air, laser: no serial number,
  // certificate or calibration due date stated"): one line each filled page one with four
  // lines saying the same.
  std::vector<std::pair<std::string, std::vector<std::string>>> lacking;
  for (const auto& i : list) {
    const std::string name = ctx(i, "id").empty() ? ctx(i, "role") : ctx(i, "id");
    const std::string due = ctx(i, "calibration_due");
    std::vector<std::string> missing;
    if (ctx(i, "serial_number").empty()) missing.push_back("serial number");
    if (ctx(i, "certificate").empty()) missing.push_back("certificate");
    if (due.empty()) missing.push_back("calibration due date");
    if (missing.empty()) continue;
    const std::string what =
        missing.size() == 1
            ? missing.front()
            : fmt::format("{} or {}", fmt::join(missing.begin(), missing.end() - 1, ", "),
                          missing.back());
    const auto same = std::find_if(lacking.begin(), lacking.end(),
                                   [&](const auto& l) { return l.first == what; });
    if (same == lacking.end())
      lacking.push_back({what, {name}});
    else
      same->second.push_back(name);
  }
  for (const auto& [what, names] : lacking)
    out.push_back(fmt::format("{}: no {} stated", fmt::join(names, ", "), what));
  return out;
}

// The traceability gaps of the runs a report covers (one run; a verification's as found and as
// left; a campaign), for its page one: each gap once, with the runs it concerns when not all of
// them (a campaign of 19 runs on the same instruments said the same line 19 times in the runs'
// sections, and nothing on page one).
// The instruments whose calibration was due before the test day of a run: (name, due date).
std::vector<std::pair<std::string, std::string>> past_due(const RunView& v) {
  const auto list = v.context.value("instruments", json::array());
  std::vector<std::pair<std::string, std::string>> out;
  if (!list.is_array()) return out;
  const std::string test_day = ymd(v.run.started_unix_ms);
  for (const auto& i : list) {
    const std::string due = ctx(i, "calibration_due");
    if (!due.empty() && due < test_day)
      out.push_back({ctx(i, "id").empty() ? ctx(i, "role") : ctx(i, "id"), due});
  }
  return out;
}

// "a", "a and b", "a, b and c".
std::string and_list(const std::vector<std::string>& items) {
  if (items.size() <= 1) return items.empty() ? std::string() : items.front();
  return fmt::format("{} and {}", fmt::join(items.begin(), items.end() - 1, ", "), items.back());
}

// The past-due calibrations of the runs a report covers, in one warning: each instrument with
// its due date (and its runs when not all of them), then the test days. A warning per run and
// date ("... (2020-01-31 < 2026-11-28)", "... (2020-01-31 < 2026-11-29)") said the same twice
// for runs of two days.
std::string past_due_warning(std::span<const RunView* const> views) {
  struct Late {
    std::string name, due;
    std::vector<std::int64_t> runs;
  };
  std::vector<Late> late;
  std::vector<std::string> days;  // the test days of the runs concerned, in order
  for (const auto* v : views)
    for (auto& [name, due] : past_due(*v)) {
      auto it = std::find_if(late.begin(), late.end(),
                             [&](const Late& l) { return l.name == name && l.due == due; });
      if (it == late.end()) it = late.insert(late.end(), Late{name, due, {}});
      if (it->runs.empty() || it->runs.back() != v->run.id) it->runs.push_back(v->run.id);
      if (const auto day = ymd(v->run.started_unix_ms);
          std::find(days.begin(), days.end(), day) == days.end())
        days.push_back(day);
    }
  if (late.empty()) return {};
  std::sort(days.begin(), days.end());
  std::vector<std::string> each;
  for (const auto& l : late)
    each.push_back(fmt::format("{} (due {}{})", l.name, l.due,
                               l.runs.size() == views.size()
                                   ? ""
                                   : fmt::format(", {} {}", l.runs.size() == 1 ? "run" : "runs",
                                                 fmt::join(l.runs, ", "))));
  const bool one = late.size() == 1;
  return fmt::format(
      "<p class=\"warning\">Traceability: the calibration{} of {} {} past due on the test "
      "date{} ({}): {} readings are not traceable to a valid certificate.</p>\n",
      one ? "" : "s", esc(and_list(each)), one ? "was" : "were", days.size() == 1 ? "" : "s",
      days.size() <= 3 ? and_list(days) : days.front() + " to " + days.back(),
      one ? "its" : "their");
}

std::string traceability_warnings(std::span<const RunView* const> views) {
  std::vector<std::pair<std::string, std::vector<std::int64_t>>> gaps;  // gap -> its runs
  for (const auto* v : views)
    for (auto& g : traceability_gaps(*v)) {
      const auto same =
          std::find_if(gaps.begin(), gaps.end(), [&](const auto& x) { return x.first == g; });
      if (same == gaps.end())
        gaps.push_back({std::move(g), {v->run.id}});
      else
        same->second.push_back(v->run.id);
    }
  std::string h = past_due_warning(views);
  for (const auto& [gap, ids] : gaps)
    h += fmt::format(
        "<p class=\"warning\">Traceability{}: {}.</p>\n",
        ids.size() == views.size()
            ? ""
            : fmt::format(" ({} {})", ids.size() == 1 ? "run" : "runs", fmt::join(ids, ", ")),
        esc(gap));
  return h;
}

std::string traceability_warnings(const RunView& v) {
  const std::array<const RunView*, 1> one{&v};
  return traceability_warnings(one);
}

// The quality of the run's stops (run_quality.hpp, docs/iso230-2.md "Suspect stops"): a suspect
// run says so on page one, with its stops named.
// `page_one`: the suspect box (or a failed check) for page one; otherwise the quality of a run
// that is not suspect, for the details (page one keeps its room for the answer).
std::string quality_banner(const st::RunReader& store, const RunView& v, bool page_one) {
  if (v.run.kind == "circle" || v.run.kind == "dynamic") return "";
  cal::storage::RunQuality q;
  try {
    q = ::daq::run_quality(store, v.run.id);
  } catch (const std::exception& e) {
    return page_one ? "<p class=\"warning\">Run quality: " + esc(e.what()) + "</p>\n" : "";
  }
  if (q.state != "suspect")
    return q.state.empty() || page_one
               ? ""
               : fmt::format("<p class=\"note\">Run quality: {}</p>\n",
                             esc(::daq::units_html(::daq::quality_text(q))));
  if (!page_one) return "";
  std::string stops;
  for (const auto& m : q.suspects) {
    // The reason begins with where the stop was ("run 2 up at 149.024 mm: +4.953 µm ..."): said
    // once, with the target's number and its position ("run 2 up at" repeated "run 2 ↑").
    const std::string where =
        fmt::format("run {} {} at ", m.run_number, m.direction == '+' ? "up" : "down");
    const auto colon = m.reason.find(": ");
    const bool placed = m.reason.starts_with(where) && colon != std::string::npos;
    const std::string at =
        placed ? " (" + m.reason.substr(where.size(), colon - where.size()) + ")" : "";
    stops += fmt::format("<li>run {} {} target {}{}: {}</li>", m.run_number,
                         m.direction == '+' ? "↑" : "↓", m.target_index + 1, esc(at),
                         esc(::daq::units_html(placed ? m.reason.substr(colon + 2) : m.reason)));
  }
  // The stops, each with its reason and limit, are the message: the summary sentence repeats
  // them (the box took page one's room for the main plot), so it is said only without a list.
  if (q.suspects.empty())
    return fmt::format(
        "<div class=\"verdict suspect\"><strong>SUSPECT RUN</strong>: {} Repeat the run before "
        "relying on it.</div>\n",
        esc(::daq::units_html(q.summary)));
  const auto n = q.suspects.size();
  return fmt::format(
      "<div class=\"verdict suspect\"><strong>SUSPECT RUN</strong>: {} stop{} beyond the run's "
      "repeatability, included in the results below; repeat {} or the run before relying on "
      "it.<ul>{}</ul></div>\n",
      n, n == 1 ? "" : "s", n == 1 ? "it" : "them", stops);
}

// Page one's heading block: who, what machine, which test, when.
std::string summary_block(const RunView& v, std::string_view test) {
  const json c = v.context.value("customer", json::object());
  const json m = v.context.value("machine", json::object());
  std::string machine = esc(v.machine.empty() ? ctx(m, "name") : v.machine);
  std::string make_model = ctx(m, "make");
  if (!ctx(m, "model").empty()) make_model += (make_model.empty() ? "" : " ") + ctx(m, "model");
  if (!make_model.empty()) machine += ", " + esc(make_model);
  if (!ctx(m, "serial_number").empty()) machine += ", s/n " + esc(ctx(m, "serial_number"));
  std::string customer = stated(ctx(c, "name"));
  if (!ctx(c, "site").empty()) customer += ", " + esc(ctx(c, "site"));
  return fmt::format(
      "<table class=\"summary\"><tbody>"
      "<tr><th>Customer</th><td>{}</td><th>Test</th><td>{}</td></tr>"
      "<tr><th>Machine</th><td>{}</td><th>Date</th><td>{}</td></tr>"
      "<tr><th>Operator</th><td>{}</td><th>Machine state</th><td>{}</td></tr>"
      "</tbody></table>\n",
      customer, esc(test), machine, iso_time(v.run.started_unix_ms),
      stated(ctx(v.context, "operator")),
      stated(ctx(v.context.value("conditions", json::object()), "state")));
}

// The state of the machine during the test, and what the sign of a deviation means.
std::string conditions_section(const RunView& v) {
  const json c = v.context.value("conditions", json::object());
  std::string comp = "<span class=\"unstated\">not stated</span>";
  if (c.contains("controller_compensation") && c["controller_compensation"].is_boolean())
    comp = c["controller_compensation"].get<bool>() ? "on (the control's own compensation active)"
                                                    : "off (the machine's errors uncompensated)";
  std::vector<std::vector<std::string>> rows = {{"Controller compensation", comp},
                                                {"Warm-up", stated(ctx(c, "warm_up"))},
                                                {"Load", stated(ctx(c, "load"))},
                                                {"Machine state", stated(ctx(c, "state"))}};
  if (!ctx(c, "notes").empty()) rows.push_back({"Notes", esc(ctx(c, "notes"))});
  const std::string sign =
      v.run.kind == "circle"
          ? "Radial deviation = measured radius &minus; nominal radius: positive outward. Angles "
            "counter-clockwise from the first axis of the plane, seen from the positive third "
            "axis; ccw and cw are the directions of travel (ISO 230-4)."
      : v.run.kind == "straightness"
          ? "Straightness deviation: the indicator's reading across the axis, positive when the "
            "tool is displaced in the positive direction read relative to the workpiece (ISO "
            "230-1; docs/kinematics.md). ↑: approach in the positive direction, ↓: in the "
            "negative."
      : v.run.kind == "ballbar5x"
          ? "Bar reading: the distance between the balls less the bar's nominal length, positive "
            "when the balls are further apart; bar deviation = reading &minus; the test's fitted "
            "bar offset. Angles of the rotary axis as the control commands them. A location "
            "error is the axis average line's position (µm) or tilt (µrad, right-hand rule) "
            "from its nominal place in the machine's model (ISO 230-1; docs/kinematics.md)."
      : v.run.kind == "rotary"
          ? "Angular positional deviation = the angle reached, read by the angular reference, "
            "&minus; the target angle (ISO 230-2 applied to a rotary axis), modulo one turn: "
            "positive when the axis stopped beyond the target in its positive direction of "
            "rotation. ↑: approach in the positive direction, ↓: in the negative."
      : v.run.kind == "angular" || v.run.kind == "roll"
          ? "Angular deviation: the tool's rotation relative to the workpiece about the axis "
            "named by the component, positive by the right-hand rule (ISO 230-1; "
            "docs/kinematics.md). ↑: approach in the positive direction, ↓: in the negative."
          : "Positional deviation x<sub>ij</sub> = actual position reached &minus; target "
            "position (ISO 230-2), the laser reading compensated for the air's refractive index "
            "and the machine's expansion to 20 °C: positive when the axis stopped beyond the "
            "target in its positive direction. ↑: approach in the positive direction, ↓: in the "
            "negative.";
  rows.push_back({"Sign convention", sign});
  return "<h3>Test conditions</h3>\n" + table({"", ""}, rows, "kv");
}

// Where the limits of a run stored without them are set, for its verdict line (`doc`: its
// result): the keys, the table of its axis or plane (a five-axis ballbar run's, of each axis),
// and the file that holds them: the configuration the run started with, or the one given to
// daq model ballbar5x-run --tolerances (the limits in force when a run starts are stored with
// it and judge it; a replay keeps its original run's). A run replayed from a capture whose
// original run is not in this database has none: a capture's header does not carry the
// tolerances. The terminal's sentence marked as HTML (verdict.hpp, to_text of limits_where).
// `several`: of a comparison's runs, `v` the newest.
std::string tolerance_hint(const RunView& v, const json& doc, bool several = false) {
  const auto w = ::daq::limits_where(v.run.kind, v.run.axis, v.settings, doc);
  static constexpr ::daq::LimitsMarkup html{
      .code = [](std::string_view t) { return "<code>" + esc(t) + "</code>"; },
      .path = [](std::string_view t) { return "<span class=\"path\">" + esc(t) + "</span>"; },
      .text = [](std::string_view t) { return esc(t); }};
  const bool each = !w.each.empty() && w.each.size() == w.keys.size();  // a five-axis run's
  std::string h = ::daq::to_text(w, html, several && !each ? "these runs" : "this run",
                                 several ? "the newest" : "it");
  h[0] = 'N';
  h += '.';
  if (each) return h;
  bool orphan_replay = false;  // replayed, of no run in this database
  for (const auto& r : v.results) {
    const json p = json::parse(r.provenance_json, nullptr, false);
    if (p.is_object() && p.value("how", "") == "replayed")
      orphan_replay = p.contains("replay_of_run") && p["replay_of_run"].is_null();
  }
  return orphan_replay ? h + " A replay takes the limits of its original run in the same "
                             "database; this capture's original run is not in it, and a capture "
                             "does not carry the limits."
                       : h;
}

// A rotary axis's location error (ISO 230-1: E_X0C ... of a five-axis ballbar run), by its key.
bool is_location_error(std::string_view key) {
  return key.size() == 5 && key.starts_with("E_") && key[3] == '0' &&
         std::string_view("ABC").find(key[4]) != std::string_view::npos;
}

// A value outside its limit, as the tables print it: "B = 4.023 µm (limit ≤ 3.000 µm)". A
// diagnostic (an error with a direction, what to check) with its sign, a deviation or span (E,
// B, U max, G) without ("U max = +4.023" read as the table's 4.023 with a sign the value does
// not have). `strong`: the symbol in bold (a list's item; inside a bold verdict line, plain).
std::string failing_value(const ::daq::Check& c, bool strong) {
  const std::string symbol = strong ? "<strong>" + esc(c.symbol) + "</strong>" : esc(c.symbol);
  return fmt::format("{} = {} {} (limit ≤ {} {})", symbol,
                     ::daq::diagnostic_advice(c.key).empty() && !is_location_error(c.key)
                         ? um(c.value)
                         : signed_text(c.value, 3),
                     esc(unit_text(c.unit)), fixed(c.limit, 3), esc(unit_text(c.unit)));
}

// What to check first for a value outside its limit: a circle diagnostic's own advice, else, for
// the values of a positioning test (ISO 230-2, VDI/DGQ 3441), the usual cause of each. Empty for
// a value with no single usual cause (straightness, angular, roll: their reports' plots say where).
std::string what_to_check(const ::daq::Check& c) {
  if (auto advice = ::daq::diagnostic_advice(c.key); !advice.empty()) return advice;
  // What the control's kinematics leave of a rotary axis's line: its pivot or its tilt (which
  // LinuxCNC's trunnion pins cannot hold: docs/five-axis-walkthrough.md, section 4).
  if (is_location_error(c.key))
    return c.unit == "um" ? "correct the axis's line in the control's kinematics"
                          : "correct the axis's tilt in the control's kinematics";
  const std::string_view key = c.key;
  const std::string_view head = key.substr(0, key.find('_'));
  // Short enough that "B = 4.023 µm (limit ≤ 3.000 µm): ..." stays one line on page one (a
  // longer advice pushed the suspect report's main plot to page two).
  static constexpr std::pair<std::string_view, std::string_view> kPositioning[] = {
      {"E", "check the pitch error compensation and thermal state"},
      {"M", "check the pitch error compensation"},
      {"A", "check the pitch error compensation, then B and R"},
      {"R", "check the drive and guideways for play, stick-slip"},
      {"B", "check the backlash compensation and the drive's play"},
      {"P", "check the pitch error compensation, then U and Ps"},
      {"Pa", "check the pitch error compensation"},
      {"Ps", "check the drive and guideways for play, stick-slip"},
      {"U", "check the backlash compensation and the drive's play"},
  };
  for (const auto& [k, advice] : kPositioning)
    if (head == k) return std::string(advice);
  return {};
}

// The failing values of a verdict, "; " between them (empty when none fails).
std::string failing_values(const ::daq::Verdict& v, bool strong) {
  std::string h;
  for (const auto& c : v.checks)
    if (!c.pass) h += (h.empty() ? "" : "; ") + failing_value(c, strong);
  return h;
}

// The verdict of a result as a coloured line: pass, fail, or no tolerance configured (then
// `hint`: which limits would judge it and where they are set, tolerance_hint).
std::string verdict_banner(const ::daq::Verdict& v, const std::string& hint) {
  if (!v.configured) {
    std::string h =
        v.notes.empty()
            ? "<p class=\"verdict none\"><strong>No tolerance configured</strong> for this test: "
              "the results are not judged. " +
                  hint + "</p>\n"
            : "<p class=\"verdict none\"><strong>No tolerance applies</strong>: the configured "
              "limits are for values this evaluation does not give, so the results are not "
              "judged.</p>\n";
    for (const auto& n : v.notes) h += "<p class=\"note\">" + esc(n) + "</p>\n";
    return h;
  }
  std::string h = fmt::format(
      "<p class=\"verdict {}\">Verdict against the machine specification ({}): "
      "<strong>{}</strong>{}</p>\n",
      v.pass ? "pass" : "fail", esc(v.basis), v.pass ? "PASS" : "FAIL",
      v.pass ? " &mdash; every limited value within its limit"
             : fmt::format(" &mdash; {} of {} limited values outside their limits",
                           std::count_if(v.checks.begin(), v.checks.end(),
                                         [](const auto& c) { return !c.pass; }),
                           v.checks.size()));
  if (!v.pass) {
    // The failing values on page one, each with its limit: why the machine did not pass.
    std::string items;
    for (const auto& c : v.checks)
      if (!c.pass) {
        const auto advice = what_to_check(c);
        items +=
            "<li>" + failing_value(c, true) + (advice.empty() ? "" : ": " + esc(advice)) + "</li>";
      }
    h += "<ul class=\"failing\">" + items + "</ul>\n";
  }
  for (const auto& n : v.notes) h += "<p class=\"note\">" + esc(n) + "</p>\n";
  return h;
}

std::string verdict_cell(const ::daq::Check* c) {
  if (!c) return "<span class=\"unstated\">&ndash;</span>";
  return c->pass ? "<span class=\"pass\">pass</span>" : "<span class=\"fail\">FAIL</span>";
}
std::string limit_cell(const ::daq::Check* c) {
  return c ? "≤ " + fixed(c->limit, 3) : "<span class=\"unstated\">&ndash;</span>";
}

// How the results shown were obtained: the current result's provenance; for a re-compensated
// run the coefficients and offsets as acquired beside those used now, and the original values.
std::string provenance_section(const RunView& v, std::string_view schema) {
  const auto current = ::daq::current_result(v.results, schema);
  std::string h = "<h3>How these results were obtained</h3>\n";
  if (!current)
    return h +
           "<p>No result is stored with this run: the values below are evaluated from the "
           "stored data now.</p>\n";
  const json p = json::parse(current->provenance_json, nullptr, false);
  std::vector<std::vector<std::string>> rows;
  const std::string how = p.is_object() ? p.value("how", "") : "";
  rows.push_back(
      {"Current result", fmt::format("result {} ({}), stored {}", current->id,
                                     esc(current->standard), iso_time(current->created_unix_ms))});
  rows.push_back(
      {"Obtained", how.empty() ? "not recorded (stored before provenance was)" : esc(how)});
  if (p.is_object() && p.contains("software"))
    rows.push_back({"Software", esc(p.value("software", ""))});
  if (p.is_object() && p.contains("replay_of_run"))
    rows.push_back({"Replay of",
                    p["replay_of_run"].is_null()
                        ? "a capture whose original run is not in this database"
                        : fmt::format("run {} (capture {})", p["replay_of_run"].get<std::int64_t>(),
                                      esc(p.value("capture", "")))});
  if (p.is_object() && p.contains("of_result") && !p["of_result"].is_null())
    rows.push_back(
        {"Re-compensation of", fmt::format("result {}", p["of_result"].get<std::int64_t>())});
  for (const auto& a : v.approvals)
    if (a.result_id == current->id)
      rows.push_back({"Approved",
                      fmt::format("by {} on {}{}", esc(a.approved_by), iso_time(a.approved_unix_ms),
                                  a.central_server.empty() ? "" : ", on the central server")});
  std::size_t older = 0;
  for (const auto& r : v.results) older += r.current() ? 0 : 1;
  if (older)
    rows.push_back(
        {"Earlier results", fmt::format("{} kept, superseded (daq show {})", older, v.run.id)});
  h += table({"", ""}, rows, "kv");
  if (v.run.kind != "linear") return h;
  // Coefficients and offsets: as acquired, and used by the current result.
  const json env = v.settings.value("environment", json::object());
  const auto& u = v.used;
  std::vector<std::vector<std::string>> coeff;
  const auto row = [&](const char* name, const std::string& acquired, const std::string& now) {
    const bool changed = acquired != now;
    coeff.push_back({name, esc(acquired),
                     changed ? "<span class=\"changed\">" + esc(now) + "</span>" : esc(now)});
  };
  row("Refractive index equation", equation_name(env.value("equation", "ciddor")),
      equation_name(u.coefficients.value("equation", "ciddor")));
  row("Expansion coefficient (ppm/K)", setting_text(env.value("expansion_ppm_per_k", json(11.5))),
      setting_text(u.coefficients.value("expansion_ppm_per_k", json(11.5))));
  row("CO2 (µmol/mol)", setting_text(env.value("co2_umol_per_mol", json(450))),
      setting_text(u.coefficients.value("co2_umol_per_mol", json(450))));
  row("Wavelength (nm)", setting_text(env.value("wavelength_nm", json(632.991))),
      setting_text(u.coefficients.value("wavelength_nm", json(632.991))));
  row("Material temperature offset (K)", "0", fmt::format("{:g}", u.offsets.material_k));
  row("Air temperature offset (K)", "0", fmt::format("{:g}", u.offsets.air_temperature_k));
  row("Pressure offset (Pa)", "0", fmt::format("{:g}", u.offsets.pressure_pa));
  row("Humidity offset (%RH)", "0", fmt::format("{:g}", u.offsets.humidity_pct));
  h += "<h4>Compensation used</h4>\n" +
       table({"coefficient", "as acquired", "used by the current result"}, coeff, "num", "lrr");
  if (!u.recompensated) return h;
  // The values before and after: the acquired result (the first of the schema) against now.
  const st::ResultRecord* original = nullptr;
  for (const auto& r : v.results) {
    const json d = json::parse(r.json, nullptr, false);
    if (d.is_object() && d.value("schema", "") == schema) {
      original = &r;
      break;
    }
  }
  if (!original || original->id == current->id) return h;
  // In the order of every output (result_rows.hpp), not the stored object's (by key).
  const auto a = ::daq::linear_rows(json::parse(original->json, nullptr, false));
  const auto b = ::daq::linear_rows(json::parse(current->json, nullptr, false));
  std::vector<std::vector<std::string>> vals;
  for (const auto& x : a)
    for (const auto& y : b)
      if (y.key == x.key)
        vals.push_back(
            {esc(x.symbol), um(x.value), um(y.value), signed_text(y.value - x.value, 3)});
  h += fmt::format("<h4>Original (result {}) and re-compensated (result {}) values</h4>\n",
                   original->id, current->id) +
       table({"value", "original (µm)", "re-compensated (µm)", "change (µm)"}, vals, "num", "lrrr");
  return h;
}

// Headline numbers of a run, for the campaign summary and the comparison trends.
struct Headline {
  struct Value {
    std::string symbol;
    double value = 0;
    std::string unit;        // as printed: "µm", "µm/m", "ms"
    bool failing = false;    // outside its limit: the campaign summary always shows it, marked
    bool is_signed = false;  // printed with its sign (a diagnostic), as the run's own tables do
  };
  std::vector<Value> values;
  std::string standard;
  std::string verdict;  // PASS, FAIL, no tolerance configured
  // The ISO 230-1 error the run measured, for a volumetric campaign's summary of its 21 errors:
  // a positioning run's E (E_XX), a straightness about its least-squares line (E_YX), an
  // angular deviation (E_BX). Empty component: the run measured none of them.
  struct Error {
    std::string component, unit;  // "E_YX", "µm"
    double value = 0;
    std::optional<double> limit;  // in unit, where the run's tolerances give one
    bool pass = false;
  } error;
};

// The check of a result row as the summary of the 21 errors takes it.
void set_error(Headline::Error& e, std::string component, double value, std::string unit,
               const ::daq::Check* c) {
  e = {.component = std::move(component), .unit = std::move(unit), .value = value};
  if (c) e.limit = c->limit, e.pass = c->pass;
}

// --- ISO 230-2
// ------------------------------------------------------------------------------------

struct Linear {
  std::vector<st::CapturedTarget> targets;
  cal::iso230_2::Evaluation e;
  AxisText text = linear_text;
};

Linear evaluate_linear(const st::RunReader& store, const RunView& v, const Options& o) {
  std::string note;  // a rotary run stored the old way (its stops' angles), read as deviations
  Linear l{.targets = ::daq::stored_targets(store, v.run, &note), .text = axis_text(v)};
  if (l.targets.empty())
    throw cal::InputError(
        fmt::format("{}: run {} has no captured targets to report", store.name(), v.run.id));
  const std::string key =
      !o.standard.empty() ? o.standard : v.settings.value("standard", "iso230-2:2014");
  try {
    l.e = cal::iso230_2::evaluate(::daq::measurements(l.targets),
                                  cal::iso230_2::standard_from_string(key));
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: run {} ({} captured stops): {}", store.name(), v.run.id,
                                      l.targets.size(), e.what()));
  }
  if (!note.empty()) l.e.warnings.push_back(note);
  return l;
}

// The budget of ISO 230-2 Annex A for this run's travel and measured air; what was not
// measured is stated in the report, not hidden.
cal::unc::Budget linear_budget(const RunView& v, const Linear& l, double& length_m) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& t : l.targets) lo = std::min(lo, t.nominal_mm), hi = std::max(hi, t.nominal_mm);
  length_m = std::max((hi - lo) * 1e-3, 1e-3);
  cal::unc::PositioningSetup s{.length_m = length_m};
  // The coefficients and sensor offsets the current result used (a re-compensated run's, not
  // the ones it was acquired with).
  const auto& c = v.used.coefficients;
  const auto& off = v.used.offsets;
  s.equation = cal::air::equation_from_string(c.value("equation", "ciddor"));
  s.alpha_per_k = c.value("expansion_ppm_per_k", 11.5) * 1e-6;
  if (!v.env.air_temperature.empty())
    s.air.temperature_degc = stats(v.env.air_temperature).mean + off.air_temperature_k;
  if (!v.env.pressure_hpa.empty())
    s.air.pressure_pa = stats(v.env.pressure_hpa).mean * 100.0 + off.pressure_pa;
  if (!v.env.humidity.empty())
    s.air.humidity =
        cal::air::Humidity::relative_pct(stats(v.env.humidity).mean + off.humidity_pct);
  s.air.co2_umol_per_mol = c.value("co2_umol_per_mol", 450.0);
  s.air.wavelength_vacuum_nm = c.value("wavelength_nm", 632.991);
  if (!v.env.material_temperature.empty())
    s.material_degc = stats(v.env.material_temperature).mean + off.material_k;
  return cal::unc::positioning_budget(s);
}

// The main plot of a linear run: the mean deviations with their ±2s bands.
std::string means_plot(const Linear& l) {
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
                .x_label = std::string(l.text.x_label),
                .y_label = fmt::format("deviation ({})", l.text.deviation),
                .height_pt = 170,  // page one holds it below the verdict and the grid
                .zero_line = true};
  // The bands x̄ ± 2s, and their edges drawn as thin dotted lines so they read in print too.
  means.bands.push_back(
      {.x = x, .lo = up_lo, .hi = up_hi, .label = "", .colour = blue, .alpha = 0.12});
  means.lines.push_back(
      {.x = x, .y = up_hi, .label = "x̄↑ ± 2s", .colour = blue, .width = 0.8, .dashed = true});
  means.lines.push_back({.x = x, .y = up_lo, .colour = blue, .width = 0.8, .dashed = true});
  means.lines.push_back({.x = x, .y = up, .label = "x̄↑", .colour = blue, .markers = true});
  if (e.bidirectional) {
    means.bands.push_back(
        {.x = x, .lo = down_lo, .hi = down_hi, .label = "", .colour = vermilion, .alpha = 0.12});
    means.lines.push_back({.x = x,
                           .y = down_hi,
                           .label = "x̄↓ ± 2s",
                           .colour = vermilion,
                           .width = 0.8,
                           .dashed = true});
    means.lines.push_back(
        {.x = x, .y = down_lo, .colour = vermilion, .width = 0.8, .dashed = true});
    means.lines.push_back({.x = x, .y = down, .label = "x̄↓", .colour = vermilion, .markers = true});
    means.lines.push_back({.x = x,
                           .y = bi,
                           // Short enough for three columns of legend ("x̄ (bidirectional)"
                           // took two, three rows, and the plot off a suspect run's page one).
                           .label = "x̄ ↑↓",
                           .colour = black,
                           .width = 1.0,
                           .dashed = true});
  }
  // One line of caption (the legend names the lines): a suspect run's page one holds it too.
  return figure(svg(means),
                "Bands x̄ ± 2s, s: the estimator of the unidirectional repeatability; x̄ ↑↓: the "
                "mean bidirectional deviation.");
}

std::string runs_plot(const Linear& l) {
  // Run by run: one line per run and direction, in the order of the targets.
  std::map<std::pair<int, char>, std::vector<std::pair<double, double>>> runs;
  for (const auto& t : l.targets)
    runs[{t.run_number, t.direction}].push_back({t.nominal_mm, t.deviation_um});
  XyChart traces{.title = "Run-by-run deviations",
                 .x_label = std::string(l.text.x_label),
                 .y_label = fmt::format("deviation ({})", l.text.deviation),
                 .height_pt = 300,
                 .zero_line = true};
  // Each run and direction its own style: the run's colour, ↑ solid with filled triangles, ↓
  // dashed with open ones (the two directions of a run, in one colour, told apart only by a
  // dash the marks hid, read as one colour repeated).
  for (auto& [key, pts] : runs) {
    std::sort(pts.begin(), pts.end());
    const auto style =
        paired_style(static_cast<std::size_t>(std::max(key.first - 1, 0)), key.second == '-');
    Line line{.label = fmt::format("run {} {}", key.first, key.second == '+' ? "↑" : "↓"),
              .colour = style.colour,
              .width = 1.0,
              .dashed = style.dashed,
              .markers = true,
              .marker = style.marker};
    for (const auto& [px, py] : pts) line.x.push_back(px), line.y.push_back(py);
    traces.lines.push_back(std::move(line));
  }
  return figure(svg(traces),
                "Every captured deviation x_ij: solid lines and filled marks approach in the "
                "positive direction (↑), dashed lines and open marks in the negative (↓).");
}

// The ISO 230-2 values as a grid: one row per kind of value, columns up, down and
// bidirectional, then the limit and verdict of the value the specification limits. Standards
// with other values (VDI/DGQ 3441) get a list.
std::string results_grid(const cal::iso230_2::Evaluation& e, const ::daq::Verdict& verdict,
                         std::string_view unit) {
  const auto value = [&](const char* key) -> const cal::iso230_2::AxisResult* {
    for (const auto& a : e.axis)
      if (a.key == key) return &a;
    return nullptr;
  };
  const auto cell = [&](const char* key) {
    const auto* a = key ? value(key) : nullptr;
    return a ? um(a->value_um) : std::string("<span class=\"unstated\">&ndash;</span>");
  };
  const struct {
    const char* name;
    const char* up;
    const char* down;
    const char* bi;
  } grid[] = {{"E &mdash; systematic positional deviation", "E_up", "E_down", "E_bi"},
              {"R &mdash; repeatability (±2s)", "R_up", "R_down", "R_bi"},
              {"A &mdash; accuracy (±2s)", "A_up", "A_down", "A_bi"},
              {"M &mdash; range of the mean bidirectional deviation", nullptr, nullptr, "M"},
              {"B &mdash; reversal value, max |B<sub>i</sub>|", nullptr, nullptr, "B"},
              {"B̄ &mdash; mean reversal value", nullptr, nullptr, "B_mean"}};
  std::vector<std::vector<std::string>> rows;
  std::size_t shown = 0;
  for (const auto& g : grid) {
    if (!value(g.up ? g.up : "") && !value(g.down ? g.down : "") && !value(g.bi)) continue;
    const ::daq::Check* c = ::daq::find_check(verdict, g.bi);
    if (!c && g.up) c = ::daq::find_check(verdict, g.up);
    rows.push_back({g.name, cell(g.up), cell(g.down), cell(g.bi), limit_cell(c), verdict_cell(c)});
    ++shown;
  }
  if (shown == 0) {  // another standard's values (VDI/DGQ 3441), with the limits it takes
    std::vector<std::vector<std::string>> axis;
    for (const auto& r : ::daq::linear_rows(::daq::to_json(e))) {
      const ::daq::Check* c = ::daq::find_check(verdict, r.key);
      axis.push_back(
          {esc(r.symbol), um(r.value), esc(r.description), limit_cell(c), verdict_cell(c)});
    }
    return table({"symbol", fmt::format("value ({})", unit), "meaning",
                  fmt::format("limit ({})", unit), "verdict"},
                 axis, "num results", "lrlrl");
  }
  return table({fmt::format("value ({})", unit), "↑&nbsp;up", "↓&nbsp;down", "bidirectional",
                fmt::format("limit&nbsp;({})", unit), "verdict"},
               rows, "num results grid", "lrrrrl");
}

// A rotary run's caldaq.rotary.v1 document: the stored current result (what daq show prints),
// else (or by another standard) the same evaluation of its stored stops now.
json rotary_doc(const st::RunReader& store, const RunView& v, const Options& o) {
  const auto stored = ::daq::current_result(v.results, "caldaq.rotary.v1");
  if (stored && o.standard.empty()) return cal::daq::parse_stored_json(stored->json);
  return ::daq::stored_rotary(store, v.run, o.standard);
}

// The instruments of a run's context with a role ("angle", "laser"), as the configuration named
// them.
std::vector<json> instruments_with_role(const RunView& v, std::string_view role) {
  std::vector<json> out;
  for (const auto& i : v.context.value("instruments", json::array()))
    if (i.is_object() && ctx(i, "role") == role) out.push_back(i);
  return out;
}

std::string instrument_text(const json& i) {
  std::string t = "<strong>" + esc(ctx(i, "id")) + "</strong> (" + esc(ctx(i, "driver")) + ")";
  if (!ctx(i, "serial_number").empty()) t += ", serial number " + esc(ctx(i, "serial_number"));
  if (!ctx(i, "certificate").empty()) t += ", certificate " + esc(ctx(i, "certificate"));
  return t;
}

// What a rotary run's angular reference is ([test.linear] reference, docs/config.md): "laser",
// "autocollimator", "level", "encoder", or "" (not stated).
std::string angular_reference_kind(const RunView& v) {
  const json m = v.settings.value("measure", json::object());
  return m.is_object() ? ctx(m, "reference") : "";
}

std::string angular_reference_kind_text(std::string_view kind) {
  if (kind == "laser") return "a laser's angular optics over a rotary indexer";
  if (kind == "autocollimator") return "an autocollimator on a polygon";
  if (kind == "level") return "an electronic level";
  if (kind == "encoder") return "a reference encoder (an indexer's readout)";
  return "<span class=\"unstated\">its kind not stated</span> (<code>reference</code> in "
         "[test.linear], docs/config.md)";
}

// A rotary run's angular reference, as configured (the device with role "angle", what it is,
// and the laser when it is a laser's angular optics), on page one.
std::string angular_reference_line(const RunView& v) {
  const std::string kind = angular_reference_kind(v);
  std::vector<std::string> devices;
  for (const auto& i : instruments_with_role(v, "angle")) devices.push_back(instrument_text(i));
  if (kind == "laser")
    for (const auto& i : instruments_with_role(v, "laser"))
      devices.push_back("the laser " + instrument_text(i));
  return fmt::format("<p>Angular reference: {}, {}.</p>\n",
                     devices.empty() ? "<span class=\"unstated\">its device not recorded</span>"
                                     : fmt::format("{}", fmt::join(devices, "; ")),
                     angular_reference_kind_text(kind));
}

// The air's refractive index of a rotary run read with a laser's angular optics (the laser's
// wavelength in air scales the angle it reads), from the run's air readings by the configured
// equation; an autocollimator, level or encoder reads no wavelength in air: it does not apply.
std::string refractive_index_text(const RunView& v) {
  if (v.env.air_temperature.empty() || v.env.pressure_hpa.empty())
    return "<span class=\"unstated\">not known: the run stored no air temperature and "
           "pressure</span>";
  // As the linear budget reads the air (with the sensors' stored offsets).
  const auto& c = v.used.coefficients;
  const auto& off = v.used.offsets;
  cal::air::Conditions air{
      .temperature_degc = stats(v.env.air_temperature).mean + off.air_temperature_k,
      .pressure_pa = stats(v.env.pressure_hpa).mean * 100.0 + off.pressure_pa,
      .co2_umol_per_mol = c.value("co2_umol_per_mol", 450.0),
      .wavelength_vacuum_nm = c.value("wavelength_nm", 632.991)};
  if (!v.env.humidity.empty())
    air.humidity = cal::air::Humidity::relative_pct(stats(v.env.humidity).mean + off.humidity_pct);
  try {
    const auto eq = cal::air::equation_from_string(c.value("equation", "ciddor"));
    return fmt::format(
        "{:.8f} ({}, from the run's mean air temperature {:.2f} °C, pressure {:.2f} hPa, {}); "
        "the angles arrive evaluated by the reference's own software: caldaq does not "
        "compensate them",
        cal::air::refractive_index(air, eq).n, esc(cal::air::to_string(eq)), air.temperature_degc,
        air.pressure_pa / 100.0,
        v.env.humidity.empty() ? std::string("humidity not measured: 50 %RH")
                               : fmt::format("humidity {:.1f} %RH", air.humidity.value));
  } catch (const cal::InputError& e) {
    return esc(e.what());
  }
}

std::string angular_reference_details(const RunView& v) {
  const std::string kind = angular_reference_kind(v);
  std::vector<std::vector<std::string>> rows;
  for (const auto& i : instruments_with_role(v, "angle"))
    rows.push_back({"Angular reference (role angle)", instrument_text(i)});
  rows.push_back({"What it is", angular_reference_kind_text(kind)});
  if (kind == "laser")
    for (const auto& i : instruments_with_role(v, "laser"))
      rows.push_back({"Laser", instrument_text(i)});
  rows.push_back(
      {"Refractive index of the air",
       kind == "laser" ? refractive_index_text(v)
       : kind.empty()
           ? "applies to a laser's angular optics only; the configuration does not say what the "
             "reference is"
           : fmt::format("does not apply: {} reads no wavelength in air",
                         angular_reference_kind_text(kind))});
  return "<h4>Angular reference</h4>\n" + table({"", ""}, rows, "kv");
}

// A run's results in two parts: the answer (page one: verdict, main table, main plot) and the
// details that support it.
struct Sections {
  std::string answer, details;
  // The details follow the answer without a page break: a circle's answer fills page one, and
  // the break left page two with the last three lines of "What to fix first".
  bool details_flow = false;
};

// A rotary axis's angular positioning run (ISO 230-2 in deg and arcsec) is reported as a
// linear axis's is, in its units, without the laser's uncertainty budget (an angular reference
// has its own): its values are the stored caldaq.rotary.v1 document's, the numbers daq show
// prints.
Sections linear_section(const st::RunReader& store, const RunView& v, const Options& o,
                        Headline& headline) {
  const auto l = evaluate_linear(store, v, o);
  const auto& e = l.e;
  const bool rotary = v.run.kind == "rotary";
  const std::string unit(l.text.deviation), position(l.text.position);
  headline.standard = std::string(e.standard.title);
  Sections out;
  std::string& h = out.answer;
  h = fmt::format(
      "<h3>Results: {}{}</h3>\n<p class=\"standard\">Evaluated by <strong>{}</strong> ({}). {} "
      "targets, {}, {}{}.</p>\n",
      esc(e.standard.title),
      rotary ? " &mdash; angular positioning of axis " + esc(v.run.axis) : "",
      esc(e.standard.title), esc(e.standard.note), e.targets.size(), esc(::daq::runs_text(e)),
      e.bidirectional ? "bidirectional" : "unidirectional",
      rotary ? "; targets in degrees, deviations in arcseconds" : "");
  // The headline (campaign summary): the bidirectional values a specification limits, or
  // every value of a standard without them (VDI/DGQ 3441).
  const auto doc = rotary ? rotary_doc(store, v, o) : ::daq::to_json(e);
  const auto values = ::daq::result_rows(doc);
  const auto verdict = ::daq::verdict_of(v.settings, doc);
  const auto failing = [&](const auto& r) {
    const auto* check = ::daq::find_check(verdict, r.key);
    return check && !check->pass;
  };
  for (const auto& r : values)
    if (r.key == "E_bi" || r.key == "R_bi" || r.key == "A_bi" || r.key == "M" || r.key == "B" ||
        r.key == "B_mean" || failing(r))
      headline.values.push_back({r.symbol, r.value, unit_text(r.unit), failing(r)});
  if (headline.values.empty())
    for (const auto& r : values)
      headline.values.push_back({r.symbol, r.value, unit_text(r.unit), failing(r)});
  headline.verdict = ::daq::summary(verdict);
  if (!rotary)
    for (const auto& r : values)
      if (r.key == "E_bi" || (r.key == "E_up" && !e.bidirectional))
        set_error(headline.error,
                  ctx(v.settings.value("measure", json::object()), "component").empty()
                      ? "E_" + v.run.axis + v.run.axis
                      : ctx(v.settings.value("measure", json::object()), "component"),
                  r.value, unit, ::daq::find_check(verdict, r.key));
  if (rotary) h += angular_reference_line(v);
  // The limits that would judge it, of this standard, in the axis's unit.
  h += verdict_banner(verdict, tolerance_hint(v, doc));
  h += results_grid(e, verdict, unit);
  h += means_plot(l);
  std::string& d = out.details;
  d = "<h3>Details of the results</h3>\n";
  if (e.axis.size() && e.axis.front().key.find('_') != std::string::npos)  // up, down, bi
    d += "<p class=\"note\">Unidirectional values (↑, ↓) of the grid on page one come from the "
         "approaches in one direction; the limits apply to the bidirectional values (ISO "
         "230-2).</p>\n";
  // The per-target table first: it follows the main plot on page one (its rows may break over
  // to page two, the run-by-run plot may not), so page one has no third left blank.
  out.details_flow = true;
  std::vector<std::string> head{fmt::format("target ({})", position)};
  for (const auto& p : e.per_target) head.push_back(esc(p.symbol) + " (" + unit + ")");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < e.targets.size(); ++i) {
    std::vector<std::string> r{fmt::format("{:.3f}", e.targets[i].target_mm)};
    for (const auto& p : e.per_target) r.push_back(um(p.values_um[i]));
    rows.push_back(std::move(r));
  }
  d += "<h4>Per target</h4>\n" + table(head, rows, "num");
  d += runs_plot(l);
  for (const auto& w : e.warnings) d += "<p class=\"warning\">Warning: " + esc(w) + "</p>\n";
  if (rotary) {
    d += angular_reference_details(v);
    d += "<p class=\"note\">Each stop's deviation is its angular reference's reading minus the "
         "target, modulo one turn (so 360 deg reads as 0 deg on the reference). The laser's "
         "uncertainty budget (ISO 230-2 Annex A) does not apply to an angular reference: state "
         "its own calibration's uncertainty with the results.</p>\n";
    return out;
  }

  double length_m = 0;
  const auto b = linear_budget(v, l, length_m);
  std::vector<std::vector<std::string>> contrib;
  for (const auto& c : b.contributors) {
    // The refractive-index equation's own uncertainty by the equation's name ("ciddor
    // equation" is the budget's key for it): "Ciddor (1996) equation".
    const auto space = c.name.find(' ');
    const std::string name = c.name.ends_with(" equation") && space != std::string::npos
                                 ? equation_name(c.name.substr(0, space)) + c.name.substr(space)
                                 : c.name;
    contrib.push_back({esc(name), fmt::format("{:.4f}", c.u_um), esc(::daq::units_html(c.model))});
  }
  d += fmt::format(
      "<h3>Measurement uncertainty</h3>\n<p>Of a positional deviation at the measured travel "
      "L = {:.3f} m (ISO 230-2 Annex A, ISO/TR 230-9): combined standard uncertainty "
      "u<sub>c</sub> = {:.4f} µm, <strong>expanded uncertainty U = {:.3f} µm (k = {:g})</strong>."
      "</p>\n",
      length_m, b.u_combined_um, b.expanded_um, b.k);
  d += table({"contributor", "u (µm)", "model"}, contrib, "num", "lrl");
  d += "<p class=\"note\">Air and material values are the means measured during this run. "
       "Assumed, not measured with the run: laser certificate 0.1 ppm (k = 2), sensor standard "
       "uncertainties 0.1 K, 10 Pa, 2 %RH, expansion coefficient ±1 ppm/K; no environmental "
       "variation (drift) test, misalignment or dead path was recorded, so they are not in the "
       "budget. Use <code>daq uncertainty</code> with the actual values to revise it.</p>\n";
  for (const auto& w : b.warnings) d += "<p class=\"warning\">Warning: " + esc(w) + "</p>\n";
  headline.values.push_back({"U (k=2)", b.expanded_um, "µm"});
  return out;
}

// --- ISO 230-4
// --------------------------------------------------------------------------------------

struct Circle {
  cal::daq::BallbarProgram program;
  ::daq::BallbarAnalysis analysis;
  // What the polar plot draws: every step-th sample of each trace (at most ~3600 points a
  // trace, 0.1 degree: more cannot be seen and would bloat the file), taken as the trace is
  // read, so the report holds no run-sized array (issue 32).
  std::vector<cal::circle::Trace> traces;
  cal::circle::Result result;
};

// A circular standard asked for in the options (a key of daq analyse --standard) replaces the
// run's own; a linear standard there is for the linear runs of a campaign and is ignored here.
std::string circular_key(const Options& o, std::string fallback) {
  if (o.standard.empty()) return fallback;
  try {
    cal::circle::circular_standard_from_key(o.standard);
    return o.standard;
  } catch (const cal::InputError&) {
    return fallback;
  }
}

Circle analyse_circle(const st::RunReader& store, const RunView& v, const Options& o) {
  if (!v.settings.contains("radius_mm"))
    throw cal::InputError(
        fmt::format("{}: run {}: its circle settings are missing", store.name(), v.run.id));
  auto [program, analysis] = ::daq::circle_settings_from_json(v.settings);
  analysis.standard = circular_key(o, analysis.standard);
  Circle c{.program = program, .analysis = analysis};
  const auto segmenter = ::daq::segment_stored_run(store, v.run.id, program);
  try {
    const auto sources = segmenter.sources();
    for (const auto& t : sources) {
      cal::circle::Trace shown{t.direction(), {}, {}};
      const std::size_t step = std::max<std::size_t>(1, t.size() / 3600);
      for (std::size_t i = 0; i < t.size(); i += step) {
        shown.angle_deg.push_back(t.angle_deg(i));
        shown.deviation_um.push_back(t.deviation_um(i));
      }
      c.traces.push_back(std::move(shown));
    }
    c.result = ::daq::analyse_traces(program, analysis, sources);
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: run {} ({} bar readings): {}", store.name(), v.run.id,
                                      segmenter.samples(), e.what()));
  }
  return c;
}

// The text of a polar plot shown beside a table (CSS .pair: half the page's width, 253 pt of
// its 400): 11 pt times 1.4 prints at 9.7 pt.
constexpr double polar_beside_text_scale = 1.4;

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
    // "ccw" and "cw", as G (ccw) and G (cw) name them: "counter-clockwise" took the legend to
    // one column a row beside the values table, which pushed what to fix first off page one.
    Line l{.label = std::string(label_prefix) +
                    (t.direction == cal::circle::Direction::ccw ? "ccw" : "cw"),
           .colour = palette(colour_offset + (t.direction == cal::circle::Direction::ccw ? 0 : 1)),
           .width = 1.2};
    // Every point of the trace as analyse_circle decimated it.
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i) {
      const double th = t.angle_deg[i] * std::numbers::pi / 180.0;
      l.x.push_back(t.angle_deg[i]);
      l.y.push_back(t.deviation_um[i] - cu * std::cos(th) - cv * std::sin(th));
    }
    p.traces.push_back(std::move(l));
  }
  return p;
}

// Where the absolute radius came from: the stored calibration (bar, calibrator, reading, date,
// its age at the test), a length given in the configuration or on the command line, or none:
// then the radius error is not evaluated and F is relative to the bar's assumed length.
std::string bar_calibration_section(const Circle& c, const RunView& v) {
  const auto& a = c.analysis;
  std::string h = "<h3>Bar calibration</h3>\n";
  if (a.uncalibrated || !a.calibrated_radius_mm)
    return h + fmt::format(
                   "<p class=\"warning\"><strong>The radius error is not evaluated</strong>: {}. "
                   "G, the diagnostics and the squareness do not need the bar's absolute length; "
                   "F max and F min are deviations from the bar's assumed length, not from an "
                   "absolute radius.</p>\n",
                   esc(a.uncalibrated_reason.empty() ? std::string("the bar was not calibrated")
                                                     : a.uncalibrated_reason));
  if (!a.calibration)
    return h + fmt::format(
                   "<p>The bar's calibrated length {:.4f} mm (it reads 0 at that length) was "
                   "given {}: no calibration record (calibrator, date) is stored with it.</p>\n",
                   *a.calibrated_radius_mm,
                   a.calibration_source == "option" ? "on the command line (daq analyse "
                                                      "--calibrated-radius-mm)"
                                                    : "in the configuration");
  const auto& k = *a.calibration;
  const double age_days =
      static_cast<double>(v.run.started_unix_ms - k.calibrated_unix_ms) / 86'400'000.0;
  const std::vector<std::vector<std::string>> rows = {
      {"bar", esc(k.bar) + (k.extensions.empty() ? "" : " with " + esc(k.extensions))},
      {"nominal length", fmt::format("{:.3f} mm", k.nominal_mm)},
      {"calibrator", (k.calibrator.empty() ? std::string("not stated") : esc(k.calibrator)) +
                         fmt::format(", {:.4f} mm", k.calibrator_length_mm)},
      {"reading in the calibrator", fmt::format("{:+.4f} mm", k.reading_mm)},
      {"calibrated length (reads 0 at)", fmt::format("{:.4f} mm", k.zero_length_mm)},
      {"temperature", k.temperature_degc ? fmt::format("{:.2f} °C (recorded, not corrected for)",
                                                       *k.temperature_degc)
                                         : std::string("not recorded")},
      {"date", fmt::format("{} ({:.0f} days before the test)", iso_time(k.calibrated_unix_ms),
                           std::max(0.0, age_days))},
      {"record", fmt::format("calibration {} (daq ballbar calibrations)", k.id)}};
  return h + "<p>The absolute radius (the radius error, F) uses this stored calibration:</p>\n" +
         table({"", ""}, rows, "kv");
}

// The order of page one's "what to fix first": every error outside its configured limit (the
// furthest over first), then the others whose correction alone would gain most in G (their
// contribution to the circularity), up to `top` rows; indices into r.diagnostics.
std::vector<std::size_t> fix_first_order(const cal::circle::Result& r,
                                         const ::daq::Verdict& verdict, std::size_t top) {
  std::vector<std::size_t> failing, gaining;
  for (std::size_t i = 0; i < r.diagnostics.size(); ++i) {
    const auto* check = ::daq::find_check(verdict, r.diagnostics[i].key);
    if (check && !check->pass)
      failing.push_back(i);
    else if (std::round(r.diagnostics[i].g_reduction_um * 1e3) > 0)
      gaining.push_back(i);
  }
  const auto over = [&](std::size_t i) {
    const auto* c = ::daq::find_check(verdict, r.diagnostics[i].key);
    return c->limit > 0 ? std::abs(c->value) / c->limit : std::abs(c->value);
  };
  std::stable_sort(failing.begin(), failing.end(),
                   [&](std::size_t a, std::size_t b) { return over(a) > over(b); });
  for (std::size_t i : gaining)
    if (failing.size() < top) failing.push_back(i);
  return failing;
}

// The diagnostics as a table: rank, error, value in its own unit, what correcting it would
// gain (µm and share of G), PV, limit and verdict, and what to check. `top`: page one's "what
// to fix first" (fix_first_order), else every error in the ranking by gain. The rank is the
// error's place in the one ranking by gain (r.diagnostics' order) in both tables: page one
// numbered its rows 1, 2, 3 in its own order (a failing backlash first), so its "1" was the
// details' "8".
std::string diagnostics_table(const cal::circle::Result& r, const ::daq::Verdict& verdict,
                              std::size_t top) {
  std::vector<std::size_t> order;
  if (top)
    order = fix_first_order(r, verdict, top);
  else
    for (std::size_t i = 0; i < r.diagnostics.size(); ++i) order.push_back(i);
  std::vector<std::vector<std::string>> diag;
  const double g = r.iso.G_bi_um;
  for (std::size_t i : order) {
    const auto& d = r.diagnostics[i];
    const auto* check = ::daq::find_check(verdict, d.key);
    const std::string share = g > 0 ? fixed(100.0 * d.g_reduction_um / g, 0) : "&ndash;";
    const auto advice = ::daq::diagnostic_advice(d.key);
    const std::string check_text = advice.empty() ? std::string("see docs/circle.md") : esc(advice);
    const std::string failing =
        check && !check->pass
            ? fmt::format(
                  " <span class=\"fail\">FAIL</span> <span class=\"nw\">(limit ≤ {} "
                  "{})</span>",
                  fixed(check->limit, 3), esc(unit_text(check->unit)))
            : std::string();
    // Page one's rows: the error with what to check under it (a column of its own was squeezed
    // to a word a line).
    std::vector<std::string> row{
        std::to_string(i + 1),
        top ? "<strong>" + esc(d.name) + "</strong>" + failing + "<br><span class=\"note\">" +
                  check_text + "</span>"
            : esc(d.name),
        "<span class=\"nw\">" + signed_text(d.value, 3) + " " + esc(unit_text(d.unit)) + "</span>",
        top ? fmt::format("<span class=\"nw\">{} µm ({} %)</span>",
                          signed_text(d.g_reduction_um, 3), share)
            : signed_text(d.g_reduction_um, 3)};
    if (!top) row.push_back(share);
    if (!top) {
      row.push_back(um(d.pv_um));
      // The limit in its unit: the column holds a backlash's µm beside a squareness's µm/m.
      row.push_back(check ? fmt::format("<span class=\"nw\">≤ {} {}</span> ",
                                        fixed(check->limit, 3), esc(unit_text(check->unit))) +
                                verdict_cell(check)
                          : "");
    }
    if (!top) row.push_back(check_text);
    diag.push_back(std::move(row));
  }
  if (diag.empty()) return "";
  std::vector<std::string> head{"rank by gain", top ? "error, and what to check" : "error",
                                "value"};
  if (top) head.push_back("G gain (share of G)");
  if (!top) {
    head.push_back("G gain (µm)");
    head.push_back("gain / G (%)");
    head.push_back("PV (µm)");
    head.push_back("limit");
  }
  if (!top) head.push_back("what to check");
  return table(head, diag, "num diag", top ? "rlrr" : "rlrrrrll");
}

// Under page one's list: how it is ordered, and for an error outside its limit whose correction
// alone would make G larger, which errors it partly offsets (those whose correction alone would
// also make G larger), so they are corrected together.
std::string fix_first_notes(const cal::circle::Result& r, const ::daq::Verdict& verdict,
                            std::size_t top) {
  std::string h =
      "<p class=\"note\">Errors outside their limit first, then by the gain in G (what "
      "correcting that error alone takes off G); every error under Details.</p>\n";
  for (std::size_t i : fix_first_order(r, verdict, top)) {
    const auto& d = r.diagnostics[i];
    if (std::round(d.g_reduction_um * 1e3) >= 0) continue;
    std::vector<std::string> others;
    for (const auto& o : r.diagnostics)
      if (o.key != d.key && std::round(o.g_reduction_um * 1e1) < 0) others.push_back(esc(o.name));
    h += fmt::format(
        "<p class=\"warning\">{} is outside its limit, but correcting it alone would make G "
        "{} µm larger: it partly offsets {}. Correct them together and measure again.</p>\n",
        esc(d.name), fixed(-d.g_reduction_um, 3),
        others.empty() ? std::string("other errors")
                       : fmt::format("{} (each would also make G larger if corrected alone)",
                                     fmt::join(others, ", ")));
  }
  return h;
}

// What the ranking means, and a warning when no term would gain anything (the first gain is not
// positive): the errors then cancel each other and none alone is worth correcting.
std::string gain_notes(const cal::circle::Result& r) {
  std::string h;
  if (!r.diagnostics.empty() && std::round(r.diagnostics.front().g_reduction_um * 1e3) <= 0)
    h += "<p class=\"warning\">No single error would make G smaller if corrected alone: the "
         "errors partly cancel each other (every G gain is zero or negative).</p>\n";
  return h;
}

Sections circle_section(const st::RunReader& store, const RunView& v, const Options& o,
                        Headline& headline) {
  const auto c = analyse_circle(store, v, o);
  const auto& r = c.result;
  const auto& st = cal::circle::info(cal::circle::circular_standard_from_key(c.analysis.standard));
  headline.standard = st.label;
  Sections out;
  std::string& h = out.answer;
  // Page one names the standard and the test in one line; its full title under Details.
  h = fmt::format(
      "<h3>Results: {0}</h3>\n<p class=\"standard\"><strong>{0}</strong>{1}: radius {2:g} mm, "
      "feed {3:g} mm/min, plane {4}, both directions.</p>\n",
      esc(st.label),
      st.identical.empty() ? std::string()
                           : fmt::format(" (the same values as {})", esc(st.identical.front())),
      c.program.radius_mm, c.program.feed_mm_per_min, esc(c.analysis.plane));
  const std::string evaluated = fmt::format(
      "<p class=\"standard\">Evaluated by <strong>{}</strong> ({}) from the stored bar "
      "readings.</p>\n",
      esc(st.label), esc(st.title));
  const auto doc = ::daq::circle_document(r, c.program, c.analysis);
  const auto verdict = ::daq::verdict_of(v.settings, doc);
  headline.verdict = ::daq::summary(verdict);
  std::vector<std::vector<std::string>> iso;
  for (const auto& x : ::daq::circle_rows(doc)) {  // as every output lists them
    const auto* check = ::daq::find_check(verdict, x.key);
    // What the symbol means under it: the table stands beside the polar plot, half the page
    // wide, where a column of its own was squeezed to a word a line.
    iso.push_back({esc(x.symbol) + "<br><span class=\"meaning\">" + esc(x.description) + "</span>",
                   um(x.value), limit_cell(check), check ? verdict_cell(check) : ""});
    const bool failing = check && !check->pass;
    if (x.key.starts_with("G") || failing)
      headline.values.push_back({x.symbol, x.value, unit_text(x.unit), failing});
  }
  // The set-up's centre and the informative values follow under Details (page one holds the
  // standard's values, what to fix first and the polar plot).
  std::vector<std::vector<std::string>> other{
      {"centre", fmt::format("{} / {}", um(r.iso.centre_u_um), um(r.iso.centre_v_um)),
       "least-squares centre relative to the pivot (set-up)"}};
  for (const auto& x : st.informative)
    other.push_back({esc(x.symbol), um(::daq::iso_value(r.iso, x.key)),
                     "<em>informative</em>: " + esc(x.meaning)});
  h += verdict_banner(verdict, tolerance_hint(v, doc));
  // Page one holds the verdict, the values, the polar plot and what to fix first: the values
  // beside the plot (one under the other pushed "what to fix first" onto page two). The plot's
  // text is drawn larger so that, shown at half the page's width, it still prints at 9 pt.
  auto polar = polar_of(c, "Polar plot, least-squares centre removed", 0, "");
  polar.centre_text = "G = " + um(r.iso.G_bi_um) + " µm";
  polar.text_scale = polar_beside_text_scale;
  h += "<div class=\"pair\"><div>" +
       table({"symbol and meaning", "value (µm)", "limit (µm)", "verdict"}, iso,
             "num results beside", "lrrl") +
       "</div>" + "<figure>" + svg(polar) + "</figure>" + "</div>\n";
  const auto first = diagnostics_table(r, verdict, 3);
  h += "<h4>What to fix first</h4>\n" +
       (first.empty() ? std::string("<p>No error would reduce G if corrected alone.</p>\n")
                      : first + fix_first_notes(r, verdict, 3));
  // The campaign summary's headline: the diagnostics of "what to fix first" in their own units,
  // every one outside its limit among them (the first four by gain once left one out).
  for (std::size_t i : fix_first_order(r, verdict, 4)) {
    const auto& x = r.diagnostics[i];
    const auto* check = ::daq::find_check(verdict, x.key);
    headline.values.push_back({x.name, x.value, unit_text(x.unit), check && !check->pass, true});
  }

  out.details_flow = true;
  std::string& d = out.details;
  d = "<h3>Details of the results</h3>\n" + evaluated +
      table({"symbol", "value (µm)", "meaning"}, other, "num results", "lrl") +
      "<h4>Diagnostics, ranked by what correcting each would gain</h4>\n" +
      diagnostics_table(r, verdict, 0) + gain_notes(r);
  for (const auto& n : st.not_evaluated)
    d += "<p class=\"note\">Not evaluated: " + esc(n) + "</p>\n";
  d += fmt::format(
      "<p class=\"note\">Each error is fitted to both traces together. <em>value</em> is the "
      "error in its own unit (a backlash in µm, a squareness in µm/m, a servo mismatch in ms). "
      "<em>G gain</em> is how much G = {:.3f} µm falls when that error alone is corrected (the "
      "least-squares circle refitted), and <em>gain / G</em> the same as a share of G; the gains "
      "do not add up, and a negative gain means the error partly cancels another (correcting it "
      "alone would make G worse). <em>PV</em> is the peak-to-valley, in µm, of the radial "
      "deviation that error alone causes on this circle. A limit applies to the magnitude of "
      "the value, in its unit.</p>\n",
      r.iso.G_bi_um);
  // The analysis's notes ("vibration: ...") as sentences, their subject capitalised; not the
  // uncalibrated bar's, which the Bar calibration section right under it says in full.
  for (const auto& n : r.notes) {
    if (n.starts_with("uncalibrated bar:")) continue;
    std::string note = n;
    if (!note.empty() && note[0] >= 'a' && note[0] <= 'z')
      note[0] = static_cast<char>(note[0] - 32);
    d += "<p class=\"note\">" + esc(note) + "</p>\n";
  }
  d += bar_calibration_section(c, v);
  d += fmt::format(
      "<h3>Measurement uncertainty</h3>\n<p>The error model leaves a residual of {:.3f} µm rms "
      "(noise and what the model does not describe). The transducer's own certificate and the "
      "calibrator's uncertainty are not recorded with the run, so an expanded uncertainty of G "
      "is not evaluated here.</p>\n",
      r.residual_rms_um);
  return out;
}

// --- other runs (e.g. imported dynamic captures)
// --------------------------------------------------

// A stored quantity as a plot reads it, its name and unit ("displacement (m)"), not its
// storage key ("displacement_m", which the plots of these runs printed).
std::string quantity_label(Q q) {
  switch (q) {
    case Q::displacement_m:
      return "displacement (m)";
    case Q::length_m:
      return "length (m)";
    case Q::machine_position_m:
      return "machine position (m)";
    case Q::angle_rad:
      return "angle (rad)";
    case Q::dew_point_degc:
      return "dew point (°C)";
    default:
      return std::string(cal::drivers::to_string(q));
  }
}

// The unit a plot of a stored quantity reads best in, from the span of its values: a length in
// mm, or in µm when it moves less than a millimetre (an indicator's few µm printed in m read
// "×10⁻³" at the axis); an angle in µrad below a hundredth of a radian, else in degrees. The
// name keeps the quantity's ("length (µm)"); other quantities as stored.
struct PlotUnit {
  std::string label;
  double factor = 1.0;  // stored SI value -> plotted value
};
PlotUnit plot_unit(Q q, std::span<const double> values_si) {
  double lo = INFINITY, hi = -INFINITY;
  for (const double x : values_si) lo = std::min(lo, x), hi = std::max(hi, x);
  const double span = hi >= lo ? hi - lo : 0.0;
  const auto name = [&](std::string_view unit) {
    auto l = quantity_label(q);
    return l.substr(0, l.rfind(" (")) + " (" + std::string(unit) + ")";
  };
  switch (q) {
    case Q::displacement_m:
    case Q::machine_position_m:
      return {name("mm"), 1e3};
    case Q::length_m:
      return span < 1e-3 ? PlotUnit{name("µm"), 1e6} : PlotUnit{name("mm"), 1e3};
    case Q::angle_rad:
      return span < 1e-2 ? PlotUnit{name("µrad"), 1e6}
                         : PlotUnit{name("°"), 180.0 / std::numbers::pi};
    default:
      return {quantity_label(q), 1.0};
  }
}

std::string generic_section(const st::RunReader& store, const RunView& v, const Options& o) {
  // Streamed: every series is thinned to about 4000 points for its plot (every step-th
  // reading, the step from the series' count), so the memory does not grow with the run.
  const auto series = store.series(v.run.id);
  std::int64_t t0 = 0, count = 0;
  for (std::size_t i = 0; i < series.size(); ++i) {
    t0 = i == 0 ? series[i].first_ns : std::min(t0, series[i].first_ns);
    count += series[i].count;
  }
  struct Thinned {
    Series s;             // labelled by the instrument ("ids3010 SIM-IDS-0001, channel 2")
    std::string title;    // by its role ("laser"), the quantity and the channel follow
    std::string channel;  // ", channel 2" (after the quantity in the title)
    std::size_t step = 1, seen = 0;
  };
  std::map<std::tuple<int, int, int>, Thinned> by;
  std::vector<std::uint8_t> plotted;
  std::uint64_t to_read = 0, read = 0;
  for (const auto& x : series) {
    const auto q = static_cast<Q>(x.quantity);
    if (q == Q::air_temperature_degc || q == Q::air_pressure_pa || q == Q::air_humidity_pct ||
        q == Q::material_temperature_degc || q == Q::refractive_index)
      continue;
    to_read += static_cast<std::uint64_t>(x.count);
    auto& t = by[{x.quantity, x.device, x.channel}];
    t.step = std::max<std::size_t>(1, static_cast<std::size_t>(x.count) / 4000);
    t.channel = x.channel > 0 ? fmt::format(", channel {}", x.channel) : "";
    // The legend names the instrument (its driver and serial), as the environment plots do; it
    // read "laser displacement (mm)", the title again.
    t.title = instrument_name(v, x.device);
    t.s.label = legend_label(v, x.device, x.channel, "");
    if (std::find(plotted.begin(), plotted.end(), x.quantity) == plotted.end())
      plotted.push_back(x.quantity);
  }
  if (!plotted.empty()) {
    auto stream = store.stream_readings(v.run.id, plotted);
    std::vector<st::RawReading> batch;
    while (stream.next(batch)) {
      for (const auto& r : batch) {
        auto& t = by[{r.quantity, r.device, r.channel}];
        if (t.seen++ % t.step != 0) continue;
        t.s.t_s.push_back(static_cast<double>(r.time_ns - t0) * 1e-9);
        t.s.value.push_back(r.value);
      }
      read += batch.size();
      if (o.reading_progress) o.reading_progress(read, to_read);
    }
  }
  // The heading, its count and the first plot kept on one page: a heading and a line at the foot
  // of a page with their plot on the next read as an empty section (the angular report's page 1).
  std::string h = fmt::format(
      "<div class=\"keep-with-next\"><h3>Readings</h3>\n<p>{} readings stored.</p>\n", count);
  // One time unit for every plot of the readings (they share the run's time).
  TimeSpan span;
  for (const auto& [key, t] : by) span.add(t.s);
  const auto time = span.unit();
  std::size_t i = 0;
  for (auto& [key, t] : by) {
    const auto unit = plot_unit(static_cast<Q>(std::get<0>(key)), t.s.value);
    for (auto& x : t.s.value) x *= unit.factor;
    t.title += " " + unit.label + t.channel;
    // Lower than a result's plot (the raw readings support it): at 300 pt each of an angular
    // run's three (the displacement and each beam) took most of a page, its pages 65 % full.
    h += figure(svg(XyChart{.title = t.title,
                            .x_label = time_label(time),
                            .y_label = unit.label,
                            .lines = lines_of({t.s}, time, i++, 4000),
                            .height_pt = 220}),
                t.title + " over the run.");
    if (i == 1) h += "</div>\n";  // after the first plot
  }
  if (i == 0) h += "</div>\n";  // no plot
  return h;
}

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
                        signed_text(res.slope_um_per_m, 3), um(res.intercept_um)});
  }
  return out;
}

// --- ISO 230-1: straightness, angular (pitch, yaw) and roll runs ------------------------------

// A profile's values, their limits and verdicts: the table on page one.
std::string profile_values_table(const std::vector<::daq::ResultRow>& rows,
                                 const ::daq::Verdict& verdict) {
  std::vector<std::vector<std::string>> cells;
  for (const auto& r : rows) {
    const auto* c = ::daq::find_check(verdict, r.key);
    const std::string value = r.key == "slope_um_per_m" ? signed_text(r.value, 3) : um(r.value);
    cells.push_back({esc(r.symbol), value + " " + esc(unit_text(r.unit)), esc(r.description),
                     c ? limit_cell(c) + " " + esc(unit_text(c->unit)) : limit_cell(c),
                     verdict_cell(c)});
  }
  return table({"symbol", "value", "meaning", "limit", "verdict"}, cells, "num results profile",
               "lrlrl");
}

// The means at each target (and each direction's), with the reference lines of a straightness.
std::string profile_plot(const json& doc, std::string_view unit) {
  std::vector<double> x, mean, up, down;
  for (const auto& t : doc.value("targets", json::array())) {
    x.push_back(t.value("position_mm", 0.0));
    mean.push_back(t.value("mean", 0.0));
    if (t["mean_up"].is_number()) up.push_back(t["mean_up"].get<double>());
    if (t["mean_down"].is_number()) down.push_back(t["mean_down"].get<double>());
  }
  const bool straight = doc.value("kind", "") == "straightness";
  const std::string quantity = straight ? "straightness deviation" : "angular deviation";
  XyChart chart{.title = fmt::format("{} {} along the axis", straight ? "Straightness" : "Angular",
                                     ctx(doc, "component")),
                .x_label = "target position (mm)",
                .y_label = fmt::format("{} ({})", quantity, unit_text(unit)),
                .height_pt = 220,
                .zero_line = !straight};
  std::string caption;
  if (straight && x.size() >= 2) {
    chart.lines = reference_lines(Profile{.position_mm = x, .deviation_um = mean}, 0, "").lines;
    chart.lines.front().label = "mean of the stops";
    caption =
        "The mean at each target with the reference lines of ISO 230-1: least squares (its "
        "straightness is the result), end point, and the minimum zone's two parallel lines "
        "(dashed) enclosing every mean.";
  } else {
    chart.lines.push_back(
        {.x = x, .y = mean, .label = "mean of the stops", .colour = black, .markers = true});
    caption = "The mean at each target; the angular deviation is their range.";
  }
  // Each direction's means where the run went both ways (a difference is reversal).
  if (up.size() == x.size() && down.size() == x.size() && !x.empty()) {
    chart.lines.push_back({.x = x, .y = up, .label = "mean ↑", .colour = blue, .width = 0.8});
    chart.lines.push_back(
        {.x = x, .y = down, .label = "mean ↓", .colour = vermilion, .width = 0.8, .dashed = true});
  }
  return figure(svg(chart), caption);
}

// Per target: the mean, each direction's, the spread and the stops.
std::string profile_targets_table(const json& doc, std::string_view unit) {
  const auto cell = [](const json& t, const char* key) {
    return t.contains(key) && t[key].is_number()
               ? signed_text(t[key].get<double>(), 3)
               : std::string("<span class=\"unstated\">&ndash;</span>");
  };
  std::vector<std::vector<std::string>> rows;
  for (const auto& t : doc.value("targets", json::array()))
    rows.push_back({fmt::format("{:.3f}", t.value("position_mm", 0.0)), cell(t, "mean"),
                    cell(t, "mean_up"), cell(t, "mean_down"), um(t.value("spread", 0.0)),
                    std::to_string(t.value("count", 0))});
  const std::string u = unit_text(unit);
  return "<h4>Per target</h4>\n" +
         table({"target (mm)", fmt::format("mean ({})", u), fmt::format("mean ↑ ({})", u),
                fmt::format("mean ↓ ({})", u), fmt::format("spread ({})", u), "stops"},
               rows, "num");
}

Sections profile_section(const st::RunReader& store, const RunView& v, const Options& o,
                         Headline& headline) {
  // The stored result (what daq show prints), else the same evaluation of the stored stops.
  const auto stored = ::daq::current_result(v.results, "caldaq.profile.v1");
  const json doc =
      stored ? cal::daq::parse_stored_json(stored->json) : ::daq::stored_profile(store, v.run);
  const std::string unit = ctx(doc, "unit");
  const auto rows = ::daq::profile_rows(doc);
  const auto verdict = ::daq::verdict_of(v.settings, doc);
  const bool straight = ctx(doc, "kind") == "straightness";
  headline.standard = "ISO 230-1";
  headline.verdict = ::daq::summary(verdict);
  for (const auto& r : rows) {
    const auto* c = ::daq::find_check(verdict, r.key);
    headline.values.push_back(
        {r.symbol, r.value, unit_text(r.unit), c && !c->pass, r.key == "slope_um_per_m"});
  }
  if (!rows.empty())  // the straightness, or the angular deviation
    set_error(headline.error, ctx(doc, "component"), rows.front().value,
              unit_text(rows.front().unit), ::daq::find_check(verdict, rows.front().key));
  Sections out;
  out.answer = fmt::format(
      "<h3>Results: {} {}</h3>\n<p class=\"standard\">Evaluated by <strong>ISO 230-1:2012</strong> "
      "from the mean of the stops at each of {} targets{}.</p>\n",
      straight ? "straightness" : "angular deviation", esc(ctx(doc, "component")),
      doc.value("targets", json::array()).size(),
      stored ? "" : " (no result was stored with the run: evaluated from its stops now)");
  out.answer += verdict_banner(verdict, tolerance_hint(v, doc));
  out.answer += profile_values_table(rows, verdict);
  out.answer += profile_plot(doc, unit);
  // The details follow on page one (after a page break, page one of an angular run was 70 %
  // full and its per-target table alone on page two).
  out.details_flow = true;
  std::string& d = out.details;
  d = "<h3>Details of the results</h3>\n";
  if (straight) {
    std::vector<double> x, mean;
    for (const auto& t : doc.value("targets", json::array()))
      x.push_back(t.value("position_mm", 0.0)), mean.push_back(t.value("mean", 0.0));
    if (x.size() >= 2)
      d += "<h4>Reference lines (ISO 230-1)</h4>\n" +
           table({"reference line", "straightness (µm)", "slope (µm/m)", "intercept (µm)"},
                 reference_lines(Profile{.position_mm = x, .deviation_um = mean}, 0, "").rows,
                 "num", "lrrr");
  }
  d += profile_targets_table(doc, unit);
  d += generic_section(store, v, o);
  return out;
}

// --- five-axis ballbar: the rotary axes' location errors
// ------------------------------------------

// What a location error is, from its name (ISO 230-1's E_<direction>0<axis>): E_X0C and E_Y0C
// place the C axis's average line (µm), E_A0C and E_B0C tilt it about X and Y (µrad).
std::string location_meaning(std::string_view name, std::string_view unit) {
  if (name.size() != 5 || !name.starts_with("E_") || name[3] != '0') return {};
  const char d = name[2], axis = name[4];
  if (unit == "um") return fmt::format("position of the {} axis's line in {}", axis, d);
  const char about = d == 'A' ? 'X' : d == 'B' ? 'Y' : 'Z';
  return fmt::format("tilt of the {} axis's line about {}", axis, about);
}

// A test's angles as read: "0 to 330° by 30°" when evenly spaced, else each one.
std::string angles_text(const json& stops) {
  std::vector<double> a;
  for (const auto& s : stops) a.push_back(s.value("angle_deg", 0.0));
  if (a.empty()) return "none";
  const double step = a.size() > 1 ? a[1] - a[0] : 0.0;
  bool even = a.size() > 2;
  for (std::size_t k = 1; k < a.size(); ++k) even = even && std::abs(a[k] - a[k - 1] - step) < 1e-9;
  if (even)
    return fmt::format("{} … {}° by {}°", setting_text(a.front()), setting_text(a.back()),
                       setting_text(step));
  std::vector<std::string> each;
  for (double x : a) each.push_back(setting_text(x));
  return fmt::format("{}°", fmt::join(each, ", "));
}

// The part program's dialect, as recorded with the run; the simulated shop's control runs the
// program's points, not a text in a control's dialect, and says so.
std::string dialect_text(const RunView& v) {
  const auto d = ctx(v.settings, "dialect");
  if (!d.empty()) return esc(d);
  return v.settings.value("simulated", false)
             ? "<span class=\"unstated\">none: the simulated control ran the program's points "
               "(daq model ballbar5x-program writes them for a real control)</span>"
             : "<span class=\"unstated\">not recorded</span>";
}

// One test's bar deviation (the reading less the test's fitted bar offset) at each stop against
// the rotary angle, with what the fitted location errors alone give there (reading − residual).
std::string ballbar5x_plot(const json& axis, const json& test) {
  // A dot as large as the other plots' marks: PLplot's own point (plpoin) printed too small to see.
  Line measured{.label = "measured", .colour = blue, .width = 0.0, .markers = true, .marker = "●"};
  Line fitted{.label = "fitted", .colour = vermilion, .width = 1.0, .dashed = true};
  const double offset = test.value("offset_um", 0.0);
  for (const auto& s : test.value("stops", json::array())) {
    const double angle = s.value("angle_deg", 0.0), reading = s.value("reading_um", 0.0);
    measured.x.push_back(angle), measured.y.push_back(reading - offset);
    fitted.x.push_back(angle), fitted.y.push_back(reading - s.value("residual_um", 0.0) - offset);
  }
  const std::string letter = ctx(axis, "axis");
  // Half the page wide: the title names the quantities (axis labels at this size were clipped
  // and left a third of the figure empty), its text drawn larger to print at 9 pt.
  return figure(
      svg(XyChart{.title = fmt::format("{}: bar deviation (µm) against {} (deg)", ctx(test, "test"),
                                       letter),
                  .x_label = "",
                  .y_label = "",
                  .lines = {fitted, measured},
                  .width_pt = 300,
                  .height_pt = 180,
                  .zero_line = true,
                  .legend = false,
                  .min_y_span = 1.0,
                  .text_scale = 1.65}),
      fmt::format("{}: the bar's deviation against the {} angle.", ctx(test, "test"), letter));
}

Sections ballbar5x_section(const st::RunReader& store, const RunView& v, const Options& o,
                           Headline& headline) {
  const auto stored = ::daq::current_result(v.results, "caldaq.ballbar5x.v1");
  if (!stored)
    throw cal::InputError(fmt::format(
        "run {} has no stored five-axis ballbar result (it ended {} before its tests were "
        "read)",
        v.run.id, st::to_string(v.run.status)));
  const json doc = cal::daq::parse_stored_json(stored->json);
  // The axes in the order they were tested (the run's axis, "CA"), not the document's (by letter).
  json axes = doc.value("axes", json::array());
  if (axes.is_array())
    std::stable_sort(axes.begin(), axes.end(), [&](const json& a, const json& b) {
      return v.run.axis.find(ctx(a, "axis")) < v.run.axis.find(ctx(b, "axis"));
    });
  const auto verdict = ::daq::verdict_of(v.settings, doc);
  headline.standard = "five-axis ballbar";
  headline.verdict = ::daq::summary(verdict);
  bool corrected = false;  // a control holding location errors: each value's `left` differs
  std::size_t tests = 0, stops = 0;
  for (const auto& a : axes) {
    const json loc = a.value("location", json::object());  // named: items() of a temporary dangles
    for (const auto& l : loc) corrected = corrected || l.value("control", 0.0) != 0.0;
    for (const auto& t : a.value("tests", json::array()))
      ++tests, stops += t.value("stops", json::array()).size();
  }
  Sections out;
  std::string& h = out.answer;
  h = fmt::format(
      "<h3>Results: location errors of the rotary axes</h3>\n<p class=\"standard\">Each axis's "
      "four location errors (ISO 230-1: the position and tilt of its average line) fitted by "
      "least squares to the bar's mean reading at {} stops of {} tests, one bar offset per test; "
      "the kinematic tests of ISO 10791-6's kind, as the literature does them (docs/kinematics.md, "
      "&ldquo;The ballbar on a rotary axis&rdquo;): caldaq does not claim ISO 10791-6's own test "
      "definitions, which are not public.</p>\n",
      stops, tests);
  h += verdict_banner(verdict, tolerance_hint(v, doc));
  // The values: every axis's four, as daq show prints them (result_rows.hpp), with u (k = 1).
  std::vector<std::vector<std::string>> rows;
  for (const auto& a : axes) {
    const json loc = a.value("location", json::object());
    for (const auto& n : a.value("names", json::array())) {
      const std::string name = n.is_string() ? n.get<std::string>() : std::string();
      if (!loc.contains(name)) continue;
      const json& l = loc[name];
      const std::string unit = ctx(l, "unit");
      const auto* c = ::daq::find_check(verdict, name);
      std::vector<std::string> row{esc(name), signed_text(l.value("value", 0.0), 3),
                                   fixed(l.value("uncertainty", 0.0), 3), esc(unit_text(unit)),
                                   esc(location_meaning(name, unit))};
      if (corrected)
        row.push_back(signed_text(l.value("control", 0.0), 3)),
            row.push_back(signed_text(l.value("left", 0.0), 3));
      row.push_back(limit_cell(c));
      row.push_back(verdict_cell(c));
      rows.push_back(std::move(row));
      headline.values.push_back(
          {name, l.value("value", 0.0), unit_text(unit), c && !c->pass, true});
    }
  }
  std::vector<std::string> head{"error", "value", "u (k = 1)", "unit", "what it is"};
  if (corrected) head.push_back("in the control"), head.push_back("left");
  head.push_back("limit"), head.push_back("verdict");
  h += table(head, rows, "num results location", corrected ? "lrrllrrrl" : "lrrllrl");
  h += fmt::format(
      "<p class=\"note\">u: the standard uncertainty (k = 1) of each value from the fit's "
      "residuals.{} Corrected in the control by <code>daq model kinematics</code>: LinuxCNC's "
      "trunnion pins hold the positions only, a SINUMERIK CYCLE800 record all four "
      "(docs/five-axis-walkthrough.md).</p>\n",
      corrected ? " The control already held location errors (<em>in the control</em>): "
                  "<em>left</em> is the fitted less the control's own, what its correction left."
                : "");
  // The tests run: what the bar was set up as, and its deviation at each stop.
  std::vector<std::vector<std::string>> trows;
  for (const auto& a : axes)
    for (const auto& t : a.value("tests", json::array())) {
      std::vector<std::string> ball;
      for (const auto& x : t.value("ball_mm", json::array()))
        ball.push_back(esc(setting_text(x)));  // as given: "150", not "150.000"
      trows.push_back({esc(ctx(t, "test")), esc(ctx(a, "axis")), esc(ctx(t, "setup")),
                       fmt::format("({})", fmt::join(ball, ", ")),
                       esc(setting_text(t.value("length_mm", json(0.0)))),
                       esc(angles_text(t.value("stops", json::array()))),
                       std::to_string(t.value("stops", json::array()).size()),
                       signed_text(t.value("offset_um", 0.0), 3) + " ± " +
                           fixed(t.value("offset_u_um", 0.0), 3)});
    }
  h += "<h4>The tests</h4>\n" +
       table({"test", "axis", "set-up", "table ball (mm)", "bar (mm)", "angles read", "stops",
              "bar offset (µm)"},
             trows, "num tests", "llllrlrr") +
       "<p class=\"note\">Set-up: the bar's direction relative to the axis (radial, tangential, "
       "axial); the table ball in machine coordinates at the axis's zero. Program dialect: " +
       dialect_text(v) + ".</p>\n";
  h += "<div class=\"multiples\">\n";
  for (const auto& a : axes)
    for (const auto& t : a.value("tests", json::array())) h += ballbar5x_plot(a, t);
  h += "</div>\n<p class=\"note\">Bar deviation: the bar's reading less the test's fitted bar "
       "offset; dots the mean of each stop's samples, the dashed line what the fitted location "
       "errors alone give (the difference is the residual).</p>\n";
  // Details: each axis's fit and each stop.
  std::string& d = out.details;
  d = "<h3>Details of the results</h3>\n";
  std::vector<std::vector<std::string>> fits;
  for (const auto& a : axes)
    fits.push_back({esc(ctx(a, "axis")), std::to_string(a.value("tests", json::array()).size()),
                    fixed(a.value("rms_um", 0.0), 3), fixed(a.value("sigma_um", 0.0), 3),
                    std::to_string(a.value("dof", 0))});
  d += "<h4>The fit of each axis</h4>\n" +
       table({"axis", "tests", "residual RMS (µm)", "σ (µm)", "degrees of freedom"}, fits, "num",
             "lrrrr");
  for (const auto& a : axes)
    for (const auto& t : a.value("tests", json::array())) {
      std::vector<std::vector<std::string>> srows;
      const double offset = t.value("offset_um", 0.0);
      for (const auto& s : t.value("stops", json::array()))
        srows.push_back({setting_text(s.value("angle_deg", json(0.0))),
                         signed_text(s.value("reading_um", 0.0), 3),
                         signed_text(s.value("reading_um", 0.0) - offset, 3),
                         fixed(s.value("spread_um", 0.0), 3), std::to_string(s.value("samples", 0)),
                         signed_text(s.value("residual_um", 0.0), 3)});
      d += fmt::format("<h4>Test {} ({} axis, {})</h4>\n", esc(ctx(t, "test")), esc(ctx(a, "axis")),
                       esc(ctx(t, "setup"))) +
           table({"angle (deg)", "reading (µm)", "deviation (µm)", "spread (µm)", "samples",
                  "residual (µm)"},
                 srows, "num");
    }
  // How the stops were read: the program's timing, and on the simulated shop its machine.
  const json timing = v.settings.value("timing", json::object());
  std::vector<std::vector<std::string>> prog;
  const auto setting = [&](const char* label, const json& j, const char* key, const char* unit) {
    // (an empty one left out: "Bar zeros injected µm" said a unit of nothing)
    if (j.is_object() && j.contains(key) && !setting_text(j[key]).empty())
      prog.push_back({label, esc(setting_text(j[key])) + (*unit ? " " + std::string(unit) : "")});
  };
  setting("Dwell at each angle", timing, "dwell_s", "s");
  if (timing.is_object() && timing.contains("settle_s") && timing["settle_s"].is_number())
    prog.push_back(
        {"Each stop averaged", fmt::format("from {} s after its start to {} s before its end",
                                           setting_text(timing["settle_s"]),
                                           setting_text(0.5 * timing["settle_s"].get<double>()))});
  setting("Rotary axis's rate between stops", timing, "rate_deg_per_s", "deg/s");
  setting("Bar's sample rate", timing, "sample_rate_hz", "Hz");
  setting("Feed-in", timing, "feed_in_mm", "mm");
  prog.push_back({"Program dialect", dialect_text(v)});
  setting("Control's kinematics", v.settings, "control_model", "");
  setting("LinuxCNC pins applied", v.settings, "hal", "");
  setting("SINUMERIK record applied", v.settings, "swivel", "");
  if (v.settings.value("simulated", false)) {
    setting("Simulated machine (truth)", v.settings, "truth_model", "");
    setting("Bar noise per sample", v.settings, "noise_um", "µm");
    setting("Bar zeros injected", v.settings, "offsets_um", "µm");
    setting("Noise seed", v.settings, "seed", "");
  }
  std::erase_if(prog, [](const auto& r) { return r[1].empty() || r[1] == "\"\""; });
  d += "<h4>The program and how its stops were read</h4>\n" + table({"", ""}, prog, "kv");
  d += generic_section(store, v, o);
  return out;
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
td { overflow-wrap: break-word; } .path { overflow-wrap: anywhere; }
.nw { white-space: nowrap; }
.verdict { padding: .4rem .6rem; border-radius: 3px; margin: .6rem 0; }
.verdict.pass { background: #e3f4ea; border: 1px solid #2e8b57; }
.verdict.fail { background: #fde8e4; border: 1px solid #c0392b; }
.verdict.none { background: #f3f3f3; border: 1px solid #999; }
span.pass { color: #1e7b45; font-weight: bold; } span.fail { color: #b8271b; font-weight: bold; }
.unstated { color: #888; font-style: italic; } .changed { color: #a04000; font-weight: bold; }
table.grid td:first-child { font-weight: normal; }
.multiples { display: grid; grid-template-columns: 1fr 1fr; gap: .5rem 1rem; }
.multiples figure { margin: .3rem 0; }
table.kv td:first-child { color: #555; }
table.kv thead { display: none; }
table.results td:first-child { font-weight: bold; }
figure { margin: 1rem 0; page-break-inside: avoid; break-inside: avoid; }
svg.plot { width: 100%; height: auto; max-width: 60rem; display: block; }
figcaption { font-size: .9rem; color: #444; }
.warning { color: #a40; } .note { color: #444; font-size: .9rem; }
.simulated { background: #fff3cd; border: 1px solid #e0b000; padding: .5rem; }
footer { margin-top: 2rem; font-size: .8rem; color: #666; border-top: 1px solid #ccc;
         break-before: avoid; page-break-before: avoid; }
h3, h4 { break-after: avoid; page-break-after: avoid; }
table { break-inside: auto; } tr { break-inside: avoid; }
table.summary { width: 100%; margin: .3rem 0 .6rem; }
table.summary th { width: 1%; white-space: nowrap; background: none; color: #555;
                   font-weight: normal; }
table.summary td { width: 49%; }
table.campaign { width: 100%; } table.campaign td:nth-child(7) { width: 100%; }
table.results td:first-child { white-space: nowrap; }
table.beside td:first-child { white-space: normal; } table.beside td.r, table.diag td.r { width: 1%; }
.meaning { font-weight: normal; color: #444; }
.verdict.suspect { background: #fff0d9; border: 1px solid #d68000; }
.approval { padding: .4rem .6rem; border-radius: 3px; margin: .6rem 0; }
.approval.issued { background: #e3f4ea; border: 2px solid #2e8b57; }
.approval.draft { background: #fde8e4; border: 2px dashed #c0392b; }
.verdict.suspect ul, ul.failing { margin: .2rem 0 .4rem; }
.verdict.fail + ul.failing { background: #fde8e4; margin-top: -.6rem; padding: .2rem 1.5rem;
  border: 1px solid #c0392b; border-top: none; }
svg.plot.polar { max-width: 30rem; margin: 0 auto; }
table.results, table.diag { width: 100%; }
.details { break-before: page; page-break-before: always; }
.details.flow { break-before: auto; page-break-before: auto; }
.pair.keep { break-inside: avoid; page-break-inside: avoid; }
.keep-with-next { break-inside: avoid; page-break-inside: avoid; }
.pair { display: grid; grid-template-columns: minmax(0, 1fr) minmax(0, 1fr); gap: 0 1rem;
        align-items: start; }
.pair figure { margin: .5rem 0; } .pair table { margin-top: .5rem; }
@media print { html { font-size: 10pt; }
  body { margin: 0; padding: 0; max-width: none; font-size: 10pt; line-height: 1.3; } h1 { font-size: 14pt; }
  th, td { padding: .08rem .4rem; } h3 { margin: .8rem 0 .3rem; } h4 { margin: .5rem 0 .3rem; }
  figure { margin: .3rem 0; } .verdict { margin: .3rem 0; } p { margin: .3rem 0; }
  h2 { page-break-before: always; } h2:first-of-type { page-break-before: auto; }
  svg.plot { max-width: 100%; margin: 0 auto; } svg.plot.polar { max-width: 72%; }
  .pair svg.plot.polar { max-width: 100%; } .overlay-polar svg.plot.polar { max-width: 50%; }
  h2.run { break-before: page; page-break-before: always; } }
.pair svg.plot.polar { max-width: 100%; }
)";

// The printed page: a running header (the report's title and who it is for) and "page n of
// m" in the page margins (CSS paged-media margin boxes, which Chromium prints). The texts are
// data (a machine or customer name) inside the <style> block: css_string escapes all but
// letters, digits and spaces, so none can end the string or the block.
// The footer's line ("Generated by ...") prints in the bottom margin of every page instead of
// after the last block: alone, it could spill onto a page of its own.
// A document holding a result not approved (issue 35, "Sign-off") is marked DRAFT — NOT APPROVED
// at the foot of every printed page; the box that says so on screen is left out of print, so
// the mark takes none of page one's room (the box pushed the main plot off a report's page one).
std::string print_css(std::string_view title, std::string_view who, std::string_view generated,
                      bool draft) {
  return fmt::format(
      "@page {{ size: A4; margin: 18mm 14mm 16mm 14mm;\n"
      "  @top-left {{ content: {}; font: 8pt \"DejaVu Sans\", sans-serif; color: #555; }}\n"
      "  @top-right {{ content: {}; font: 8pt \"DejaVu Sans\", sans-serif; color: #555; }}\n"
      "  @bottom-left {{ content: {}; font: 8pt \"DejaVu Sans\", sans-serif; color: #555; }}\n"
      "{}"
      "  @bottom-right {{ content: \"page \" counter(page) \" of \" counter(pages); "
      "font: 8pt \"DejaVu Sans\", sans-serif; color: #555; }} }}\n"
      "@media print {{ footer {{ display: none; }}{} }}\n",
      css_string(title), css_string(who), css_string(generated),
      draft ? "  @bottom-center { content: \"DRAFT \\2014  NOT APPROVED\"; "
              "font: bold 9pt \"DejaVu Sans\", sans-serif; color: #c0392b; }\n"
            : "",
      draft ? " .approval.draft { display: none; }" : "");
}

std::string page(std::string_view title, const std::string& body, const Options& o,
                 std::string_view who = "") {
  const auto now_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                          std::chrono::system_clock::now().time_since_epoch())
                          .count();
  const std::string generated = fmt::format("Generated by {} on {}", o.software, iso_time(now_ms));
  return fmt::format(
      "<!doctype html>\n<html lang=\"en\">\n<head>\n{}\n<meta charset=\"utf-8\">\n"
      "<title>{}</title>\n<style>{}{}</style>\n</head>\n<body>\n<h1>{}</h1>\n{}<footer>{}. "
      "Plots drawn with PLplot. Self-contained: no external resources.</footer>\n"
      "</body>\n</html>\n",
      csp_meta(), esc(title), css,
      print_css(title, who, generated,
                body.find("<div class=\"approval draft\">") != std::string::npos),
      esc(title), body, esc(generated));
}

// "Customer — machine" for the running header.
std::string who_of(const RunView& v) {
  const std::string customer = ctx(v.context.value("customer", json::object()), "name");
  return customer.empty() ? v.machine : customer + " — " + v.machine;
}

// Where the readings came from, stored with the run (provenance.hpp, run_origin): a simulated,
// replayed or imported run says so first, whatever its names; a run stored before origins were
// recorded says that too.
std::string origin_banner(const RunView& v) {
  const auto o = ::daq::run_origin(v.run, v.instruments, v.machine);
  std::string h;
  if (o.simulated)
    h += "<p class=\"simulated\"><strong>SIMULATED</strong>: this run was made on the simulated "
         "machine and instruments: the numbers show what the software measures, not a real "
         "machine.</p>\n";
  if (o.replayed)
    h += "<p class=\"simulated\"><strong>REPLAYED</strong>: these readings were pushed through "
         "the drivers again from a recorded capture, not measured now.</p>\n";
  if (o.imported)
    h += "<p class=\"simulated\"><strong>IMPORTED</strong> from another tool's file.</p>\n";
  return h;
}

// A report of several runs: which of them were not measured on real instruments, by origin
// ("SIMULATED: all 18 runs of this report ..."), for its page one, and the origins as the title's
// prefix ("SIMULATED, REPLAYED"): the names (a campaign, a machine) may say nothing of it.
struct Origins {
  std::string banner, label;
};
// Each run's origin label ("" for real instruments), in the report's order.
using RunLabels = std::vector<std::pair<std::int64_t, std::string>>;
std::string origin_label(const RunView& v) {
  return ::daq::run_origin(v.run, v.instruments, v.machine).label();
}
Origins origins_of(const RunLabels& runs) {
  // By each word of a label ("SIMULATED, REPLAYED" is both): a replay of a simulated run is
  // simulated like the run it replays, and replayed besides.
  // In the order the runs' labels name them ("SIMULATED, REPLAYED", as a run's title).
  std::vector<std::pair<std::string, std::vector<std::int64_t>>> by_origin;
  for (const auto& [id, label] : runs)
    for (std::size_t at = 0; at < label.size();) {
      const auto end = std::min(label.find(", ", at), label.size());
      const auto word = label.substr(at, end - at);
      auto it = std::find_if(by_origin.begin(), by_origin.end(),
                             [&](const auto& b) { return b.first == word; });
      if (it == by_origin.end()) it = by_origin.insert(by_origin.end(), {word, {}});
      it->second.push_back(id);
      at = end + 2;
    }
  Origins o;
  for (const auto& [origin, ids] : by_origin) {
    const std::string which =
        ids.size() == runs.size()
            ? (runs.size() == 1   ? std::string("the run of this report")
               : runs.size() == 2 ? std::string("both runs of this report")
                                  : fmt::format("all {} runs of this report", runs.size()))
            : fmt::format("run{} {} ({} of {})", ids.size() > 1 ? "s" : "", fmt::join(ids, ", "),
                          ids.size(), runs.size());
    const bool several = ids.size() > 1;
    const std::string what =
        origin == "SIMULATED"
            ? fmt::format(
                  "{} made on the simulated machine and instruments: the numbers show "
                  "what the software measures, not a real machine",
                  several ? "were" : "was")
        : origin == "REPLAYED"
            ? fmt::format(
                  "{} pushed through the drivers again from a recorded capture, not "
                  "measured now",
                  several ? "were" : "was")
        : origin == "IMPORTED"
            ? fmt::format("{} imported from another tool's file", several ? "were" : "was")
            : fmt::format(
                  "{} not measured on real instruments alone (each run's section says "
                  "which instruments were what)",
                  several ? "were" : "was");
    o.banner += fmt::format("<p class=\"simulated\"><strong>{}</strong>: {} {}.</p>\n", esc(origin),
                            which, what);
    o.label += (o.label.empty() ? "" : ", ") + origin;
  }
  return o;
}

std::string titled(const Origins& o, std::string title) {
  return o.label.empty() ? title : o.label + " — " + title;
}

// The as-left check of a compensation written before this run (compensation_check.hpp).
std::string compensation_check(const st::RunReader& store, const RunView& v) {
  if (v.run.kind != "linear" && v.run.kind != "straightness") return "";
  std::optional<::daq::LoopCheck> c;
  try {
    c = ::daq::check_run(store, v.run.id);
  } catch (const std::exception& e) {
    return "<p class=\"warning\">Compensation check: " + esc(e.what()) + "</p>\n";
  }
  if (!c) return "";
  const bool ok = c->verification.finding == cal::comptable::Finding::as_predicted;
  return fmt::format("<p class=\"verdict {}\"><strong>Compensation check</strong>: {}</p>\n",
                     ok ? "pass" : "fail", esc(::daq::loop_text(*c)));
}

// The schema of the result a run's report shows ("" for a kind without a stored result).
std::string_view result_schema(const RunView& v) {
  const auto& kind = v.run.kind;
  if (kind == "linear") return "caldaq.iso230-2.v1";
  if (kind == "circle") return "caldaq.circle.v2";
  if (kind == "rotary") return "caldaq.rotary.v1";
  if (kind == "ballbar5x") return "caldaq.ballbar5x.v1";
  if (::daq::is_profile_kind(kind)) return "caldaq.profile.v1";
  return "";
}

// Sign-off (issue 35; docs/reports.md): the report is an issued certificate only when the result
// it shows was approved (daq approve), naming the reviewer and when; otherwise a draft. The
// approval names an exact result: one re-analysed since is a new result, not approved.
std::string approval_banner(const RunView& v) {
  const auto schema = result_schema(v);
  std::optional<st::ResultRecord> shown;
  if (!schema.empty()) {
    shown = ::daq::current_result(v.results, schema);
  } else {
    for (const auto& r : v.results)
      if (r.current()) shown = r;
  }
  if (shown)
    for (const auto& a : v.approvals)
      if (a.result_id == shown->id)
        return fmt::format(
            "<div class=\"approval issued\"><strong>ISSUED CERTIFICATE</strong>: result {} "
            "approved by <span class=\"approver\">{}</span> on {}{}{}.</div>\n",
            shown->id, esc(a.approved_by), iso_time(a.approved_unix_ms),
            a.central_server.empty() ? "" : ", on the central server",
            a.result_fingerprint.empty()
                ? std::string()
                : fmt::format(" (result fingerprint {}, version {} of the run's stops)",
                              esc(a.result_fingerprint), a.run_version));
  // One line: page one keeps its room for the answer.
  return fmt::format(
      "<div class=\"approval draft\"><strong>DRAFT — NOT APPROVED</strong>: {} (daq approve "
      "{}).</div>\n",
      shown ? fmt::format("result {} has not been approved", shown->id)
            : std::string("no stored result to approve"),
      v.run.id);
}

// A run changed in more than one place (the central store keeps each version of its stops,
// docs/storage.md "Conflicts are versions"): which version this report shows, who sent it, and
// that its results are that version's (the store reads only those); nothing for one version.
std::string version_line(const st::RunReader& store, const RunView& v, int chosen) {
  const auto versions = store.versions(v.run.id);
  if (versions.size() < 2 && chosen == 0) return {};
  const auto shown = std::find_if(versions.begin(), versions.end(), [&](const st::RunVersion& x) {
    return chosen ? x.version == chosen : x.current;
  });
  if (shown == versions.end()) return {};
  const auto current = std::find_if(versions.begin(), versions.end(),
                                    [](const st::RunVersion& x) { return x.current; });
  const auto sender =
      shown->sent_by.empty() && shown->sent_from.empty()
          ? std::string("sent")
          : fmt::format("sent by {} from {}", esc(shown->sent_by), esc(shown->sent_from));
  return fmt::format(
      "<p class=\"warning\"><strong>Version {} of {} of the run's stops</strong>{}: {} on {}; the "
      "results below are those computed from these stops.{}</p>\n",
      shown->version, versions.size(), shown->current ? " (the current one)" : "", sender,
      iso_time(shown->sent_unix_ms),
      shown->current || current == versions.end()
          ? std::string()
          : fmt::format(" The current version is {} (daq report {} without --version).",
                        current->version, v.run.id));
}

// Page one is the answer: who, which machine and test, when; where the readings came from and
// how good they are; the verdict with the failing values, the main table and the main plot.
// Then the details, the conditions and traceability, and the settings as an appendix.
std::string run_body(const st::RunReader& store, const RunView& v, const Options& o, Headline& hl) {
  std::string h = approval_banner(v);
  h += origin_banner(v);
  h += version_line(store, v, o.version);
  h += summary_block(v, test_name(v, linear_standard_key(v, o)));
  if (v.run.status != st::RunStatus::complete)
    h += fmt::format(
        "<p class=\"warning\">This run is {}{}: the results cover only what was stored{}.</p>\n",
        st::to_string(v.run.status), v.run.note.empty() ? "" : " (" + esc(v.run.note) + ")",
        v.missed.empty() ? ""
                         : fmt::format("; {} planned stops were never captured (listed under "
                                       "Details)",
                                       v.missed.size()));
  h += quality_banner(store, v, true);
  h += traceability_warnings(v);
  h += compensation_check(store, v);
  // An aborted or interrupted run may hold too little to evaluate: the report still shows what
  // was stored, and says why there are no results.
  Sections results;
  try {
    if (v.run.kind == "linear" || v.run.kind == "rotary")
      results = linear_section(store, v, o, hl);
    else if (v.run.kind == "circle")
      results = circle_section(store, v, o, hl);
    else if (::daq::is_profile_kind(v.run.kind))
      results = profile_section(store, v, o, hl);
    else if (v.run.kind == "ballbar5x")
      results = ballbar5x_section(store, v, o, hl);
    else
      results.answer = generic_section(store, v, o);
  } catch (const cal::InputError& e) {
    results.answer = fmt::format(
        "<h3>Results</h3>\n<p class=\"warning\">The results cannot be evaluated: "
        "{}</p>\n",
        esc(e.what()));
  }
  h += results.answer;
  h += (results.details_flow ? "<div class=\"details flow\">\n" : "<div class=\"details\">\n") +
       results.details + quality_banner(store, v, false);
  if (!v.missed.empty()) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& m : v.missed)
      rows.push_back({std::to_string(m.run_number), m.direction == '+' ? "↑ up" : "↓ down",
                      std::to_string(m.target_index + 1), fmt::format("{:.3f}", m.nominal_mm)});
    h += "<h4>Missed stops (never captured)</h4>\n" +
         table({"run", "direction", "target", fmt::format("nominal ({})", axis_text(v).position)},
               rows, "num", "rlrr");
  }
  h += operator_actions_section(v);
  h += customer_section(v);
  h += conditions_section(v);
  h += instruments_section(v);
  if (!result_schema(v).empty()) h += provenance_section(v, result_schema(v));
  h += setup_section(v);
  h += environment_section(v.env);
  h += settings_appendix(v);
  return h + "</div>\n";
}

std::string date_of(const RunView& v) { return iso_time(v.run.started_unix_ms).substr(0, 10); }

// A comparison table's date cell (the run column names the run): the day, and its time when
// runs share a day. It may wrap between its parts, not inside one: "11-" over "28" read as no
// date (nothing unbroken either: "run 3 11-28 07:31" on one line printed the page shrunk).
std::string date_cell(const std::string& iso, bool with_time) {
  const auto part = [](std::string_view t) {
    return fmt::format("<span class=\"nw\">{}</span>", t);
  };
  return with_time ? part(iso.substr(5, 5)) + " " + part(iso.substr(11, 5))
                   : part(iso.substr(0, 5)) + "<wbr>" + part(iso.substr(5, 5));
}

}  // namespace

std::string run_report(const st::RunReader& store, std::int64_t run, const Options& o) {
  const auto v = load(store, run);
  Headline hl;
  return page(run_title(v, linear_standard_key(v, o)), run_body(store, v, o, hl), o, who_of(v));
}

// The campaign's ballbar tests side by side and the three-plane table (docs/circle.md, "The
// three-plane table"); empty when the campaign has no circle run with a result.
std::string volumetric_section(const st::RunReader& store, std::span<const std::int64_t> runs) {
  std::vector<std::int64_t> circles;
  for (const auto id : runs)
    if (const auto r = store.run(id);
        r && r->kind == "circle" && r->status == st::RunStatus::complete)
      circles.push_back(id);
  if (circles.empty()) return {};
  const auto tests = ::daq::ballbar_tests(store, circles);
  const auto v = ::daq::volumetric_table(tests);
  const auto opt = [](const std::optional<double>& x) {
    return x ? signed_text(*x, 3) : std::string("&ndash;");
  };
  std::vector<std::vector<std::string>> rows;
  for (const auto& t : tests)
    rows.push_back({fmt::format("<a href=\"#run-{}\">{}</a>", t.run, t.run), esc(t.plane_name),
                    fmt::format("{:g}", t.radius_mm), fmt::format("{:g}", t.feed_mm_per_min),
                    fmt::format("{:.0f}°", t.arc_deg), um(t.G_bi_um), opt(t.squareness_um_per_m),
                    opt(t.scale_mismatch_um_per_m), opt(t.servo_ms),
                    esc(::daq::summary(t.verdict))});
  std::string h =
      "<h2 id=\"three-planes\">Ballbar tests and the three-plane table</h2>\n" +
      table({"run", "plane", "R (mm)", "feed (mm/min)", "arc", "G(b) (µm)", "squareness (µm/m)",
             "scale mismatch (µm/m)", "servo mismatch (ms)", "verdict"},
            rows, "num", "rlrrrrrrrl") +
      "<p class=\"note\">Scale mismatch in the plane's order: XY X − Y, ZX Z − X, YZ Y − Z. "
      "Servo mismatch: the plane's second axis lags its first (positive); the ellipse it "
      "makes grows with the feed, a squareness's does not.</p>\n";
  std::vector<std::vector<std::string>> planes;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& pv = v.combined.planes[i];
    if (!pv) continue;
    std::string used;
    for (auto r : v.used[i].runs) used += (used.empty() ? "" : ", ") + std::to_string(r);
    // The runs by number, said so: a bare "2" under "runs" read as a count of two.
    used = (v.used[i].runs.size() == 1 ? "run " : "runs ") + used;
    const auto mp = cal::circle::model_plane(pv->plane);
    planes.push_back({i == 0   ? "XY"
                      : i == 1 ? "YZ"
                               : "ZX",
                      used, fmt::format("{:g}", v.used[i].feed_mm_per_min),
                      signed_text(pv->squareness_um_per_m, 3),
                      fmt::format("{} = {}", cal::kinematics::location_error_name(mp),
                                  signed_text(cal::circle::location_error_urad(*pv), 3)),
                      fmt::format("{} {}",
                                  i == 0   ? "X − Y"
                                  : i == 1 ? "Y − Z"
                                           : "Z − X",
                                  signed_text(pv->scale_mismatch_um_per_m, 3)),
                      opt(pv->mean_scale_um_per_m)});
  }
  h += "<h3>Three-plane table</h3>\n";
  if (!planes.empty())
    h += table({"plane", "averaged", "feed (mm/min)", "squareness α (µm/m)",
                "model location error (µrad)", "scale mismatch (µm/m)", "mean scale (µm/m)"},
               planes, "num", "llrrrrr");
  h += "<p>Each plane at its slowest feed (servo errors grow with the feed, geometric errors do "
       "not), its tests averaged. α is positive when the angle between the positive axes exceeds "
       "90°; the machine model's ISO 230-1 location errors are E_C0Y = +α<sub>XY</sub>, "
       "E_B0Z = −α<sub>ZX</sub>, E_A0Z = +α<sub>YZ</sub> (docs/kinematics.md). A circle "
       "measures squareness where it was run. The mean scale (s<sub>u</sub> + s<sub>v</sub>)/2 "
       "comes from a calibrated bar's radius error only.</p>\n";
  if (const auto& sc = v.combined.scale_um_per_m)
    h += fmt::format(
        "<p>Axis scales: X {}, Y {}, Z {} µm/m, <strong>{}</strong>{}.</p>\n",
        signed_text((*sc)[0], 3), signed_text((*sc)[1], 3), signed_text((*sc)[2], 3),
        v.combined.scale_absolute ? "absolute (calibrated bar)"
                                  : "relative: their mean is set to 0; the absolute scale is "
                                    "not evaluated without a calibrated bar",
        v.combined.scale_residual_um_per_m ? fmt::format(", least-squares residual {} µm/m",
                                                         um(*v.combined.scale_residual_um_per_m))
                                           : std::string());
  else
    h += "<p>Axis scales: not evaluated (they need the scale mismatches of two planes).</p>\n";
  if (v.combined.closure_um_per_m)
    h += fmt::format(
        "<p>Closure (X − Y) + (Y − Z) + (Z − X) = {} µm/m (0 for a consistent set: noise, "
        "drift between the tests and the local errors of each position move it).</p>\n",
        signed_text(*v.combined.closure_um_per_m, 3));
  for (const auto& n : v.notes) h += "<p class=\"note\">" + esc(n) + "</p>\n";
  return h;
}

namespace {

namespace kin = cal::kinematics;

// What a component is, in one word that fits a line of a half-page table beside its symbol,
// value, limit and verdict: "straightness", "angular", "roll", "positioning" (the symbol
// E_<error><moving axis> says in which direction and of which axis, docs/kinematics.md, and
// the note under the table reads it; "straightness in X" wrapped over two lines).
std::string error_words(std::string_view c) {
  const char error = c[2], axis = c[3];
  if (error == axis) return "positioning";
  if (error - 'A' == axis - 'X') return "roll";  // E_AX, E_BY, E_CZ
  if (error == 'A' || error == 'B' || error == 'C') return "angular";
  return "straightness";
}

struct ErrorRow {
  std::string name, words;  // "E_YX", "straightness in Y"
  std::int64_t run = 0;     // 0: not measured
  Headline::Error e;
  bool is_signed = false;  // a squareness has a direction
};

std::string error_rows_table(const std::vector<ErrorRow>& rows) {
  std::vector<std::vector<std::string>> cells;
  for (const auto& r : rows) {
    const std::string name = r.run ? fmt::format(
                                         "<span class=\"nw\"><a href=\"#run-{}\"><strong>{}"
                                         "</strong></a> {}</span>",
                                         r.run, esc(r.name), esc(r.words))
                                   : fmt::format("<span class=\"nw\"><strong>{}</strong> {}</span>",
                                                 esc(r.name), esc(r.words));
    if (!r.run) {
      cells.push_back({name, "<span class=\"unstated\">not measured</span>", "", ""});
      continue;
    }
    const auto& e = r.e;
    cells.push_back({name,
                     fmt::format("<span class=\"nw\">{} {}</span>",
                                 r.is_signed ? signed_text(e.value, 3) : um(e.value), esc(e.unit)),
                     e.limit ? "<span class=\"nw\">≤ " + fixed(*e.limit, 3) + "</span>"
                             : "<span class=\"unstated\">&ndash;</span>",
                     !e.limit ? "<span class=\"unstated\">&ndash;</span>"
                     : e.pass ? "<span class=\"pass\">pass</span>"
                              : "<span class=\"fail\">FAIL</span>"});
  }
  return table({"error", "value", "limit", "verdict"}, cells, "num errors", "lrrl");
}

// A volumetric campaign's answer on its page one: each of the 21 geometric errors of ISO
// 230-1 with its value in its own unit, its limit and verdict where the run's tolerances give
// one (the latest complete run of each component, as daq model build takes them), and the
// three squareness errors from the slopes of each plane's straightness pair against one square,
// computed as daq model build computes them. Empty for a campaign that measured no
// straightness, angular or roll run (a positioning test and a circle are reported as such).
std::string errors_section(const st::RunReader& store, std::span<const std::int64_t> runs,
                           const std::map<std::int64_t, Headline::Error>& measured) {
  std::map<std::string, std::int64_t> latest;  // component -> run
  bool volumetric = false;
  for (const auto& [id, e] : measured) {
    if (e.component.size() != 4) continue;
    const auto r = store.run(id);
    if (!r || r->status != st::RunStatus::complete) continue;
    volumetric = volumetric || ::daq::is_profile_kind(r->kind);
    auto& l = latest[e.component];
    l = std::max(l, id);
  }
  if (!volumetric) return {};
  std::vector<ErrorRow> rows;
  for (const auto c : kin::all_components()) {
    const std::string name(kin::to_string(c));
    ErrorRow row{.name = name, .words = error_words(name)};
    if (const auto it = latest.find(name); it != latest.end())
      row.run = it->second, row.e = measured.at(it->second);
    rows.push_back(std::move(row));
  }
  // Squareness: the model build's own computation on this campaign's runs (the Abbe terms of
  // the measured angles removed from each straightness before its slope is taken).
  std::string note;
  std::optional<cal::daq::model::BuildReport> built;
  try {
    const auto first = store.run(runs.front());
    const auto machine = first ? store.machine(first->machine_id) : std::nullopt;
    if (machine) {
      const auto stored = ::daq::stored_profiles(store, machine->name, runs);
      if (stored.topology)
        built = cal::daq::model::build(
            stored.profiles,
            {.machine = machine->name, .topology = *stored.topology, .allow_missing = true});
      else
        note =
            "the runs do not state the machine's chain ([machine] topology), so the "
            "squareness is not evaluated";
    }
  } catch (const cal::InputError& x) {
    note = fmt::format("the squareness is not evaluated: {}", x.what());
  }
  for (const auto p : {kin::Plane::xy, kin::Plane::xz, kin::Plane::yz}) {
    ErrorRow row{.name = std::string(kin::location_error_name(p)),
                 .words = fmt::format("squareness {}", kin::to_string(p)),
                 .is_signed = true};
    const auto& sq = built ? built->model.squareness[static_cast<std::size_t>(p)]
                           : cal::daq::model::SquarenessEntry{};
    if (built && sq.given) {
      const json src = json::parse(sq.source.json, nullptr, false);
      const json ids = src.is_object() ? src.value("run_ids", json::array()) : json::array();
      row.run = ids.empty() ? 0 : ids.back().get<std::int64_t>();
      row.e = {
          .component = row.name, .unit = "µrad", .value = built->model.machine.squareness.of(p)};
      // A limit on the squareness is a circular test's ([tolerances.PLANE.diagnostics]
      // squareness, on |α| in µm/m, and |α| = |location error|): a circle of the plane in
      // the campaign carries it.
      for (const auto id : runs)
        if (const auto r = store.run(id); r && r->kind == "circle") {
          try {
            if (kin::plane_from_string(r->axis) != p) continue;
          } catch (const cal::InputError&) {
            continue;
          }
          const json s = cal::daq::parse_stored_json(r->settings_json);
          const json t =
              s.is_object() ? s.value("context", json::object()).value("tolerances", json::object())
                            : json::object();
          const json d = t.is_object() ? t.value("diagnostics", json::object()) : json::object();
          if (d.is_object() && d.contains("squareness") && d["squareness"].is_number()) {
            row.e.limit = d["squareness"].get<double>();
            row.e.pass = std::abs(std::round(row.e.value * 1000) / 1000) <= *row.e.limit;
          }
        }
    }
    rows.push_back(std::move(row));
  }
  std::size_t done = 0;
  for (const auto& r : rows) done += r.run ? 1 : 0;
  const auto half = rows.begin() + 12;  // X and Y beside Z and the squareness
  std::string h = fmt::format(
      "<h3 id=\"errors\">The 21 geometric errors (ISO 230-1): {} of 21 measured</h3>\n", done);
  h += "<div class=\"pair\"><div>" + error_rows_table({rows.begin(), half}) + "</div><div>" +
       error_rows_table({half, rows.end()}) + "</div></div>\n";
  h += "<p class=\"note\">E_YX reads: the error in Y (X, Y, Z a straightness or, along the "
       "axis itself, the positioning; A, B, C an angle about X, Y, Z, about the axis itself its "
       "roll) of the motion of X. "
       "Positioning: E, the bidirectional systematic positional deviation "
       "(ISO 230-2); straightness: about the least-squares line; angular and roll: the range "
       "of the means; squareness: the location error from the slopes of the plane's two "
       "straightness runs against one square, as <code>daq model build</code> takes it (1 µrad "
       "= 1 µm/m). Limits: <code>E_um</code>, <code>straightness_um</code>, "
       "<code>angular_urad</code> under <code>[tolerances.AXIS]</code>; a squareness's is "
       "<code>squareness</code> under <code>[tolerances.PLANE.diagnostics]</code>, stored with "
       "a circular test of the plane. Each error's run links to its section.</p>\n";
  if (!note.empty()) h += "<p class=\"warning\">" + esc(note) + ".</p>\n";
  return h;
}

// A value's name in a table cell that only breaks before its parenthesis ("Cyclic error X" /
// "(40.01 mm period)"), the rest kept whole.
std::string breakable_name(std::string_view name) {
  const auto paren = name.find(" (");
  if (paren == std::string_view::npos) return esc(name);
  return esc(name.substr(0, paren)) + "</span> <span class=\"nw\">" + esc(name.substr(paren + 1));
}
}  // namespace

std::string campaign_report(const st::RunReader& store, std::span<const std::int64_t> runs,
                            std::string_view title, const Options& o) {
  if (runs.empty()) throw cal::InputError("campaign report: no runs to report");
  std::vector<std::vector<std::string>> summary;
  std::string sections, who;
  // The runs not measured on real instruments: page one says so whatever the campaign and the
  // machine are named (it relied on the names).
  RunLabels labels;
  std::map<std::int64_t, Headline::Error> errors;  // run -> the ISO 230-1 error it measured
  std::vector<RunView> views;                      // for page one's traceability gaps
  views.reserve(runs.size());                      // `v` below stays valid
  for (const auto id : runs) {
    const auto& v = views.emplace_back(load(store, id));
    labels.emplace_back(id, origin_label(v));
    Headline hl;
    const auto body = run_body(store, v, o, hl);
    if (!hl.error.component.empty()) errors[id] = hl.error;
    // Each value kept whole on its line with its name ("E 8.576 µm", "Backlash X +4.084 µm"),
    // but a long name may break before its parenthesis: whole, "Cyclic error X (40.01 mm
    // period) +0.997 µm" pushed the table past the page's margin. Up to eight, never leaving
    // out a value outside its limit.
    std::string numbers;
    std::size_t shown = 0;
    for (const auto& x : hl.values)
      if (x.failing || shown < 8) {
        ++shown;
        numbers +=
            fmt::format("<span class=\"nw\">{} {} {}{}</span>; ", breakable_name(x.symbol),
                        x.is_signed || x.unit != "µm" ? signed_text(x.value, 3) : um(x.value),
                        esc(x.unit), x.failing ? " <span class=\"fail\">FAIL</span>" : "");
      }
    const std::string verdict = hl.verdict == "PASS"   ? "<span class=\"pass\">PASS</span>"
                                : hl.verdict == "FAIL" ? "<span class=\"fail\">FAIL</span>"
                                : hl.verdict.empty()
                                    ? "<span class=\"unstated\">&ndash;</span>"
                                    : "<span class=\"unstated\">no tolerance</span>";
    summary.push_back({fmt::format("<a href=\"#run-{}\">{}</a>", id, id),
                       "<span class=\"nw\">" + date_of(v) + "</span>", esc(v.run.kind),
                       esc(v.run.axis), std::string(st::to_string(v.run.status)), esc(hl.standard),
                       numbers, verdict});
    sections +=
        fmt::format("<h2 class=\"run\" id=\"run-{}\">{}</h2>\n{}", id, esc(run_title(v)), body);
    if (who.empty()) who = who_of(v);
  }
  const auto origins = origins_of(labels);
  std::vector<const RunView*> each;
  for (const auto& v : views) each.push_back(&v);
  const std::string body =
      origins.banner + traceability_warnings(each) + errors_section(store, runs, errors) +
      fmt::format("<p>{} runs.</p>\n", runs.size()) +
      table({"run", "date", "test", "axis", "status", "standard", "results", "verdict"}, summary,
            "campaign", "r") +
      volumetric_section(store, runs) + sections;
  // The origin leads the title, so it is on every printed page's running header too.
  return page(titled(origins, std::string(title)), body, o, who);
}

namespace {
// A comparison with more values than fit across the page (a circle's G values and a dozen
// diagnostics: printed, Chromium shrank the whole page to about 5 pt to fit the table) lists the
// values down the page, one column per run.
constexpr std::size_t max_run_columns = 11;

// The positioning values a specification limits (ISO 230-2's bidirectional ones, VDI/DGQ 3441's):
// the tables of several runs side by side keep to them, the unidirectional ones are in each
// run's own report (all twelve would not fit a printed page).
bool is_specified_value(std::string_view key) {
  static constexpr std::string_view keys[] = {"E_bi",   "R_bi", "A_bi", "M",      "B",
                                              "B_mean", "P",    "Pa",   "Ps_max", "U_max"};
  return std::find(std::begin(keys), std::end(keys), key) != std::end(keys);
}

// A comparison's verdict in words, for page one (it was said only by the table's ✓ and ✗): the
// newest run's verdict, then each failing run (newest first) with its failing values and their
// limits, what to check beside the newest run's diagnostics. `verdicts` in the order of `views`
// (by date); `newest_doc`: the newest run's result (with no limit: which would judge them,
// where).
std::string comparison_verdict(const std::vector<RunView>& views,
                               const std::vector<::daq::Verdict>& verdicts, const json& newest_doc,
                               bool same_day) {
  constexpr std::size_t max_listed = 4;  // earlier failing runs named; the rest counted
  const auto when = [&](const RunView& v) {
    return fmt::format("run {} ({})", v.run.id,
                       same_day ? iso_time(v.run.started_unix_ms).substr(0, 16) : date_of(v));
  };
  std::vector<std::size_t> failing;  // newest first
  std::size_t configured = 0;
  for (std::size_t i = verdicts.size(); i-- > 0;) {
    configured += verdicts[i].configured ? 1 : 0;
    if (verdicts[i].configured && !verdicts[i].pass) failing.push_back(i);
  }
  if (!configured) {
    // Limits stored that fit none of the values (as verdict_banner says of one run): not "no
    // limit was stored", which would be false; the newest such run's notes say which and why.
    const auto noted = std::find_if(verdicts.rbegin(), verdicts.rend(),
                                    [](const ::daq::Verdict& v) { return !v.notes.empty(); });
    if (noted != verdicts.rend()) {
      std::string h =
          "<p class=\"verdict none\"><strong>No tolerance applies</strong> to these runs: the "
          "limits stored with them are for values these evaluations do not give, so they are "
          "not judged.</p>\n";
      for (const auto& n : noted->notes) h += "<p class=\"note\">" + esc(n) + "</p>\n";
      return h;
    }
    return "<p class=\"verdict none\"><strong>No tolerance configured</strong> for these runs: "
           "their values are not judged. " +
           tolerance_hint(views.back(), newest_doc, true) + "</p>\n";
  }
  // A run's failing values, each with what to check where a diagnostic says (the newest run's:
  // what to fix first).
  const auto failing_words = [](const ::daq::Verdict& v, bool advise) {
    std::string h;
    for (const auto& c : v.checks) {
      if (c.pass) continue;
      const auto advice = advise ? ::daq::diagnostic_advice(c.key) : std::string();
      h += (h.empty() ? "" : "; ") + failing_value(c, false) +
           (advice.empty() ? "" : ": " + esc(advice));
    }
    return h;
  };
  const auto& newest = verdicts.back();
  std::string h = fmt::format(
      "<p class=\"verdict {}\">The newest run, {}: <strong>{}</strong>{}.",
      !newest.configured ? "none"
      : newest.pass      ? "pass"
                         : "fail",
      when(views.back()), ::daq::summary(newest),
      newest.configured && !newest.pass ? " &mdash; " + failing_words(newest, true) : "");
  std::vector<std::size_t> earlier;  // the failing runs before the newest, newest first
  for (const auto i : failing)
    if (i + 1 != views.size()) earlier.push_back(i);
  h += fmt::format("<br>Earlier runs outside their specification: {} of {}{}", earlier.size(),
                   views.size() - 1, earlier.empty() ? "." : "");
  for (std::size_t k = 0; k < earlier.size() && k < max_listed; ++k)
    h += fmt::format("{} {}: {}", k ? ";" : " &mdash;", when(views[earlier[k]]),
                     failing_words(verdicts[earlier[k]], false));
  if (earlier.size() > max_listed)
    h += fmt::format("; and {} more (their ✗ in the table)", earlier.size() - max_listed);
  if (!earlier.empty()) h += ".";
  return h + "</p>\n";
}

std::string transposed(const std::vector<std::string>& head,
                       const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::string> runs{"value"};
  for (const auto& r : rows)
    runs.push_back(r.at(1).find("run ") != std::string::npos ? r.at(1)
                                                             : "run " + r.at(0) + "<br>" + r.at(1));
  std::vector<std::vector<std::string>> values;
  for (std::size_t j = 2; j < head.size(); ++j) {
    values.push_back({head[j]});
    for (const auto& r : rows) values.back().push_back(j < r.size() ? r[j] : "");
  }
  return table(runs, values, "num", "l");
}
}  // namespace

std::string comparison_report(const st::RunReader& store, std::span<const std::int64_t> runs,
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
  if (first.run.kind != "linear" && first.run.kind != "circle" && first.run.kind != "rotary")
    throw cal::InputError(fmt::format(
        "comparison report: {} runs cannot be compared (linear, rotary and circle runs can)",
        first.run.kind));
  // A rotary axis's angular positioning is compared as a linear axis's positioning is, in its
  // units (deg, arcsec: axis_text).
  const bool positioning = first.run.kind == "linear" || first.run.kind == "rotary";
  const AxisText& text = axis_text(first);

  // The runs' dates as x labels: the day, or with the time (UTC) when two runs share a day.
  std::vector<std::string> dates;
  bool same_day = false;
  for (std::size_t i = 0; i < views.size(); ++i) {
    dates.push_back(date_of(views[i]));
    if (i && dates[i] == dates[i - 1]) same_day = true;
  }
  // The small plots' labels are short, or they overlap at that size: the run where two share a
  // day, else the day (without the year when every run is in one year).
  std::vector<std::string> short_dates;
  const bool one_year = date_of(views.front()).substr(0, 4) == date_of(views.back()).substr(0, 4);
  for (std::size_t i = 0; i < views.size(); ++i)
    short_dates.push_back(same_day   ? fmt::format("run {}", views[i].run.id)
                          : one_year ? dates[i].substr(5)
                                     : dates[i]);
  if (same_day)
    for (std::size_t i = 0; i < views.size(); ++i)
      dates[i] = fmt::format("run {} {}", views[i].run.id,
                             iso_time(views[i].run.started_unix_ms).substr(5, 11));  // MM-DD HH:MM
  // The smallest span of a trend's y axis: four expanded uncertainties of the runs' positional
  // deviations (linear runs), at least 1 of the value's unit (0.1 ms): a change within it is not
  // a change worth a slope across the whole plot.
  double u_max_um = 0.0;
  struct Value {
    std::string key, symbol, unit;
    double value = 0;
    bool is_signed = false;  // a diagnostic: its sign is the error's direction
  };
  std::map<std::string, Line> trends;        // key -> value run by run
  std::map<std::string, double> limits;      // key -> the limit of the newest run that has one
  std::map<std::string, std::string> names;  // key -> symbol (unit)
  std::map<std::string, std::string> units;  // key -> unit as printed
  std::vector<std::string> trend_order;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::map<std::string, std::string>> cells;  // per run: key -> its value's cell
  XyChart overlay{.title = "Mean bidirectional deviation, run by run",
                  .x_label = std::string(text.x_label),
                  .y_label = fmt::format("deviation ({})", text.deviation),
                  // (300 pushed the first row of the trends below off page one, leaving a
                  // quarter of it empty, once the verdict was said in words above the table)
                  .height_pt = 260,
                  .zero_line = true};
  std::vector<PolarChart> polars;
  std::vector<::daq::Verdict> verdicts;  // run by run, in date order
  json newest;                           // the last run's result
  for (std::size_t i = 0; i < views.size(); ++i) {
    const auto& v = views[i];
    // (With runs on one day the date label already names the run.)
    const std::string label = same_day ? dates[i] : fmt::format("run {} ({})", v.run.id, dates[i]);
    std::vector<Value> values;
    json doc;
    if (positioning) {
      const auto l = evaluate_linear(store, v, o);
      double length_m = 0;
      // The laser's budget (ISO 230-2 Annex A) is a length's: not an angular reference's.
      if (v.run.kind == "linear")
        u_max_um = std::max(u_max_um, linear_budget(v, l, length_m).expanded_um);
      Line line{.label = label, .colour = palette(i), .width = 1.4, .markers = true};
      for (const auto& t : l.e.targets)
        line.x.push_back(t.target_mm), line.y.push_back(t.mean_bi_um);
      overlay.lines.push_back(std::move(line));
      // A rotary run's caldaq.rotary.v1 (its values in arcsec, judged by its arcsec limits).
      doc = v.run.kind == "rotary" ? rotary_doc(store, v, o) : ::daq::to_json(l.e);
      // In the order of every output (result_rows.hpp).
      for (const auto& r : ::daq::result_rows(doc))
        values.push_back({r.key, r.symbol, unit_text(r.unit), r.value});
    } else {
      const auto c = analyse_circle(store, v, o);
      polars.push_back(polar_of(c, "", 2 * i, label + ", "));
      doc = ::daq::circle_document(c.result, c.program, c.analysis);
      for (const auto& r : ::daq::circle_rows(doc))
        if (r.key.starts_with("G")) values.push_back({r.key, r.symbol, unit_text(r.unit), r.value});
      for (const auto& r : ::daq::diagnostic_rows(doc))
        values.push_back({r.key, r.symbol, unit_text(r.unit), r.value, true});
    }
    const auto verdict = ::daq::verdict_of(v.settings, doc);
    verdicts.push_back(verdict);
    newest = doc;
    // A re-compensated run is compared with the values it has now, and says so.
    std::vector<std::string> row{
        std::to_string(v.run.id) +
            (v.used.recompensated ? "<br><span class=\"changed\">re-compensated</span>" : ""),
        date_cell(iso_time(v.run.started_unix_ms), same_day)};
    std::map<std::string, std::string> by_key;  // the value cells, placed by key below
    // A linear run's table keeps to the values a specification limits (the unidirectional ones
    // are in each run's report): all twelve would not fit a printed page.
    if (positioning &&
        std::any_of(values.begin(), values.end(), [](const Value& x) { return x.key == "E_bi"; }))
      std::erase_if(values, [](const Value& x) { return !is_specified_value(x.key); });
    for (const auto& x : values) {
      if (!trends.count(x.key)) {
        trend_order.push_back(x.key);
        names[x.key] = x.symbol + " (" + x.unit + ")";
        units[x.key] = x.unit;
        trends[x.key] = Line{.colour = blue, .width = 1.4, .markers = true};
      }
      trends[x.key].x.push_back(static_cast<double>(i));
      trends[x.key].y.push_back(x.value);
      const auto* check = ::daq::find_check(verdict, x.key);
      if (check) limits[x.key] = check->limit;
      by_key[x.key] = (x.is_signed ? signed_text(x.value, 3) : um(x.value)) +
                      (check ? (check->pass ? " <span class=\"pass\">✓</span>"
                                            : " <span class=\"fail\">✗</span>")
                             : "");
    }
    row.push_back(!verdict.configured ? "<span class=\"unstated\">no tolerance</span>"
                  : verdict.pass      ? "<span class=\"pass\">PASS</span>"
                                      : "<span class=\"fail\">FAIL</span>");
    const auto air = stats(v.env.air_temperature), mat = stats(v.env.material_temperature);
    row.push_back(air.n ? fmt::format("{:.2f}", air.mean) : "&ndash;");
    row.push_back(mat.n ? fmt::format("{:.2f}", mat.mean) : "&ndash;");
    rows.push_back(std::move(row));
    cells.push_back(std::move(by_key));
  }
  // Each run's values under their own column: a circle's diagnostics come ranked by their gain,
  // in another order in each run (run 5's squareness stood under "Backlash Y").
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::vector<std::string> value_cells;
    for (const auto& k : trend_order) {
      const auto it = cells[i].find(k);
      value_cells.push_back(it == cells[i].end() ? "&ndash;" : it->second);
    }
    rows[i].insert(rows[i].begin() + 2, value_cells.begin(), value_cells.end());
  }
  std::vector<std::string> head{"run", "date"};
  for (const auto& k : trend_order) head.push_back(esc(names[k]));
  head.push_back("verdict");
  head.push_back("air (°C)");
  head.push_back("material (°C)");
  std::string body = fmt::format(
      "<p>The same test ({} of axis {}) on {} occasions, from {} to {}. ✓ / ✗: within / outside "
      "the limit of that run's specification.</p>\n",
      esc(first.run.kind), esc(first.run.axis), views.size(), date_of(first),
      date_of(views.back()));
  body += comparison_verdict(views, verdicts, newest, same_day);
  std::vector<const RunView*> each;
  for (const auto& v : views) each.push_back(&v);
  body += traceability_warnings(each);
  // The run and date cells are text that may wrap (a cell of class "r" does not: "3
  // re-compensated" and "run 3 11-28 07:31" unbroken printed the page shrunk to 0.9).
  body += head.size() <= max_run_columns ? table(head, rows, "num", "ll") : transposed(head, rows);
  // A linear comparison's overlay follows its table on page one; a circle's polar overlay
  // (as tall as the page is wide) comes after the trends, which fill page one below the
  // table (the overlay left half of it empty).
  std::string overlay_figure;
  if (positioning) {
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
    overlay_figure = figure(svg(all), "Both directions of every run on one scale.");
  }
  // One small plot per value: each on its own scale, the runs in date order, the limit dashed.
  body += "<h3>Each value over time</h3>\n<div class=\"multiples\">\n";
  std::size_t plotted = 0;
  // Those with a limit first: of a circle's 17 values the ten plotted left out the failing
  // backlash X (ranked last by its gain).
  auto plot_order = trend_order;
  std::stable_partition(plot_order.begin(), plot_order.end(),
                        [&](const std::string& k) { return limits.count(k) > 0; });
  for (const auto& k : plot_order) {
    if (positioning && !is_specified_value(k)) continue;
    if (plotted++ >= 10) break;
    XyChart small{.title = names[k],
                  .x_label = "",
                  .y_label = "",  // the title names it (a rotated label at this size was clipped)
                  .width_pt = 300,
                  // Four rows to a printed page (at 200, three: a circle's trends left a page
                  // 76 % full before the next)
                  .height_pt = 180,
                  .x_labels = short_dates,
                  .legend = false,
                  .text_scale = 1.65};
    const bool in_um = units[k] == "µm";
    small.min_y_span = std::max(in_um ? 4 * u_max_um : 0.0, units[k] == "ms" ? 0.1 : 1.0);
    small.lines.push_back(trends[k]);
    if (limits.count(k)) {
      const double n = static_cast<double>(views.size()) - 1;
      small.lines.push_back({.x = {-0.4, n + 0.4},
                             .y = {limits[k], limits[k]},
                             .colour = vermilion,
                             .width = 1.0,
                             .dashed = true});
    }
    body += figure(svg(small), names[k] + (limits.count(k) ? " (dashed: the limit)" : ""));
  }
  body += "</div>\n";
  body +=
      u_max_um > 0
          ? fmt::format(
                "<p class=\"note\">Each y axis spans at least {} µm, four times the largest "
                "expanded uncertainty U = {} µm of these runs (at least 1 of the value's unit): "
                "a change smaller than that is not drawn as a slope across the plot.</p>\n",
                fixed(std::max(4 * u_max_um, 1.0), 3), fixed(u_max_um, 3))
          : "<p class=\"note\">Each y axis spans at least 1 of its value's unit (0.1 ms): a "
            "smaller change is not drawn as a slope across the plot.</p>\n";
  body += overlay_figure;
  return page(fmt::format("Comparison: {} test of axis {}", first.run.kind, first.run.axis), body,
              o, who_of(first));
}

std::string as_found_as_left_report(const st::RunReader& store, std::int64_t found_id,
                                    std::int64_t left_id, const Options& o) {
  const auto found = load(store, found_id), left = load(store, left_id);
  if (found.run.kind != left.run.kind || found.run.axis != left.run.axis)
    throw cal::InputError(fmt::format(
        "as found / as left: run {} is a {} test of {}, run {} a {} test of {}; give the same test "
        "before and after the compensation",
        found_id, found.run.kind, found.run.axis, left_id, left.run.kind, left.run.axis));
  if (found.run.kind != "linear" && found.run.kind != "circle" && found.run.kind != "rotary")
    throw cal::InputError(fmt::format(
        "as found / as left: runs {} and {} are {} tests; linear, rotary or circle runs", found_id,
        left_id, found.run.kind));
  // A rotary axis's angular positioning is put side by side as a linear axis's is, in its units
  // (targets in deg, deviations and values in arcsec: axis_text), judged by its arcsec limits.
  const bool positioning = found.run.kind == "linear" || found.run.kind == "rotary";
  const AxisText& words = axis_text(found);
  struct Side {
    json doc;
    ::daq::Verdict verdict;
    struct Entry {
      std::string key, label;  // the label with its unit: "Squareness XY (µm/m)"
      double value = 0;
      bool is_signed = false;  // a diagnostic: its sign is the error's direction
    };
    std::vector<Entry> values;
  };
  // A circle's table mixed µm, µm/m and ms under a head without units.
  const auto entry = [](const auto& r, bool is_signed) {
    return Side::Entry{r.key, fmt::format("{} ({})", r.symbol, unit_text(r.unit)), r.value,
                       is_signed};
  };
  XyChart overlay{.title = "Mean bidirectional deviation, as found and as left",
                  .x_label = std::string(words.x_label),
                  .y_label = fmt::format("deviation ({})", words.deviation),
                  .height_pt = 240,
                  .zero_line = true};
  PolarChart polar{.title = "As found and as left"};
  const auto side = [&](const RunView& v, std::size_t colour, const char* label) {
    Side sd;
    if (positioning) {
      const auto l = evaluate_linear(store, v, o);
      Line line{.label = fmt::format("{} (run {})", label, v.run.id),
                .colour = palette(colour),
                .width = 1.4,
                .markers = true};
      for (const auto& t : l.e.targets)
        line.x.push_back(t.target_mm), line.y.push_back(t.mean_bi_um);
      overlay.lines.push_back(std::move(line));
      // A rotary run's caldaq.rotary.v1 (the values daq show prints, in arcsec).
      sd.doc = v.run.kind == "rotary" ? rotary_doc(store, v, o) : ::daq::to_json(l.e);
      // The values a specification limits: with the unidirectional six too the table filled
      // page one to its last line (a second warning above pushed its verdict row off it).
      const auto rows = ::daq::result_rows(sd.doc);
      const bool iso =
          std::any_of(rows.begin(), rows.end(), [](const auto& r) { return r.key == "E_bi"; });
      for (const auto& r : rows)
        if (!iso || is_specified_value(r.key)) sd.values.push_back(entry(r, false));
    } else {
      const auto c = analyse_circle(store, v, o);
      auto p = polar_of(c, "", 2 * colour, std::string(label) + " ");
      polar.first_axis = p.first_axis, polar.second_axis = p.second_axis;
      for (auto& t : p.traces) polar.traces.push_back(std::move(t));
      sd.doc = ::daq::circle_document(c.result, c.program, c.analysis);
      for (const auto& r : ::daq::circle_rows(sd.doc))
        if (r.key.starts_with("G")) sd.values.push_back(entry(r, false));
      for (const auto& r : ::daq::diagnostic_rows(sd.doc)) sd.values.push_back(entry(r, true));
    }
    sd.verdict = ::daq::verdict_of(v.settings, sd.doc);
    return sd;
  };
  const auto a = side(found, 1, "as found"), b = side(left, 2, "as left");
  std::vector<std::vector<std::string>> rows;
  for (const auto& e : a.values) {
    std::optional<double> vb;
    for (const auto& other : b.values)
      if (other.key == e.key) vb = other.value;
    const auto text = [&](double x) { return e.is_signed ? signed_text(x, 3) : um(x); };
    const auto* ca = ::daq::find_check(a.verdict, e.key);
    const auto* cb = ::daq::find_check(b.verdict, e.key);
    rows.push_back({esc(e.label), text(e.value) + " " + (ca ? verdict_cell(ca) : ""),
                    vb ? text(*vb) + " " + (cb ? verdict_cell(cb) : "") : "&ndash;",
                    vb ? signed_text(*vb - e.value, 3) : "&ndash;", limit_cell(cb ? cb : ca)});
  }
  const auto banner = [](const ::daq::Verdict& v) {
    return !v.configured ? std::string("<span class=\"unstated\">no tolerance configured</span>")
           : v.pass      ? std::string("<span class=\"pass\">PASS</span>")
                         : std::string("<span class=\"fail\">FAIL</span>");
  };
  // Page one: where the readings came from, who and what, the verdict of each run with its
  // failing values, the plot, the table (it began with the table and its verdict row at the
  // bottom, no SIMULATED banner, and a circle's polar plot was pushed to page two).
  const auto origins = origins_of({{found_id, origin_label(found)}, {left_id, origin_label(left)}});
  std::string body = origins.banner + summary_block(left, test_name(left));
  const auto verdict_words = [&](const Side& sd, const char* when, std::int64_t id) {
    const std::string failing = failing_values(sd.verdict, false);
    return fmt::format("{} (run {}): <strong>{}</strong>{}", when, id, banner(sd.verdict),
                       failing.empty() ? "" : " &mdash; " + failing);
  };
  const bool left_fails = b.verdict.configured && !b.verdict.pass;
  body += fmt::format("<p class=\"verdict {}\">{}.<br>{}.</p>\n",
                      left_fails                               ? "fail"
                      : b.verdict.configured && b.verdict.pass ? "pass"
                                                               : "none",
                      verdict_words(a, "As found", found_id), verdict_words(b, "As left", left_id));
  body += traceability_warnings(std::array<const RunView*, 2>{&found, &left});
  body += fmt::format(
      "<p>The machine as it was found (run {}, {}) and as it was left after the compensation "
      "(run {}, {}): the same test, side by side{}. Each run's full report follows.</p>\n",
      found_id, date_of(found), left_id, date_of(left),
      positioning ? ", by the values a specification limits (the unidirectional ones are in the "
                    "runs' reports)"
                  : "");
  if (positioning) {
    body += figure(svg(overlay), "The mean bidirectional positional deviation before and after.");
  } else {
    // Half the page's width, so that the table fits under it on page one; its text scaled as a
    // polar plot beside a table is, to print at 9 pt or larger.
    polar.text_scale = polar_beside_text_scale;
    body +=
        "<div class=\"overlay-polar\">" +
        figure(svg(polar),
               "Both directions of both runs on one scale, their least-squares centres removed.") +
        "</div>\n";
  }
  rows.push_back({"<strong>verdict</strong>", banner(a.verdict), banner(b.verdict), "", ""});
  body += table({"value", fmt::format("as found, run {}", found_id),
                 fmt::format("as left, run {}", left_id), "change", "limit"},
                rows, "num results", "lrrrr");
  Headline hl;
  body += fmt::format("<h2 class=\"run\" id=\"run-{}\">As found: {}</h2>\n", found_id,
                      esc(run_title(found))) +
          run_body(store, found, o, hl);
  body += fmt::format("<h2 class=\"run\" id=\"run-{}\">As left: {}</h2>\n", left_id,
                      esc(run_title(left))) +
          run_body(store, left, o, hl);
  return page(titled(origins, fmt::format("As found and as left: {} test of {}", found.run.kind,
                                          found.run.axis)),
              body, o, who_of(found));
}

// --- the compensation loop: an as-left run against the table written before it ------------------

namespace {

namespace ct = cal::comptable;

// Per target (the mean of the directions compared there): as found, what the table adds
// (expected change), as left.
struct LoopProfile {
  std::vector<double> target_mm, found_um, change_um, left_um;
};
LoopProfile loop_profile(const ct::VerifyInput& in) {
  LoopProfile p;
  for (std::size_t i = 0; i < in.target_mm.size();) {
    std::size_t j = i;
    double f = 0, c = 0, l = 0;
    for (; j < in.target_mm.size() && std::abs(in.target_mm[j] - in.target_mm[i]) < 1e-9; ++j)
      f += in.before_um[j], c += in.applied_um[j], l += in.after_um[j];
    const double n = static_cast<double>(j - i);
    p.target_mm.push_back(in.target_mm[i]);
    p.found_um.push_back(f / n), p.change_um.push_back(c / n), p.left_um.push_back(l / n);
    i = j;
  }
  return p;
}

Line loop_line(const std::vector<double>& x, const std::vector<double>& y, std::string label,
               Rgb colour, bool dashed) {
  return {.x = x,
          .y = y,
          .label = std::move(label),
          .colour = colour,
          .width = 1.6,
          .dashed = dashed,
          .markers = !dashed};
}

// Whether the control applied the table's sign, units, reference point and positions as written:
// what the finding says about each (a finding explains the whole change by one of them).
std::vector<std::vector<std::string>> loop_checks(const ct::Verification& v) {
  using F = ct::Finding;
  const auto ok = std::string("<span class=\"pass\">as written</span>");
  const auto bad = [](const std::string& s) { return "<span class=\"fail\">" + s + "</span>"; };
  const bool decided = v.finding == F::as_predicted || v.finding == F::inverted_sign ||
                       v.finding == F::unit_scale || v.finding == F::constant_shift ||
                       v.finding == F::position_shift;
  const std::string unknown =
      "<span class=\"unstated\">not determined (" + esc(ct::to_string(v.finding)) + ")</span>";
  if (!decided)
    return {{"Sign", unknown},
            {"Units", unknown},
            {"Reference point", unknown},
            {"Table positions", unknown}};
  return {{"Sign", v.finding == F::inverted_sign ? bad("inverted: the control applies −1 × the "
                                                       "values")
                                                 : ok},
          {"Units",
           v.finding == F::unit_scale
               ? bad(fmt::format("wrong: the control applies {} × the values", fixed(v.scale, 4)))
               : ok},
          {"Reference point",
           v.finding == F::constant_shift
               ? bad(fmt::format("off: a constant {} µm added", signed_text(v.offset_um, 3)))
               : ok},
          {"Table positions", v.finding == F::position_shift
                                  ? bad(fmt::format("shifted by {} mm", signed_text(v.shift_mm, 3)))
                                  : ok}};
}

// The table checked: its number, format, files, where it came from, the machine, when written,
// and what its values mean by the vendor's text.
std::vector<std::vector<std::string>> loop_table_rows(const ::daq::LoopCheck& c,
                                                      const std::string& machine) {
  const json doc = json::parse(c.compensation.json, nullptr, false);
  // The path a single file was written to (stored since the report was added), else the files'
  // names (a compensation of several files).
  const std::string written = doc.is_object() && doc.contains("file") && doc["file"].is_string()
                                  ? doc["file"].get<std::string>()
                                  : "";
  std::string files;
  const json listed = doc.is_object() ? doc.value("files", json::array()) : json::array();
  for (const auto& f : listed)
    if (f.is_object() && f.contains("name") && f["name"].is_string()) {
      const auto name = f["name"].get<std::string>();
      files += (files.empty() ? "" : ", ") + esc(name.empty() ? written : name);
    }
  if (!listed.is_array() || listed.empty()) files = esc(written);
  if (files.empty()) files = "<span class=\"unstated\">not stored (written to the terminal)</span>";
  return {{"Table", fmt::format("compensation {}, {} format, axis {}", c.compensation.id,
                                esc(c.compensation.format), esc(c.compensation.axis))},
          {"File", "<span class=\"path\">" + files + "</span>"},
          {"Machine", esc(machine)},
          {"Written",
           iso_time(c.compensation.created_unix_ms) + ", from " + esc(c.compensation.source)}};
}

// What the table's values are by the vendor's text, as stored with it (for the details).
std::string loop_meaning(const ::daq::LoopCheck& c) {
  const json doc = json::parse(c.compensation.json, nullptr, false);
  const json m = doc.is_object() ? doc.value("meaning", json::object()) : json::object();
  if (!m.is_object() || m.empty()) return "";
  return fmt::format(
      "<p>The table's values are <strong>the {}</strong> by the vendor's text ({}: {}); "
      "docs/compensation-tables.md.</p>\n",
      esc(ctx(m, "values")), esc(ctx(m, "evidence")), esc(ctx(m, "source")));
}

std::string loop_verdict(const ::daq::LoopCheck& c) {
  using F = ct::Finding;
  const auto& v = c.verification;
  const bool pass = v.finding == F::as_predicted;
  const bool none = v.finding == F::too_small;
  // A sentence of its own here, its micrometres as the report writes them (the terminal's "um").
  std::string advice = std::regex_replace(v.text, std::regex(R"((\d) um\b)"), "$1 µm");
  if (!advice.empty()) advice[0] = static_cast<char>(std::toupper(advice[0]));
  return fmt::format(
      "<p class=\"verdict {}\">Verdict: <strong>{}</strong> &mdash; finding: <strong>{}</strong>. "
      "{}.</p>\n",
      pass   ? "pass"
      : none ? "none"
             : "fail",
      pass   ? "PASS"
      : none ? "NOT DECIDED"
             : "FAIL",
      esc(ct::to_string(v.finding)), esc(advice));
}

}  // namespace

std::string verification_report(const st::RunReader& store, std::int64_t run,
                                std::optional<std::int64_t> compensation, const Options& o) {
  const auto left = load(store, run);
  const auto check = ::daq::check_run(store, run, compensation);
  if (!check)
    throw cal::InputError(fmt::format(
        "{}: run {}: no compensation of its axis on its machine was stored before it (or none of "
        "its stops lies where the table was made): nothing to verify (daq verify --list)",
        store.name(), run));
  const auto& c = *check;
  const auto& v = c.verification;
  std::optional<RunView> found;
  if (c.as_found_run != 0 && store.run(c.as_found_run)) found = load(store, c.as_found_run);
  const std::string found_name = found ? fmt::format("run {}", c.as_found_run)
                                       : "the table's source (" + c.compensation.source + ")";
  // What the run reads: a positioning run its own axis, a straightness run the axis it names.
  const std::string read = c.component.empty() ? "deviation" : "deviation of " + c.component;
  const auto p = loop_profile(c.input);
  std::vector<double> expected;
  for (std::size_t i = 0; i < p.target_mm.size(); ++i)
    expected.push_back(p.found_um[i] + p.change_um[i]);
  const std::string x_label = fmt::format("position of axis {} (mm)", left.run.axis);
  XyChart overlay{.title = "As found, as left and as the table should leave it",
                  .x_label = x_label,
                  .y_label = read + " (µm)",
                  // Page one holds it, the finding and the table: at 250 the finding's last
                  // row ("Agreement with the finding") fell onto page two, alone; at 190 with
                  // a line of traceability warning above it, the finding and the table did.
                  .height_pt = 165,
                  .zero_line = true};
  overlay.lines.push_back(
      loop_line(p.target_mm, p.found_um, "as found (" + found_name + ")", orange, false));
  overlay.lines.push_back(
      loop_line(p.target_mm, expected, "expected as left (as found + table)", green, true));
  overlay.lines.push_back(
      loop_line(p.target_mm, p.left_um, fmt::format("as left (run {})", run), blue, false));

  RunLabels labels;
  if (found) labels.emplace_back(found->run.id, origin_label(*found));
  labels.emplace_back(run, origin_label(left));
  const auto origins = origins_of(labels);
  std::vector<const RunView*> both;
  if (found) both.push_back(&*found);
  both.push_back(&left);
  std::string body = origins.banner + summary_block(left, test_name(left)) + loop_verdict(c) +
                     traceability_warnings(both);
  body += figure(svg(overlay),
                 "Each target's mean of the directions compared (µm). Dashed: the as-found error "
                 "plus what the table adds there, what the as-left run should read; a table "
                 "applied as written puts the as-left run on it.");
  // The numbers in the order daq verify prints them.
  double found_max = 0;
  for (const double x : c.input.before_um) found_max = std::max(found_max, std::abs(x));
  std::vector<std::vector<std::string>> numbers = {
      {"Largest |deviation| as found", um(found_max) + " µm"},
      {"Largest |deviation| as left, predicted", um(v.predicted_max_um) + " µm"},
      {"Largest |deviation| as left, measured", um(v.measured_max_um) + " µm"},
      {"Points compared", fmt::format("{} (targets × directions)", c.points)},
      {"Agreement with the finding", fmt::format("{} µm rms (within {} µm: twice the runs' "
                                                 "repeatability, at least 0.3 µm)",
                                                 um(v.mismatch_rms_um), um(v.tolerance_um))}};
  // The finding and the table are not split across pages (class keep).
  body += "<div class=\"pair keep\"><div><h3>The finding</h3>\n" +
          table({"", ""}, loop_checks(v), "kv") + table({"", ""}, numbers, "kv") +
          "</div><div><h3>The table</h3>\n" +
          table({"", ""}, loop_table_rows(c, left.machine), "kv") +
          fmt::format("<p>As found: {}{}; as left: run {}, {}.</p>", esc(found_name),
                      found ? ", " + date_of(*found) : std::string(), run, date_of(left)) +
          "</div></div>\n";
  const std::string meaning = loop_meaning(c);

  // Details: what the table was to remove, what it did, point by point.
  std::vector<double> measured;
  for (std::size_t i = 0; i < p.target_mm.size(); ++i)
    measured.push_back(p.left_um[i] - p.found_um[i]);
  XyChart change{.title = "The change: expected (the table) and measured (as left − as found)",
                 .x_label = x_label,
                 .y_label = "change (µm)",
                 .height_pt = 300,
                 .zero_line = true};
  change.lines.push_back(
      loop_line(p.target_mm, p.change_um, "expected: what the table adds", green, true));
  change.lines.push_back(
      loop_line(p.target_mm, measured, "measured: as left − as found", vermilion, false));
  body += "<div class=\"details\">\n<h3>What the table was to remove, and what it did</h3>\n";
  body += figure(svg(change),
                 "A table applied as written changes the deviation by what it adds (the expected "
                 "change, which is minus the as-found error where it corrects it fully); the "
                 "other sign mirrors it about zero, a unit error scales it, a reference-point "
                 "error moves it up or down, a position shift moves it along the axis.");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < c.input.target_mm.size(); ++i) {
    const auto& in = c.input;
    const char d = i < c.direction.size() ? c.direction[i] : '+';
    rows.push_back(
        {fixed(in.target_mm[i], 3), d == '+' ? "↑" : "↓", signed_text(in.before_um[i], 3),
         signed_text(in.applied_um[i], 3), signed_text(in.before_um[i] + in.applied_um[i], 3),
         signed_text(in.after_um[i], 3), signed_text(in.after_um[i] - in.before_um[i], 3),
         signed_text(in.after_um[i] - in.before_um[i] - in.applied_um[i], 3)});
  }
  body += table(
      {"target (mm)", "dir.", "as found (µm)", "expected change (µm)", "expected as left (µm)",
       "as left (µm)", "measured change (µm)", "measured − expected (µm)"},
      rows, "num", "rlrrrrrr");
  body +=
      "<p class=\"note\">↑: approach in the positive direction, ↓: in the negative. Each "
      "value is the mean of the run's stops at that target in that direction. The "
      "corrected table: <code>daq verify RUN --corrected FILE</code>.</p>\n" +
      meaning + "</div>\n";
  Headline hl;
  if (found)
    body += fmt::format("<h2 class=\"run\" id=\"run-{}\">As found: {}</h2>\n", found->run.id,
                        esc(run_title(*found))) +
            run_body(store, *found, o, hl);
  body +=
      fmt::format("<h2 class=\"run\" id=\"run-{}\">As left: {}</h2>\n", run, esc(run_title(left))) +
      run_body(store, left, o, hl);
  return page(titled(origins, fmt::format("Verification of compensation {}: {}", c.compensation.id,
                                          test_name(left))),
              body, o, who_of(left));
}

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
      "moving B (deviation in +A); the square's own error {} µm/m is removed.</p>\n",
      esc(a.source), esc(b.source), signed_text(square_error, 3));
  body += table({"result", "value", ""},
                {{"squareness", signed_text(r.squareness_um_per_m, 3) + " µm/m",
                  "positive: the angle between the positive axis directions exceeds 90°"},
                 {"", signed_text(r.arcsec(), 3) + "″", "arc seconds"}},
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
