// Line gauges and serial thermometers in the device registry: the configurable line codec's
// options and the factories.
#include <fmt/format.h>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "decode_util.hpp"
#include "line_gauge/codec.hpp"
#include "line_gauge/instrument.hpp"
#include "line_gauge/twin.hpp"

namespace cal::drivers::line_gauge {
namespace {

std::vector<std::string> preset_names() {
  std::vector<std::string> names{"none"};
  for (const auto& p : codec::gauge_presets()) names.emplace_back(p.name);
  return names;
}

const std::vector<OptionSpec>& table() {
  static const std::vector<OptionSpec> t{
      {.name = "preset",
       .type = OptionType::choice,
       .choices = preset_names(),
       .default_value = std::string("none"),
       .help = "a gauge family's documented output (docs/drivers.md, Gauge presets): its request "
               "and pattern, unless request or pattern is given; unit stays yours (the lines "
               "print none, except mahr_millimar's)"},
      {.name = "request",
       .type = OptionType::string,
       .default_value = std::string(),
       .help = "sent to poll the gauge, e.g. \"?\\r\" (\\r, \\n, \\t as written); empty: the "
               "gauge streams by itself",
       .unescape = true},
      {.name = "pattern",
       .type = OptionType::string,
       .default_value = std::string(),
       .help = "ECMAScript regex with one capture group for the number; empty: the whole line is "
               "a number, optionally followed by a unit word (mm, um, in, m)"},
      {.name = "unit",
       .type = OptionType::choice,
       .choices = {"mm", "um", "in", "m", "degC", "urad", "mrad", "mm/m", "arcsec"},
       .default_value = std::string("mm"),
       .help = "the unit of the printed number (a unit printed on the line wins); degC makes a "
               "serial thermometer, an angle unit (urad, mrad = mm/m, arcsec) an electronic "
               "level"},
      {.name = "scale",
       .type = OptionType::number,
       .default_value = 1.0,
       .help = "multiplies the printed number before the unit is applied"},
      {.name = "offset",
       .type = OptionType::number,
       .default_value = 0.0,
       .help = "added after scaling, in the printed unit"},
      {.name = "min_si",
       .type = OptionType::number,
       .help = "plausible minimum in SI (m, degC for a thermometer, rad for a level); default "
               "-10 m, -40 degC or -0.01 rad"},
      {.name = "max_si",
       .type = OptionType::number,
       .help = "plausible maximum in SI (m, degC for a thermometer, rad for a level); default "
               "10 m, 150 degC or 0.01 rad"},
  };
  return t;
}

const codec::GaugePreset* preset_of(const Options& o) {
  return codec::gauge_preset(o.text("preset"));  // nullptr for "none"
}

// A key given explicitly wins over the preset's value.
std::string request_of(const Options& o) {
  const auto* p = preset_of(o);
  return p && !o.is_set("request") ? std::string(p->request) : o.text("request");
}
std::string pattern_of(const Options& o) {
  const auto* p = preset_of(o);
  return p && !o.is_set("pattern") ? std::string(p->pattern) : o.text("pattern");
}

codec::GaugeConfig config_of(const Options& o) {
  codec::GaugeConfig c{.request = request_of(o),
                       .pattern = pattern_of(o),
                       .unit = codec::gauge_unit_from_string(o.text("unit")),
                       .scale = o.number("scale"),
                       .offset = o.number("offset")};
  if (c.unit == codec::GaugeUnit::degc) c.min_si = -40, c.max_si = 150;
  if (codec::is_angle(c.unit)) c.min_si = -0.01, c.max_si = 0.01;  // +-10 mm/m: beyond any level
  if (o.has_value("min_si")) c.min_si = o.number("min_si");
  if (o.has_value("max_si")) c.max_si = o.number("max_si");
  return c;
}

bool thermometer(const Options& o) { return o.text("unit") == "degC"; }
bool level(const Options& o) {
  return codec::is_angle(codec::gauge_unit_from_string(o.text("unit")));
}
Quantity quantity_of(const Options& o) {
  return thermometer(o) ? Quantity::material_temperature_degc
         : level(o)     ? Quantity::angle_rad
                        : Quantity::length_m;
}

class Driver final : public DeviceDriver {
 public:
  std::string_view name() const override { return "gauge"; }
  std::string_view description() const override {
    return "line-oriented serial gauge: the length transducer of a ballbar, a linear gauge, an "
           "electronic level (angle units), or a "
           "serial thermometer (configurable request, pattern and unit)";
  }
  std::string_view transport_example() const override { return "serial /dev/ttyUSB1 9600 8N1"; }
  std::span<const OptionSpec> options() const override { return table(); }
  void validate(const Options& o) const override {
    const auto c = config_of(o);
    codec::GaugeCodec check(c);  // throws cal::InputError for a bad pattern
    if (!(c.min_si < c.max_si))
      throw InputError(fmt::format("options 'min_si' {} and 'max_si' {}: min must be < max",
                                   c.min_si, c.max_si));
  }
  std::vector<Quantity> quantities(const Options& o, const InstrumentContext&) const override {
    return {quantity_of(o)};
  }
  bool may_be_silent(const Options& o) const override { return request_of(o).empty(); }
  std::chrono::microseconds default_poll(const Options&,
                                         const InstrumentContext& c) const override {
    if (c.role == "material") return std::chrono::seconds(1);  // a thermometer on the structure
    return std::chrono::milliseconds(10);
  }
  std::span<const LegacyKey> legacy_keys() const override {
    static constexpr LegacyKey keys[] = {
        {"/gauge/request", "request"}, {"/gauge/pattern", "pattern"}, {"/gauge/unit", "unit"},
        {"/gauge/preset", "preset"},   {"/gauge/scale", "scale"},     {"/gauge/offset", "offset"},
        {"/gauge/min_si", "min_si"},   {"/gauge/max_si", "max_si"}};
    return keys;
  }
  std::string_view decode_input() const override { return "the bytes the gauge sends"; }
  std::unique_ptr<Instrument> make_instrument(boost::asio::io_context& io,
                                              std::unique_ptr<transport::Transport> t,
                                              InstrumentOptions instrument, const Options& o,
                                              const InstrumentContext&) const override {
    return make_gauge(io, std::move(t), std::move(instrument), config_of(o));
  }
  std::unique_ptr<Decoder> make_decoder(const Options& o) const override {
    const Quantity q = quantity_of(o);
    return detail::make_codec_decoder(
        codec::GaugeCodec(config_of(o)),
        [q](const codec::GaugeFrame& f, std::uint64_t offset, std::vector<DecodedItem>& out) {
          out.push_back(detail::reading_item(offset, 0, q, f.value_si));
        });
  }
  std::unique_ptr<sim::Twin> make_twin(boost::asio::io_context& io, sim::World& world,
                                       sim::Clock clock, const Options& o) const override {
    std::string request = request_of(o);
    while (!request.empty() && (request.back() == '\r' || request.back() == '\n'))
      request.pop_back();
    sim::GaugeTwinConfig c{.continuous = request.empty(), .request = request};
    // The twin prints the family's lines (its terminator, prefix and unit word).
    if (const auto* p = preset_of(o)) c.style = sim::gauge_line_style(p->name);
    if (thermometer(o)) {
      c.decimals = 3;
      c.value = [](const sim::World& w) { return w.state().machine_temperature_degc; };
    }
    return std::make_unique<sim::GaugeTwin>(io, world, std::move(clock), std::move(c));
  }
};

}  // namespace

const DeviceDriver& driver() {
  static const Driver d;
  return d;
}

}  // namespace cal::drivers::line_gauge
