// PCsensor TEMPer thermometers in the device registry: options, USB ids, factories.
#include <fmt/format.h>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "decode_util.hpp"
#include "temper/codec.hpp"
#include "temper/instrument.hpp"
#include "temper/twin.hpp"

namespace cal::drivers::temper {
namespace {

const std::vector<OptionSpec>& table() {
  static const std::vector<OptionSpec> t{
      {.name = "family",
       .type = OptionType::choice,
       .choices = {"ds75", "gold", "temperx", "sht2x", "si7005", "si7006"},
       .help = "the report layout; default: found from the firmware string (an unknown firmware "
               "is refused, naming it; docs/drivers.md has the table)"},
      {.name = "channels",
       .type = OptionType::integer_list,
       .min = 0,
       .max = 1,
       .help = "the sensors read, each its own series: 0 the stick's, 1 the probe's; default: "
               "[1] for role material (the probe on the machine), [0] for role air"},
  };
  return t;
}

// The VID:PID pairs as the devices report them, with the firmware strings the public projects
// saw behind each (urwen/temper and ccwienk/temper device tables, OpenBSD usbdevs via ugold.c);
// several models share a pair: the firmware string read at open tells them apart.
constexpr KnownDevice kUsb[] = {
    {0x0c45, 0x7401, "temper",
     "Microdia TEMPer: TEMPerF1.2/F1.4, TEMPer1F_V1.3, TEMPer1F1.1 (DS75)", "hid"},
    {0x0c45, 0x7402, "temper", "Microdia TEMPerHUM: TEMPer1F_H1V1.5F, TEMPerHum M12", "hid"},
    {0x413d, 0x2107, "temper",
     "PCsensor TEMPerGold_V3.1, TEMPerX_V3.1/V3.3 (also a TEMPer1F on TEMPerX_V3.3)", "hid"},
    {0x1a86, 0xe025, "temper",
     "WCH (QinHeng) TEMPerGold_V3.3/V3.4, TEMPer2_V3.7/V3.9, TEMPer1F_V3.9, "
     "TEMPerHUM_V3.8/V3.9",
     "hid"},
    {0x3553, 0xa001, "temper", "PCsensor TEMPerGold_V3.5, TEMPer2_V4.1", "hid"},
};

std::optional<codec::TemperFamily> family_of(const Options& o) {
  if (!o.has_value("family")) return std::nullopt;
  return codec::temper_family_from_string(o.text("family"));
}

std::vector<std::uint8_t> channels_of(const Options& o, const InstrumentContext& c) {
  if (o.has_value("channels")) {
    std::vector<std::uint8_t> out;
    for (const auto ch : o.integers("channels")) out.push_back(static_cast<std::uint8_t>(ch));
    return out;
  }
  if (c.role == "material") return {1};  // the probe, on the machine structure
  if (c.role == "air") return {0};       // the stick's own sensor, in the air
  return {};                             // every sensor of the model
}

Quantity temperature_quantity(const InstrumentContext& c) {
  return c.role == "air" ? Quantity::air_temperature_degc : Quantity::material_temperature_degc;
}

class Driver final : public DeviceDriver {
 public:
  std::string_view name() const override { return "temper"; }
  std::string_view description() const override {
    return "PCsensor TEMPer USB-HID thermometers (material or air temperature)";
  }
  std::string_view transport_example() const override { return "hid 413d:2107"; }
  std::span<const OptionSpec> options() const override { return table(); }
  void validate(const Options& o) const override {
    if (o.has_value("channels") && o.integers("channels").empty())
      throw InputError("option 'channels': give at least one channel (0 or 1)");
  }
  std::vector<Quantity> quantities(const Options& o, const InstrumentContext& c) const override {
    std::vector<Quantity> q{temperature_quantity(c)};
    if (family_of(o) != codec::TemperFamily::ds75 && family_of(o) != codec::TemperFamily::gold)
      q.push_back(Quantity::air_humidity_pct);  // the model may have humidity
    return q;
  }
  std::vector<std::uint8_t> channels(const Options& o, const InstrumentContext& c) const override {
    auto ch = channels_of(o, c);
    if (ch.empty()) ch = {0, 1};
    return ch;
  }
  std::chrono::microseconds default_poll(const Options&, const InstrumentContext&) const override {
    return std::chrono::seconds(1);
  }
  int hid_interface() const override { return 1; }  // the sensor's; 0 is a keyboard
  std::span<const KnownDevice> usb_ids() const override { return kUsb; }
  std::span<const LegacyKey> legacy_keys() const override {
    // Sessions recorded before the option tables had a family, and read every channel.
    static constexpr LegacyKey keys[] = {{"/temper_family", "family"},
                                         {"", "channels", LegacyKey::Form::as_is, "0,1"}};
    return keys;
  }
  std::string_view decode_input() const override {
    return "the 8-byte input reports in hex, one report per line";
  }
  std::unique_ptr<Instrument> make_instrument(boost::asio::io_context& io,
                                              std::unique_ptr<transport::Transport> t,
                                              InstrumentOptions instrument, const Options& o,
                                              const InstrumentContext& c) const override {
    return make_temper(io, std::move(t), std::move(instrument),
                       {.family = family_of(o),
                        .quantity = temperature_quantity(c),
                        .channels = channels_of(o, c)});
  }
  std::unique_ptr<Decoder> make_decoder(const Options& o) const override;
  std::unique_ptr<sim::Twin> make_twin(boost::asio::io_context& io, sim::World& world,
                                       sim::Clock clock, const Options& o) const override {
    // A TEMPer2 (two sensors) unless a family is set: then a model of that family.
    std::string firmware = "TEMPer2_V3.7    ";
    if (const auto f = family_of(o); f && f != codec::TemperFamily::gold)
      for (const auto& m : codec::temper_models())
        if (m.family == *f) {
          firmware = std::string(m.firmware);
          break;
        }
    return std::make_unique<sim::TemperTwin>(io, world, std::move(clock),
                                             sim::TemperTwinConfig{.firmware = firmware});
  }
};

// Hex reports, one per line ("80 80 09 2e 00 00 00 00", spaces optional; '#' starts a comment),
// after an optional line "firmware: <string>" that names the model as the device's answer to
// 01 86 ff 01 does: the family is then detected as on a device (unless --set family=...).
class HexReportDecoder final : public detail::LineDecoder {
 public:
  explicit HexReportDecoder(std::optional<codec::TemperFamily> family)
      : LineDecoder("TEMPer"),
        family_(family),
        codec_({.family = family.value_or(codec::TemperFamily::gold)}) {}
  const codec::CodecStats& stats() const override { return codec_.stats(); }

