#include "session_spec.hpp"

#include <chrono>
#include <ctime>

#include "cal/analysis/error.hpp"
#include "cal/drivers/instruments.hpp"

namespace daq {

using nlohmann::json;
namespace codec = cal::drivers::codec;

std::unique_ptr<cal::drivers::Instrument> make_instrument(
    boost::asio::io_context& io, const InstrumentSpec& spec,
    std::unique_ptr<cal::drivers::transport::Transport> transport,
    cal::drivers::InstrumentOptions options) {
  options.device = spec.device;
  if (spec.driver == "ids3010")
    return cal::drivers::make_ids3010(io, std::move(transport), std::move(options),
                                      {.axes = spec.ids_axes});
  if (spec.driver == "ptu300")
    return cal::drivers::make_ptu300(io, std::move(transport), std::move(options));
  if (spec.driver == "gauge")
    return cal::drivers::make_gauge(io, std::move(transport), std::move(options), spec.gauge);
  if (spec.driver == "temper")
    return cal::drivers::make_temper(
        io, std::move(transport), std::move(options),
        {.family = codec::temper_family_from_string(spec.temper_family),
         .quantity = spec.role == "air" ? cal::drivers::Quantity::air_temperature_degc
                                        : cal::drivers::Quantity::material_temperature_degc});
  if (spec.driver == "shdr" || spec.driver == "halsampler") {
    const double m_per_unit = spec.feed_unit == "in" ? 0.0254 : 1e-3;
    cal::drivers::PositionFeedOptions f{.kind = spec.driver == "shdr"
                                                    ? cal::drivers::PositionFeedKind::shdr
                                                    : cal::drivers::PositionFeedKind::halsampler};
    f.shdr.keys = {{spec.feed_key, spec.feed_axis}};
    f.shdr.metres_per_unit = m_per_unit;
    f.halsampler.column = {-1, -1, -1};
    f.halsampler.column[static_cast<std::size_t>(spec.feed_axis)] = spec.feed_column;
    f.halsampler.metres_per_unit = m_per_unit;
    return cal::drivers::make_position_feed(io, std::move(transport), std::move(options), f);
  }
  throw cal::InputError("instrument driver '" + spec.driver + "' cannot be built here");
}

namespace {
std::string unit_name(codec::GaugeUnit u) {
  switch (u) {
    case codec::GaugeUnit::mm:
      return "mm";
    case codec::GaugeUnit::um:
      return "um";
    case codec::GaugeUnit::inch:
      return "in";
    case codec::GaugeUnit::m:
      return "m";
    case codec::GaugeUnit::degc:
      return "degC";
    case codec::GaugeUnit::none:
      return "none";
  }
  return "none";
}
}  // namespace

json to_json(const InstrumentSpec& s) {
  return {{"device", s.device},
          {"driver", s.driver},
          {"role", s.role},
          {"transport", s.transport},
          {"ids_axes", s.ids_axes},
          {"gauge",
           {{"request", s.gauge.request},
            {"pattern", s.gauge.pattern},
            {"unit", unit_name(s.gauge.unit)},
            {"scale", s.gauge.scale},
            {"offset", s.gauge.offset},
            {"min_si", s.gauge.min_si},
            {"max_si", s.gauge.max_si}}},
          {"temper_family", s.temper_family},
          {"feed",
           {{"axis", s.feed_axis},
            {"key", s.feed_key},
            {"column", s.feed_column},
            {"unit", s.feed_unit}}}};
}

InstrumentSpec instrument_spec_from_json(const json& j) {
  InstrumentSpec s;
  s.device = j.at("device").get<std::uint16_t>();
  s.driver = j.at("driver").get<std::string>();
  s.role = j.value("role", "");
  s.transport = j.value("transport", "");
  if (j.contains("ids_axes")) s.ids_axes = j["ids_axes"].get<std::array<bool, 3>>();
  if (const auto g = j.find("gauge"); g != j.end()) {
    s.gauge.request = g->value("request", "");
    s.gauge.pattern = g->value("pattern", "");
    s.gauge.unit = codec::gauge_unit_from_string(g->value("unit", "mm"));
    s.gauge.scale = g->value("scale", 1.0);
    s.gauge.offset = g->value("offset", 0.0);
    s.gauge.min_si = g->value("min_si", -10.0);
    s.gauge.max_si = g->value("max_si", 10.0);
  }
  s.temper_family = j.value("temper_family", s.temper_family);
  if (const auto f = j.find("feed"); f != j.end()) {
    s.feed_axis = f->value("axis", 0);
    s.feed_key = f->value("key", s.feed_key);
    s.feed_column = f->value("column", 0);
    s.feed_unit = f->value("unit", s.feed_unit);
  }
  return s;
}

json to_json(const cal::daq::Config& c) {
  json j{{"machine", c.machine_name},
         {"description", c.machine_description},
         {"campaign", c.campaign}};
  const auto& e = c.environment;
  j["environment"] = {{"equation", e.equation},
                      {"stale_after_s", e.stale_after_s},
                      {"on_stale", e.on_stale == cal::daq::StalePolicy::stop ? "stop" : "fallback"},
                      {"fallback_temperature_degc", e.fallback_temperature_degc},
                      {"fallback_pressure_pa", e.fallback_pressure_pa},
                      {"fallback_humidity_pct", e.fallback_humidity_pct},
                      {"fallback_material_degc", e.fallback_material_degc},
                      {"co2_umol_per_mol", e.co2_umol_per_mol},
                      {"wavelength_nm", e.wavelength_nm},
                      {"expansion_ppm_per_k", e.expansion_ppm_per_k}};
  j["trigger"] = {{"tolerance_um", c.trigger.tolerance_um},
                  {"dwell_s", c.trigger.dwell_s},
                  {"window_mm", c.trigger.window_mm}};
  if (c.linear) {
    const auto& l = *c.linear;
    j["linear"] = {{"axis", l.axis},
                   {"first_mm", l.first_mm},
                   {"last_mm", l.last_mm},
                   {"random_fraction", l.random_fraction},
                   {"cycle", l.cycle},
                   {"runs", l.runs},
                   {"bidirectional", l.bidirectional},
                   {"overrun_mm", l.overrun_mm},
                   {"feed_mm_per_min", l.feed_mm_per_min},
                   {"dwell_s", l.dwell_s},
                   {"dead_path_mm", l.dead_path_mm},
                   {"standard", l.standard}};
    if (l.interval_mm) j["linear"]["interval_mm"] = *l.interval_mm;
    if (l.count) j["linear"]["count"] = *l.count;
  }
  if (c.circle) {
    const auto& ci = *c.circle;
    j["circle"] = {{"plane", ci.plane},
                   {"radius_mm", ci.radius_mm},
                   {"feed_mm_per_min", ci.feed_mm_per_min},
                   {"sample_rate_hz", ci.sample_rate_hz},
                   {"overshoot_deg", ci.overshoot_deg},
                   {"centre_mm", ci.centre_mm},
                   {"calibrated_radius_mm", ci.calibrated_radius_mm}};
  }
  return j;
}

cal::daq::Config config_from_json(const json& j) {
  cal::daq::Config c;
  c.machine_name = j.value("machine", "machine");
  c.machine_description = j.value("description", "");
  c.campaign = j.value("campaign", "");
  if (const auto e = j.find("environment"); e != j.end()) {
    auto& x = c.environment;
    x.equation = e->value("equation", x.equation);
    x.stale_after_s = e->value("stale_after_s", x.stale_after_s);
    x.on_stale = e->value("on_stale", "stop") == "stop" ? cal::daq::StalePolicy::stop
                                                        : cal::daq::StalePolicy::fallback;
    x.fallback_temperature_degc =
        e->value("fallback_temperature_degc", x.fallback_temperature_degc);
    x.fallback_pressure_pa = e->value("fallback_pressure_pa", x.fallback_pressure_pa);
    x.fallback_humidity_pct = e->value("fallback_humidity_pct", x.fallback_humidity_pct);
    x.fallback_material_degc = e->value("fallback_material_degc", x.fallback_material_degc);
    x.co2_umol_per_mol = e->value("co2_umol_per_mol", x.co2_umol_per_mol);
    x.wavelength_nm = e->value("wavelength_nm", x.wavelength_nm);
    x.expansion_ppm_per_k = e->value("expansion_ppm_per_k", x.expansion_ppm_per_k);
  }
  if (const auto t = j.find("trigger"); t != j.end()) {
    c.trigger.tolerance_um = t->value("tolerance_um", c.trigger.tolerance_um);
    c.trigger.dwell_s = t->value("dwell_s", c.trigger.dwell_s);
    c.trigger.window_mm = t->value("window_mm", c.trigger.window_mm);
  }
  if (const auto l = j.find("linear"); l != j.end()) {
    cal::daq::LinearTestConfig x;
    x.axis = l->value("axis", x.axis);
    x.first_mm = l->value("first_mm", x.first_mm);
    x.last_mm = l->value("last_mm", x.last_mm);
    if (l->contains("interval_mm")) x.interval_mm = (*l)["interval_mm"].get<double>();
    if (l->contains("count")) x.count = (*l)["count"].get<int>();
    x.random_fraction = l->value("random_fraction", x.random_fraction);
    x.cycle = l->value("cycle", x.cycle);
    x.runs = l->value("runs", x.runs);
    x.bidirectional = l->value("bidirectional", x.bidirectional);
    x.overrun_mm = l->value("overrun_mm", x.overrun_mm);
    x.feed_mm_per_min = l->value("feed_mm_per_min", x.feed_mm_per_min);
    x.dwell_s = l->value("dwell_s", x.dwell_s);
    x.dead_path_mm = l->value("dead_path_mm", x.dead_path_mm);
    x.standard = l->value("standard", x.standard);
    c.linear = x;
  }
  if (const auto ci = j.find("circle"); ci != j.end()) {
    cal::daq::CircleTestConfig x;
    x.plane = ci->value("plane", x.plane);
    x.radius_mm = ci->value("radius_mm", x.radius_mm);
    x.feed_mm_per_min = ci->value("feed_mm_per_min", x.feed_mm_per_min);
    x.sample_rate_hz = ci->value("sample_rate_hz", x.sample_rate_hz);
    x.overshoot_deg = ci->value("overshoot_deg", x.overshoot_deg);
    x.centre_mm = ci->value("centre_mm", x.centre_mm);
    x.calibrated_radius_mm = ci->value("calibrated_radius_mm", x.calibrated_radius_mm);
    c.circle = x;
  }
  return c;
}

std::string capture_header(const cal::daq::Config& c, const std::vector<InstrumentSpec>& specs,
                           const std::string& software) {
  json j{{"format", "caldaq.capture-header.v1"}, {"software", software}, {"config", to_json(c)}};
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  j["started_utc"] = buf;
  j["instruments"] = json::array();
  for (const auto& s : specs) j["instruments"].push_back(to_json(s));
  return j.dump(1);
}

}  // namespace daq
