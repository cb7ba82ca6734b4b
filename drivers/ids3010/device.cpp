// Attocube IDS3010 in the device registry: its options, factories, USB ids (none: it is a
// network device) and probe.
#include <fmt/format.h>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "decode_util.hpp"
#include "ids3010/codec.hpp"
#include "ids3010/instrument.hpp"
#include "ids3010/twin.hpp"

namespace cal::drivers::ids3010 {
namespace {

using codec::IdsMethod;

const std::vector<OptionSpec>& table() {
  static const std::vector<OptionSpec> t{
      {.name = "axes",
       .type = OptionType::integer_list,
       .min = 0,
       .max = 2,
       .default_value = std::vector<std::int64_t>{0},
       .help = "interferometer axes to read (0, 1, 2); a linear run uses the first"},
      {.name = "start_measurement",
       .type = OptionType::boolean,
       .default_value = true,
       .help = "send startMeasurement on connect (false: only observe a running measurement)"},
      {.name = "environment",
       .type = OptionType::boolean,
       .default_value = true,
       .help = "read the environmental unit (ECU): air temperature, pressure, humidity, "
               "refractive index"},
      {.name = "api",
       .type = OptionType::choice,
       .choices = {"auto", "ids", "sen"},
       .default_value = std::string("auto"),
       .help = "the API generation: com.attocube.ids (firmware before 1.9.1), com.attocube.sen "
               "(1.9.1 and later), or auto: asked at connect"},
      {.name = "environment_period_s",
       .type = OptionType::number,
       .unit = "s",
       .min = 0.05,
       .max = 3600,
       .default_value = 1.0,
       .help = "how often the ECU is read"},
  };
  return t;
}

Ids3010Options ids_options(const Options& o) {
  Ids3010Options ids{.axes = {false, false, false},
                     .start_measurement = o.boolean("start_measurement"),
                     .read_environment = o.boolean("environment"),
                     .environment_period = std::chrono::milliseconds(
                         static_cast<std::int64_t>(o.number("environment_period_s") * 1e3))};
  for (const auto a : o.integers("axes")) ids.axes[static_cast<std::size_t>(a)] = true;
  return ids;
}

// A transcript of both directions (as a TCP stream capture gives it): request lines are known
// by their "method" member and teach the codec the ids of the answers that follow.
class TranscriptDecoder final : public detail::LineDecoder {
 public:
  TranscriptDecoder() : LineDecoder("IDS") {}
  const codec::CodecStats& stats() const override { return codec_.stats(); }

 private:
  // attocube's own client (IDS-APIs python/ACS.py) writes each request with no terminator and
  // reads the answer up to CR LF, so a capture of both directions has each request and its
  // answer on one line: each JSON object of a line is taken on its own.
  void on_line(std::string_view line, std::uint64_t offset,
               std::vector<DecodedItem>& out) override {
    for (const auto object : codec::json_objects(line)) {
      const std::string with_eol = std::string(object) + "\n";
      if (object.find("\"method\"") != std::string_view::npos) {
        codec_.note_requests(codec::as_bytes(with_eol));
        continue;
      }
      frames_.clear();
      errors_.clear();
      codec_.feed(with_eol, frames_, errors_);
      add_errors_at(offset, errors_, out);
      for (const auto& r : frames_) on_response(r, offset, out);
    }
  }

  void on_response(const codec::IdsResponse& r, std::uint64_t offset,
                   std::vector<DecodedItem>& out) {
    if (r.error_code != 0)
      out.push_back({.kind = DecodedItem::Kind::note,
                     .offset = offset,
                     .text = fmt::format(
                         "{}: {} {}{}{}", codec::method_name(r.method, r.api),
                         codec::returns_warning(r.method) && !r.rpc_error ? "warning" : "error",
                         r.error_code, r.error_message.empty() ? "" : ": ", r.error_message)});
    const auto status = r.error_code == 0 ? ReadingStatus::ok : ReadingStatus::signal_lost;
    for (std::uint8_t a = 0; a < 3; ++a)
      if (r.displacement_m[a])
        out.push_back(detail::reading_item(offset, a, Quantity::displacement_m,
                                           *r.displacement_m[a], status));
    const auto air = [&](const std::optional<double>& v, Quantity q) {
      if (v) out.push_back(detail::reading_item(offset, 0, q, *v));
    };
    air(r.temperature_degc, Quantity::air_temperature_degc);
    air(r.pressure_pa, Quantity::air_pressure_pa);
    air(r.humidity_pct_rh, Quantity::air_humidity_pct);
    air(r.refractive_index, Quantity::refractive_index);
    if (!r.text.empty())
      out.push_back({.kind = DecodedItem::Kind::note,
                     .offset = offset,
                     .text = fmt::format("{}: {}", codec::method_name(r.method, r.api), r.text)});
  }

