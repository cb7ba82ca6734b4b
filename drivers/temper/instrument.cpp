// PCsensor TEMPer thermometers over USB-HID (codec: codec/temper.hpp).
#include "temper/instrument.hpp"

#include "instrument_core.hpp"

namespace cal::drivers {
namespace {

class Temper final : public detail::InstrumentCore {
 public:
  Temper(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t, InstrumentOptions o,
         TemperOptions temper)
      : InstrumentCore(io, std::move(t), std::move(o)),
        temper_(temper),
        codec_({.family = temper.family}) {}
  const codec::CodecStats& codec_stats() const override { return codec_.stats(); }

 private:
  // Asks for the sensor count once (some firmwares answer data requests only after it),
  // then polls the sensors.
  void on_connected() override {
    codec_ = codec::TemperCodec({.family = temper_.family});
    send(codec::TemperCodec::init_command());
    start_polling();
  }
  void on_poll() override { send(codec::TemperCodec::read_command()); }
  void on_bytes(std::span<const std::byte> bytes) override {
    decode(codec_, bytes, frames_);
    const std::int64_t t = now_ns();
    for (const auto& f : frames_) {
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
  std::vector<codec::TemperFrame> frames_;
};

}  // namespace

std::unique_ptr<Instrument> make_temper(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, TemperOptions temper) {
  return std::make_unique<Temper>(io, std::move(transport), std::move(options), temper);
}

}  // namespace cal::drivers