 private:
  void error(std::uint64_t offset, std::string text, std::vector<DecodedItem>& out) {
    out.push_back({.kind = DecodedItem::Kind::error,
                   .offset = offset,
                   .error_kind = "malformed",
                   .text = std::move(text)});
  }

  void on_firmware(std::string_view firmware, std::uint64_t offset, std::vector<DecodedItem>& out) {
    const auto* model = codec::temper_model_of(firmware);
    if (!model && !family_)
      return error(offset,
                   fmt::format("TEMPer firmware '{}' is not in the detection table (docs/"
                               "drivers.md); if you know its report layout, --set family=...",
                               firmware),
                   out);
    codec::TemperConfig config = codec_.config();
    if (model) {
      config.family = family_.value_or(model->family);
      config.inner = model->inner;
      config.probe = model->probe;
      config.ds75_slots = model->ds75_slots;
    }
    codec_.configure(config);
    known_ = true;
    out.push_back({.kind = DecodedItem::Kind::note,
                   .offset = offset,
                   .text = fmt::format("firmware '{}': {} family{}", firmware,
                                       codec::to_string(config.family),
                                       model ? fmt::format(" ({})", model->source) : "")});
  }

  void on_line(std::string_view line, std::uint64_t offset,
               std::vector<DecodedItem>& out) override {
    if (const auto hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    if (line.starts_with("firmware:")) {
      line.remove_prefix(9);
      while (!line.empty() && line.front() == ' ') line.remove_prefix(1);
      return on_firmware(line, offset, out);
    }
    std::string report;
    int nibble = -1;
    for (char c : line) {
      if (c == ' ' || c == '\t' || c == ':') continue;
      const auto u = static_cast<unsigned char>(c);
      const int v = std::isdigit(u) ? c - '0' : std::isxdigit(u) ? std::tolower(u) - 'a' + 10 : -1;
      if (v < 0)
        return error(offset, fmt::format("TEMPer: '{}' is not a hex report", line.substr(0, 40)),
                     out);
      if (nibble < 0) {
        nibble = v;
      } else {
        report.push_back(static_cast<char>(nibble << 4 | v));
        nibble = -1;
      }
    }
    if (report.empty() && nibble < 0) return;
    if (nibble >= 0 || report.size() != codec::TemperCodec::report_bytes)
      return error(offset,
                   fmt::format("TEMPer: a report has 8 bytes, this line {}",
                               nibble >= 0 ? "an odd number of hex digits"
                                           : fmt::format("{}", report.size())),
                   out);
    if (!known_ && !family_ && static_cast<unsigned char>(report[0]) == 0x80)
      return error(offset,
                   "TEMPer: a data report, but the family is unknown: give a line 'firmware: "
                   "<string>' first, or --set family=...",
                   out);
    frames_.clear();
    errors_.clear();
    codec_.feed(report, frames_, errors_);
    add_errors_at(offset, errors_, out);
    for (const auto& f : frames_) {
      out.push_back(detail::reading_item(offset, static_cast<std::uint8_t>(f.sensor),
                                         Quantity::material_temperature_degc, f.temperature_degc));
      if (f.humidity_pct)
        out.push_back(detail::reading_item(offset, 0, Quantity::air_humidity_pct, *f.humidity_pct));
    }
  }

  std::optional<codec::TemperFamily> family_;
  bool known_ = false;
  codec::TemperCodec codec_;
  std::vector<codec::TemperFrame> frames_;
  std::vector<codec::CodecError> errors_;
};

std::unique_ptr<Decoder> Driver::make_decoder(const Options& o) const {
  return std::make_unique<HexReportDecoder>(family_of(o));
}

}  // namespace

const DeviceDriver& driver() {
  static const Driver d;
  return d;
}

}  // namespace cal::drivers::temper
