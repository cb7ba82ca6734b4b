// PCsensor TEMPer thermometers over USB-HID (codec: temper/codec.hpp; steps: instrument.hpp).
#include "temper/instrument.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "cal/drivers/loop_time.hpp"
#include "instrument_core.hpp"

namespace cal::drivers {
namespace {

std::string sensors_of(const codec::TemperModel& m) {
  std::vector<std::string_view> s;
  if (m.inner) s.push_back("0 (the stick)");
  if (m.probe) s.push_back("1 (the probe)");
  return fmt::format("{}{}", fmt::join(s, ", "), m.humidity ? ", and humidity" : "");
}

class Temper final : public detail::InstrumentCore {
 public:
  Temper(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t, InstrumentOptions o,
         TemperOptions temper)
      : InstrumentCore(io, std::move(t), std::move(o)),
        temper_(std::move(temper)),
        firmware_timer_(io) {}
  ~Temper() override { *alive_ = false; }
  const codec::CodecStats& codec_stats() const override { return codec_.stats(); }

 private:
  // The firmware string first (it names the model), then the sensor count (some firmwares
  // answer data requests only after it), then the sensors, polled.
  void on_connected() override {
    codec_ = codec::TemperCodec({.family = temper_.family.value_or(codec::TemperFamily::gold)});
    model_read_ = false;
    firmware_queries_ = 0;
    if (temper_.family) {  // the layout is known: the firmware is for the log, asked once
      send(codec::TemperCodec::model_command());
      return start_reading();
    }
    ask_firmware();
  }
  void on_disconnected() override { firmware_timer_.cancel(); }

  // A real TEMPer1F sometimes answers the firmware query with one report of the two, its second
  // half ("V3.3    ", urwen/temper #9 and PR #16's usbmon trace). The public readers ask again:
  // ccwienk/temper's _read_hidraw_firmware up to 10 times, each answer read until 0.2 s pass
  // without a report, while it has 8 bytes or fewer. So does this, then gives up naming what
  // came, instead of waiting for the silence watchdog with half a model string.
  void ask_firmware() {
    codec_.reset_model();  // a half answer is never joined to the next one
    ++firmware_queries_;
    send(codec::TemperCodec::model_command());
    firmware_timer_.expires_after(temper_.firmware_quiet);
    firmware_timer_.async_wait([this, alive = alive_](const boost::system::error_code& ec) {
      if (!ec && *alive && !model_read_ && state() != InstrumentState::closed) on_firmware_quiet();
    });
  }
  void on_firmware_quiet() {
    const std::string got = codec_.model();
    if (firmware_queries_ >= temper_.firmware_tries)
      return fail(
          fmt::format("TEMPer: no whole answer to the firmware query (01 86 ff 01) in {} "
                      "tries; the last: {}",
                      firmware_queries_, answer_of(got, codec_.model_reports())));
    report_message(
        {.severity = DeviceMessage::Severity::warning,
         .text = fmt::format("TEMPer firmware query {} of {}: {}; asking again", firmware_queries_,
                             temper_.firmware_tries, answer_of(got, codec_.model_reports()))});
    ask_firmware();
  }
  static std::string answer_of(const std::string& model, int reports) {
    if (reports == 0) return "no answer";
    return fmt::format("'{}' ({} report of the 2{})", model, reports,
                       model.starts_with("TEMPer") ? "" : ", the second half only");
  }
  // Replay: the recorded session's own firmware queries start the model string afresh.
  void on_sent(std::span<const std::byte> bytes) override {
    const auto query = codec::TemperCodec::model_command();
    if (bytes.size() >= 4 && static_cast<char>(bytes[2]) == query[2] &&
        static_cast<char>(bytes[3]) == query[3])
      codec_.reset_model();
  }
  void start_reading() {
    send(codec::TemperCodec::init_command());
    start_polling();
  }
  void on_poll() override { send(codec::TemperCodec::read_command()); }

  // Two reports of the firmware string have come: the model, and whether it can be read.
  void on_model() {
    model_read_ = true;
    firmware_timer_.cancel();
    const std::string firmware = codec_.model();
    const auto* model = codec::temper_model_of(firmware);
    if (!model && !temper_.family)
      return fail(fmt::format(
          "TEMPer firmware '{}' is not in the detection table (docs/drivers.md); if you know its "
          "report layout, set family = \"ds75\", \"gold\", \"temperx\", \"sht2x\", \"si7005\" or "
          "\"si7006\"",
          firmware));
    codec::TemperConfig config = codec_.config();
    if (model) {
      if (!temper_.family) config.family = model->family;
      config.inner = model->inner;
      config.probe = model->probe;
      config.ds75_slots = model->ds75_slots;
    }
    codec_.configure(config);
    report_message({.text = model ? fmt::format("firmware '{}': {} family, sensors {}", firmware,
                                                codec::to_string(config.family), sensors_of(*model))
                                  : fmt::format("firmware '{}': not in the detection table, read "
                                                "as the configured {} family",
                                                firmware, codec::to_string(config.family))});
    for (const auto c : temper_.channels)
      if (model && !(c == 0 ? model->inner : c == 1 ? model->probe : false))
        return fail(fmt::format("TEMPer '{}' has no channel {}; its sensors: {}", firmware, c,
                                sensors_of(*model)));
    if (!temper_.family) start_reading();
  }

  bool wanted(int channel) const {
    return temper_.channels.empty() || std::find(temper_.channels.begin(), temper_.channels.end(),
                                                 channel) != temper_.channels.end();
  }

  void on_bytes(std::span<const std::byte> bytes) override {
    decode(codec_, bytes, frames_);
    if (!model_read_ && codec_.model_reports() >= 2) on_model();
    const std::int64_t t = now_ns();
    for (const auto& f : frames_) {
      if (wanted(f.sensor))
        emit({.time_ns = t,
              .channel = static_cast<std::uint8_t>(f.sensor),
              .quantity = temper_.quantity,
              .value = f.temperature_degc});
      if (f.humidity_pct)
        emit({.time_ns = t, .quantity = Quantity::air_humidity_pct, .value = *f.humidity_pct});
    }
  }

  TemperOptions temper_;
  codec::TemperCodec codec_;
  bool model_read_ = false;
  int firmware_queries_ = 0;
  Timer firmware_timer_;  // the quiet time after a firmware query (ask_firmware)
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  std::vector<codec::TemperFrame> frames_;
};

}  // namespace

std::unique_ptr<Instrument> make_temper(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, TemperOptions temper) {
  return std::make_unique<Temper>(io, std::move(transport), std::move(options), std::move(temper));
}

}  // namespace cal::drivers
