// MTConnect SHDR adapters (machine position feeds) in the device registry.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cctype>
#include <span>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "decode_util.hpp"
#include "shdr/codec.hpp"
#include "shdr/instrument.hpp"
#include "shdr/twin.hpp"

namespace cal::drivers::shdr {
namespace {

const std::vector<OptionSpec>& table() {
  static const std::vector<OptionSpec> t{
      {.name = "key",
       .type = OptionType::string,
       .default_value = std::string(),
       .help = "the data item of the test axis in a run, e.g. \"Xact\"; empty: the test axis' "
               "entry of keys"},
      {.name = "keys",
       .type = OptionType::string,
       .default_value = std::string("Xact,Yact,Zact"),
       .help = "the data items of X, Y and Z, comma-separated (an empty entry: not read); daq "
               "decode reads all three"},
      {.name = "unit",
       .type = OptionType::choice,
       .choices = {"mm", "in"},
       .default_value = std::string("mm"),
       .help = "the unit of the positions (MTConnect positions are millimetres)"},
      {.name = "heartbeat_ms",
       .type = OptionType::integer,
       .unit = "ms",
       .min = 0,
       .max = 1800000,
       .default_value = std::int64_t{0},
       .help = "ping this often once the adapter answers * PONG (0: every <ms> its PONG says, as "
               "the MTConnect agent does); silence beyond twice the period drops the connection"},
      {.name = "legacy_timeout_s",
       .type = OptionType::number,
       .unit = "s",
       .min = 0,
       .default_value = 0.0,
       .help = "for an adapter that never answers * PONG: silence longer than this drops the "
               "connection (the agent's LegacyTimeout is 600 s); 0: never, since adapters send "
               "only on change and a machine dwelling at a target is silent"},
  };
  return t;
}

// The entries of `keys`: X, Y, Z (missing or empty entries: "").
std::array<std::string, 3> axis_keys(const Options& o) {
  std::array<std::string, 3> out;
  std::string_view rest = o.text("keys");
  for (std::size_t axis = 0; axis < 3 && !rest.empty(); ++axis) {
    const auto comma = rest.find(',');
    std::string_view item = rest.substr(0, comma);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    out[axis] = std::string(item);
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  return out;
}

codec::DecimalScale metres_per_unit(const Options& o) {
  return o.text("unit") == "in" ? codec::kInchesToMetres : codec::kMillimetresToMetres;
}

// A run: the test axis only.
codec::ShdrConfig run_config(const Options& o, int axis) {
  std::string key = o.text("key");
  if (key.empty()) key = axis_keys(o)[static_cast<std::size_t>(axis)];
  return {.keys = {{key, axis}}, .metres_per_unit = metres_per_unit(o)};
}

// daq decode: every axis of `keys`, and `key` as X when given.
codec::ShdrConfig decode_config(const Options& o) {
  codec::ShdrConfig c{.keys = {}, .metres_per_unit = metres_per_unit(o), .census = true};
  const auto keys = axis_keys(o);
  for (int axis = 0; axis < 3; ++axis)
    if (!keys[static_cast<std::size_t>(axis)].empty())
      c.keys[keys[static_cast<std::size_t>(axis)]] = axis;
  if (!o.text("key").empty()) c.keys[o.text("key")] = 0;
  return c;
}

// The codec's frames as readings (with the adapter's time), and what else the stream said
// (heartbeats, commands, assets) as notes.
class ShdrDecoder final : public Decoder {
 public:
  explicit ShdrDecoder(codec::ShdrConfig config) : codec_(std::move(config)) {}
  void feed(std::span<const std::byte> bytes, std::vector<DecodedItem>& out) override {
    const std::uint64_t offset = codec_.stats().bytes;
    const auto pongs = codec_.pongs(), commands = codec_.commands(), assets = codec_.assets();
    frames_.clear();
    errors_.clear();
    codec_.feed(bytes, frames_, errors_);
    detail::add_errors(errors_, out);
    const auto note = [&](std::string text) {
      out.push_back({.kind = DecodedItem::Kind::note, .offset = offset, .text = std::move(text)});
    };
    if (codec_.pongs() != pongs)
      note(codec_.pong_timeout_ms()
               ? fmt::format("* PONG: heartbeat every {} ms", *codec_.pong_timeout_ms())
               : std::string("* PONG without a period"));
    if (codec_.commands() != commands) note("command: " + codec_.last_command());
    if (codec_.assets() != assets) note("multi-line asset (skipped)");
    for (const auto& f : frames_)
      for (std::uint8_t axis = 0; axis < 3; ++axis) {
        // The adapter has no position for the axis (a run's trigger holds nothing through it).
        if (f.unavailable[axis]) note(fmt::format("{}: UNAVAILABLE (no position)", key_of(axis)));
        if (!f.position_m[axis]) continue;
        auto item =
            detail::reading_item(offset, axis, Quantity::machine_position_m, *f.position_m[axis]);
        item.device_time_unix_ns = f.time_unix_ns;
        ++positions_;
        if (f.relative_time_ms) item.device_time_relative_s = *f.relative_time_ms / 1e3;
        out.push_back(item);
      }
  }
  std::string_view key_of(std::uint8_t axis) const {
    for (const auto& [key, a] : codec_.config().keys)
      if (a == axis) return key;
    return "?";
  }
  // No position at all: most likely the control names its items otherwise (the Okuma
  // OSP-P300 says X1actw, not Xact). Name the numeric items seen and how to choose them.
  void finish(std::vector<DecodedItem>& out) override {
    if (positions_ > 0) return;
    const auto& seen = codec_.numeric_keys_seen();
    const auto position_like = [](std::string_view k) {
      std::string l(k);
      for (auto& c : l) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      return l.find("act") != std::string::npos || l.find("pos") != std::string::npos;
    };
    std::vector<std::string_view> shown;  // position-like names first, then the others
    for (const bool first : {true, false})
      for (const auto& k : seen)
        if (position_like(k) == first && shown.size() < kShown) shown.push_back(k);
    std::vector<std::string_view> configured;
    for (const auto& [key, axis] : codec_.config().keys) configured.push_back(key);
    out.push_back(
        {.kind = DecodedItem::Kind::note,
         .offset = codec_.stats().bytes,
         .text = seen.empty()
                     ? fmt::format("no position: none of the keys {} is in the input, and no other "
                                   "item has a numeric value; choose the keys with --set "
                                   "keys=KEY_X,KEY_Y,KEY_Z",
                                   fmt::join(configured, ", "))
                     : fmt::format("no position: none of the keys {} is in the input; data item "
                                   "keys with numeric values seen: {}{}; choose yours with --set "
                                   "keys=KEY_X,KEY_Y,KEY_Z",
                                   fmt::join(configured, ", "), fmt::join(shown, ", "),
                                   seen.size() > shown.size()
                                       ? fmt::format(" and {} more", seen.size() - shown.size())
                                       : "")});
  }
  const codec::CodecStats& stats() const override { return codec_.stats(); }

 private:
  static constexpr std::size_t kShown = 16;
  std::size_t positions_ = 0;
  codec::ShdrCodec codec_;
  std::vector<codec::PositionFrame> frames_;
  std::vector<codec::CodecError> errors_;
};

class Driver final : public DeviceDriver {
 public:
  std::string_view name() const override { return "shdr"; }
  std::string_view description() const override {
    return "MTConnect SHDR adapter (a machine position feed, TCP port 7878 by default)";
  }
  std::string_view transport_example() const override { return "tcp 192.168.1.20:7878"; }
  std::span<const OptionSpec> options() const override { return table(); }
  void validate(const Options& o) const override {
    const auto keys = axis_keys(o);
    if (keys[0].empty() && keys[1].empty() && keys[2].empty() && o.text("key").empty())
      throw InputError("options 'keys' and 'key': no data item to read");
  }
  std::vector<Quantity> quantities(const Options&, const InstrumentContext&) const override {
    return {Quantity::machine_position_m};
  }
  bool sends_on_change() const override { return true; }
  std::vector<std::uint8_t> channels(const Options&, const InstrumentContext& c) const override {
    return {static_cast<std::uint8_t>(c.test_axis)};
  }
  std::span<const LegacyKey> legacy_keys() const override {
    static constexpr LegacyKey keys[] = {{"/feed/key", "key"}, {"/feed/unit", "unit"}};
    return keys;
  }
  std::string_view decode_input() const override {
    return "the lines the adapter sends (a `nc HOST 7878` dump, or an agent's demo file)";
  }
  std::unique_ptr<Instrument> make_instrument(boost::asio::io_context& io,
                                              std::unique_ptr<transport::Transport> t,
                                              InstrumentOptions instrument, const Options& o,
                                              const InstrumentContext& c) const override {
    ShdrHeartbeat heartbeat{.override_period =
                                std::chrono::milliseconds(o.integer("heartbeat_ms"))};
    if (o.number("legacy_timeout_s") > 0)
      heartbeat.legacy_timeout =
          std::chrono::milliseconds(static_cast<std::int64_t>(o.number("legacy_timeout_s") * 1e3));
    return make_shdr(io, std::move(t), std::move(instrument), run_config(o, c.test_axis),
                     heartbeat);
  }
  std::unique_ptr<Decoder> make_decoder(const Options& o) const override {
    return std::make_unique<ShdrDecoder>(decode_config(o));
  }
  std::unique_ptr<sim::Twin> make_twin(boost::asio::io_context& io, sim::World& world,
                                       sim::Clock clock, const Options& o) const override {
    // It sends the data items this configuration reads, so its feed is understood.
    auto keys = axis_keys(o);
    if (!o.text("key").empty()) keys[0] = o.text("key");
    return std::make_unique<sim::ShdrTwin>(io, world, std::move(clock),
                                           sim::ShdrTwinConfig{.keys = keys});
  }
};

}  // namespace

const DeviceDriver& driver() {
  static const Driver d;
  return d;
}

}  // namespace cal::drivers::shdr
