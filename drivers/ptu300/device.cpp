// Vaisala PTU300 in the device registry: its options, factories and probe.
#include <fmt/format.h>

#include "cal/drivers/registry.hpp"
#include "decode_util.hpp"
#include "ptu300/codec.hpp"
#include "ptu300/instrument.hpp"
#include "ptu300/twin.hpp"

namespace cal::drivers::ptu300 {
namespace {

const std::vector<OptionSpec>& table() {
  static const std::vector<OptionSpec> t{
      {.name = "checksum",
       .type = OptionType::choice,
       .choices = {"none", "cs2", "cs4", "csx"},
       .default_value = std::string("none"),
       .help = "the checksum field a custom FORM ends its lines with (CS2, CS4 or CSX of the "
               "user's guide); none for the default FORM"},
  };
  return t;
}

codec::Ptu300Config config_of(const Options& o) {
  const auto& c = o.text("checksum");
  return {.checksum = c == "cs2"   ? codec::Ptu300Checksum::cs2
                      : c == "cs4" ? codec::Ptu300Checksum::cs4
                      : c == "csx" ? codec::Ptu300Checksum::csx
                                   : codec::Ptu300Checksum::none};
}

class Driver final : public DeviceDriver {
 public:
  std::string_view name() const override { return "ptu300"; }
  std::string_view description() const override {
    return "Vaisala PTU300 barometer, hygrometer and thermometer (serial, 4800 7E1 by default)";
  }
  std::string_view transport_example() const override { return "serial /dev/ttyUSB0 4800 7E1"; }
  std::span<const OptionSpec> options() const override { return table(); }
  std::vector<Quantity> quantities(const Options&, const InstrumentContext&) const override {
    return {Quantity::air_pressure_pa, Quantity::air_temperature_degc, Quantity::air_humidity_pct,
            Quantity::dew_point_degc};
  }
  std::chrono::microseconds default_poll(const Options&, const InstrumentContext&) const override {
    return std::chrono::seconds(1);
  }
  std::optional<ProbeSpec> probe() const override {
    return ProbeSpec{.transport_kind = "serial",
                     .default_serial = "4800 7E1",
                     .request = codec::ptu300_send(),
                     .recognise = [](std::string_view received) {
                       using V = ProbeSpec::Verdict;
                       if (received.find('\n') == std::string_view::npos)
                         return ProbeSpec::Answer{};
                       codec::Ptu300Codec c;
                       std::vector<codec::Ptu300Frame> frames;
                       c.feed(received, frames);
                       for (const auto& f : frames)
                         if (f.pressure_pa || f.temperature_degc)
                           return ProbeSpec::Answer{V::yes, "answered SEND"};
                       return ProbeSpec::Answer{V::no, "no PTU300 answer to SEND"};
                     }};
  }
  std::string_view decode_input() const override { return "the bytes the PTU300 sends"; }
  std::unique_ptr<Instrument> make_instrument(boost::asio::io_context& io,
                                              std::unique_ptr<transport::Transport> t,
                                              InstrumentOptions instrument, const Options& o,
                                              const InstrumentContext&) const override {
    return make_ptu300(io, std::move(t), std::move(instrument), config_of(o));
  }
  std::unique_ptr<Decoder> make_decoder(const Options& o) const override {
    return detail::make_codec_decoder(
        codec::Ptu300Codec(config_of(o)),
        [](const codec::Ptu300Frame& f, std::uint64_t offset, std::vector<DecodedItem>& out) {
          for_each_reading(f, [&](Quantity q, double v) {
            out.push_back(detail::reading_item(offset, 0, q, v));
          });
          const auto note = [&](std::string text) {
            out.push_back(
                {.kind = DecodedItem::Kind::note, .offset = offset, .text = std::move(text)});
          };
          for (const auto& field : f.fields) {
            if (const auto text = unavailable_text(field))
              note(*text);
            else if (!field.available)
              note(fmt::format("{}: not available (the device printed stars)", field.label));
            else if (field.quantity == codec::Ptu300Quantity::gauge_pressure)
              note(fmt::format("{} = {} Pa gauge ({}): not taken for the air pressure", field.label,
                               field.value_si, field.unit));
            else if (field.quantity == codec::Ptu300Quantity::pressure_tendency)
              note(fmt::format("{} = {} Pa (3 h pressure trend)", field.label, field.value_si));
          }
          if (f.fields.empty() && !f.text.empty()) note("text: " + f.text);
        });
  }
  std::unique_ptr<sim::Twin> make_twin(boost::asio::io_context& io, sim::World& world,
                                       sim::Clock clock, const Options&) const override {
    return std::make_unique<sim::Ptu300Twin>(io, world, std::move(clock));
  }
};

}  // namespace

const DeviceDriver& driver() {
  static const Driver d;
  return d;
}

}  // namespace cal::drivers::ptu300
