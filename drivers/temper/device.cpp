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
       .choices = {"ds75", "gold", "temperx"},
       .default_value = std::string("gold"),
       .help = "the report layout (docs/drivers.md, TEMPer report families)"},
  };
  return t;
}

// The VID:PID pairs as the public projects list them (docs/drivers.md); several models share
// a pair, the firmware string read at open tells them apart.
constexpr KnownDevice kUsb[] = {
    {0x0c45, 0x7401, "temper", "PCsensor TEMPer / TEMPer1 / TEMPer2 (RDing)", "hid"},
    {0x0c45, 0x7402, "temper", "PCsensor TEMPerHUM (RDing)", "hid"},
    {0x413d, 0x2107, "temper", "PCsensor TEMPerGold / TEMPer2 (v3.x firmware)", "hid"},
    {0x1a86, 0xe025, "temper", "PCsensor TEMPerGold (CH554-based)", "hid"},
    {0x3553, 0xa001, "temper", "PCsensor TEMPerX", "hid"},
};

codec::TemperFamily family_of(const Options& o) {
  return codec::temper_family_from_string(o.text("family"));
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
  std::vector<Quantity> quantities(const Options& o, const InstrumentContext& c) const override {
    std::vector<Quantity> q{temperature_quantity(c)};
    if (family_of(o) == codec::TemperFamily::temperx) q.push_back(Quantity::air_humidity_pct);
    return q;
  }
  std::chrono::microseconds default_poll(const Options&, const InstrumentContext&) const override {
    return std::chrono::seconds(1);
  }
  int hid_interface() const override { return 1; }  // the sensor's; 0 is a keyboard
  std::span<const KnownDevice> usb_ids() const override { return kUsb; }
  std::span<const LegacyKey> legacy_keys() const override {
    static constexpr LegacyKey keys[] = {{"/temper_family", "family"}};
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
                       {.family = family_of(o), .quantity = temperature_quantity(c)});
  }
  std::unique_ptr<Decoder> make_decoder(const Options& o) const override;
  std::unique_ptr<sim::Twin> make_twin(boost::asio::io_context& io, sim::World& world,
                                       sim::Clock clock, const Options& o) const override {
    return std::make_unique<sim::TemperTwin>(io, world, std::move(clock),
                                             sim::TemperTwinConfig{.family = family_of(o)});
  }
};

// Hex reports, one per line ("80 80 09 2e 00 00 00 00", spaces optional); '#' starts a comment.
class HexReportDecoder final : public detail::LineDecoder {
 public:
  explicit HexReportDecoder(codec::TemperConfig config) : LineDecoder("TEMPer"), codec_(config) {}
  const codec::CodecStats& stats() const override { return codec_.stats(); }

 private:
  void on_line(std::string_view line, std::uint64_t offset,
               std::vector<DecodedItem>& out) override {
    if (const auto hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    std::string report;
    int nibble = -1;
    for (char c : line) {
      if (c == ' ' || c == '\t' || c == ':') continue;
      const int v =
          std::isxdigit(static_cast<unsigned char>(c))
              ? (std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
                                                             : (std::tolower(c) - 'a' + 10))
              : -1;
      if (v < 0) {
        out.push_back(
            {.kind = DecodedItem::Kind::error,
             .offset = offset,
             .error_kind = "malformed",
             .text = fmt::format("TEMPer: '{}' is not a hex report", line.substr(0, 40))});
        return;
      }
      if (nibble < 0) {
        nibble = v;
      } else {
        report.push_back(static_cast<char>(nibble << 4 | v));
        nibble = -1;
      }
    }
    if (report.empty() && nibble < 0) return;
    if (nibble >= 0 || report.size() != codec::TemperCodec::report_bytes) {
      out.push_back({.kind = DecodedItem::Kind::error,
                     .offset = offset,
                     .error_kind = "malformed",
                     .text = fmt::format("TEMPer: a report has 8 bytes, this line {}",
                                         nibble >= 0 ? "an odd number of hex digits"
                                                     : fmt::format("{}", report.size()))});
      return;
    }
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

  codec::TemperCodec codec_;
  std::vector<codec::TemperFrame> frames_;
  std::vector<codec::CodecError> errors_;
};

std::unique_ptr<Decoder> Driver::make_decoder(const Options& o) const {
  return std::make_unique<HexReportDecoder>(codec::TemperConfig{.family = family_of(o)});
}

}  // namespace

const DeviceDriver& driver() {
  static const Driver d;
  return d;
}

}  // namespace cal::drivers::temper