  codec::IdsCodec codec_;
  std::vector<codec::IdsResponse> frames_;
  std::vector<codec::CodecError> errors_;
};

class Driver final : public DeviceDriver {
 public:
  std::string_view name() const override { return "ids3010"; }
  std::string_view description() const override {
    return "Attocube IDS3010 displacement interferometer (JSON-RPC over TCP, port 9090)";
  }
  std::string_view transport_example() const override { return "tcp HOST:9090"; }
  std::span<const OptionSpec> options() const override { return table(); }
  void validate(const Options& o) const override {
    if (o.integers("axes").empty())
      throw InputError("option 'axes': give at least one axis (0, 1 or 2)");
  }
  std::vector<Quantity> quantities(const Options& o, const InstrumentContext&) const override {
    std::vector<Quantity> q{Quantity::displacement_m};
    if (o.boolean("environment"))
      q.insert(q.end(), {Quantity::air_temperature_degc, Quantity::air_pressure_pa,
                         Quantity::air_humidity_pct, Quantity::refractive_index});
    return q;
  }
  std::vector<std::uint8_t> channels(const Options& o, const InstrumentContext&) const override {
    std::vector<std::uint8_t> c;
    for (const auto a : o.integers("axes")) c.push_back(static_cast<std::uint8_t>(a));
    return c;
  }
  // getCurrentMode in both generations at once (ids 1 and 2): the one that answers with a
  // result names the API generation.
  std::optional<ProbeSpec> probe() const override {
    codec::IdsCodec request;
    request.set_api(codec::IdsApi::sen);
    std::string lines = request.encode(IdsMethod::get_current_mode);
    request.set_api(codec::IdsApi::ids);
    lines += request.encode(IdsMethod::get_current_mode);
    return ProbeSpec{
        .transport_kind = "tcp",
        .default_port = 9090,
        .request = lines,
        .recognise = [lines](std::string_view received) {
          using V = ProbeSpec::Verdict;
          codec::IdsCodec c;
          c.note_requests(codec::as_bytes(lines));
          std::vector<codec::IdsResponse> frames;
          c.feed(received, frames);
          for (const auto& f : frames)
            if (!f.rpc_error)
              return ProbeSpec::Answer{
                  V::yes,
                  fmt::format("API {} (firmware {} 1.9.1), mode: {}", codec::to_string(f.api),
                              f.api == codec::IdsApi::sen ? ">=" : "<", f.mode)};
          if (frames.size() >= 2 || c.stats().errors() > 0)
            return ProbeSpec::Answer{V::no, "no IDS3010 JSON-RPC answer in either API generation"};
          return ProbeSpec::Answer{};
        }};
  }
  std::span<const LegacyKey> legacy_keys() const override {
    // Sessions recorded before the option tables spoke com.attocube.ids.
    static constexpr LegacyKey keys[] = {
        {"/ids_axes", "axes", LegacyKey::Form::bool_mask_to_indices},
        {"", "api", LegacyKey::Form::as_is, "ids"}};
    return keys;
  }
  std::string_view decode_input() const override {
    return "the JSON-RPC lines of both directions, as a TCP stream capture gives them (requests "
           "are known by their \"method\" member and match the answers' ids)";
  }
  std::unique_ptr<Instrument> make_instrument(boost::asio::io_context& io,
                                              std::unique_ptr<transport::Transport> t,
                                              InstrumentOptions instrument, const Options& o,
                                              const InstrumentContext&) const override {
    return make_ids3010(io, std::move(t), std::move(instrument), ids_options(o));
  }
  std::unique_ptr<Decoder> make_decoder(const Options&) const override {
    return std::make_unique<TranscriptDecoder>();
  }
  std::unique_ptr<sim::Twin> make_twin(boost::asio::io_context& io, sim::World& world,
                                       sim::Clock clock, const Options& o) const override {
    // auto: the newer generation (the instrument has to find it out).
    return std::make_unique<sim::IdsTwin>(
        io, world, std::move(clock),
        sim::IdsTwinConfig{.api =
                               o.text("api") == "ids" ? codec::IdsApi::ids : codec::IdsApi::sen});
  }
};

}  // namespace

const DeviceDriver& driver() {
  static const Driver d;
  return d;
}

}  // namespace cal::drivers::ids3010
