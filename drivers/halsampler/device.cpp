// LinuxCNC halsampler position feeds in the device registry.
#include <fmt/format.h>

#include "cal/drivers/registry.hpp"
#include "decode_util.hpp"
#include "halsampler/codec.hpp"
#include "halsampler/instrument.hpp"
#include "halsampler/twin.hpp"

namespace cal::drivers::halsampler {
namespace {

const std::vector<OptionSpec>& table() {
  static const std::vector<OptionSpec> t{
      {.name = "tagged",
       .type = OptionType::boolean,
       .default_value = false,
       .help = "each line starts with the sample number (halsampler -t); halsampler's own "
               "default is untagged"},
      {.name = "column",
       .type = OptionType::integer,
       .min = 0,
       .max = 63,
       .default_value = std::int64_t{0},
       .help = "the value column of the test axis (0-based, after the sample number)"},
      {.name = "unit",
       .type = OptionType::choice,
       .choices = {"mm", "in"},
       .default_value = std::string("mm"),
       .help = "the machine's unit"},
  };
  return t;
}

codec::HalsamplerConfig config_of(const Options& o, int axis) {
  codec::HalsamplerConfig c{.sample_numbers = o.boolean("tagged"),
                            .column = {-1, -1, -1},
                            .metres_per_unit = o.text("unit") == "in"
                                                   ? codec::kInchesToMetres
                                                   : codec::kMillimetresToMetres};
  c.column[static_cast<std::size_t>(axis)] = static_cast<int>(o.integer("column"));
  return c;
}

class Driver final : public DeviceDriver {
 public:
  std::string_view name() const override { return "halsampler"; }
  std::string_view description() const override {
    return "LinuxCNC halsampler lines (a machine position feed), e.g. halsampler piped to a TCP "
           "port or a serial line";
  }
  std::string_view transport_example() const override { return "tcp 192.168.1.20:5000"; }
  std::span<const OptionSpec> options() const override { return table(); }
  std::vector<Quantity> quantities(const Options&, const InstrumentContext&) const override {
    return {Quantity::machine_position_m};
  }
  std::vector<std::uint8_t> channels(const Options&, const InstrumentContext& c) const override {
    return {static_cast<std::uint8_t>(c.test_axis)};
  }
  std::span<const LegacyKey> legacy_keys() const override {
    // Sessions recorded before the option tables always read sample numbers.
    static constexpr LegacyKey keys[] = {{"/feed/column", "column"},
                                         {"/feed/unit", "unit"},
                                         {"", "tagged", LegacyKey::Form::as_is, "true"}};
    return keys;
  }
  std::string_view decode_input() const override { return "the lines halsampler prints"; }
  std::unique_ptr<Instrument> make_instrument(boost::asio::io_context& io,
                                              std::unique_ptr<transport::Transport> t,
                                              InstrumentOptions instrument, const Options& o,
                                              const InstrumentContext& c) const override {
    return make_halsampler(io, std::move(t), std::move(instrument), config_of(o, c.test_axis));
  }
  std::unique_ptr<Decoder> make_decoder(const Options& o) const override {
    return detail::make_codec_decoder(
        codec::HalsamplerCodec(config_of(o, 0)),
        [](const codec::PositionFrame& f, std::uint64_t offset, std::vector<DecodedItem>& out) {
          if (f.lost_before > 0 || f.overrun) {
            DecodedItem gap{.kind = DecodedItem::Kind::gap, .offset = offset};
            if (f.lost_before > 0) {
              gap.text = fmt::format("{} samples lost before this one{}", f.lost_before,
                                     f.overrun ? " (overrun)" : "");
              gap.lost_samples = f.lost_before;
            } else {
              gap.text = "overrun: samples lost before this one (untagged: how many is unknown)";
            }
            out.push_back(gap);
          }
          for (std::uint8_t axis = 0; axis < 3; ++axis)
            if (f.position_m[axis]) {
              out.push_back(detail::reading_item(offset, axis, Quantity::machine_position_m,
                                                 *f.position_m[axis]));
              out.back().sample = f.sample;  // with tagged: halsampler -t's number
            }
        });
  }
  std::unique_ptr<sim::Twin> make_twin(boost::asio::io_context& io, sim::World& world,
                                       sim::Clock clock, const Options& o) const override {
    return std::make_unique<sim::HalsamplerTwin>(
        io, world, std::move(clock), sim::HalsamplerTwinConfig{.tagged = o.boolean("tagged")});
  }
};

}  // namespace

const DeviceDriver& driver() {
  static const Driver d;
  return d;
}

}  // namespace cal::drivers::halsampler
