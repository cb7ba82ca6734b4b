// Attocube IDS3010 over JSON-RPC (codec: codec/attocube_ids.hpp).
#include "ids3010/instrument.hpp"

#include <array>
#include <vector>

#include "ids3010/codec.hpp"
#include "instrument_core.hpp"

namespace cal::drivers {
namespace {

using codec::IdsMethod;

class Ids3010 final : public detail::InstrumentCore {
 public:
  Ids3010(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t, InstrumentOptions o,
          Ids3010Options ids)
      : InstrumentCore(io, std::move(t), std::move(o)), ids_(ids) {}

  const codec::CodecStats& codec_stats() const override { return codec_.stats(); }

 private:
  void on_connected() override {
    codec_ = codec::IdsCodec{};
    in_flight_ = false;
    running_ = false;
    if (ids_.start_measurement) request(IdsMethod::start_measurement);
    start_polling();
  }

  void on_disconnected() override { in_flight_ = false; }

  void on_poll() override {
    if (in_flight_) return;  // one request at a time: answers arrive in order
    if (!running_) return request(IdsMethod::get_current_mode);
    if (ids_.read_environment && now_ns() >= next_environment_ns_) {
      request(environment_[environment_index_]);
      if (++environment_index_ == environment_.size()) {
        environment_index_ = 0;
        next_environment_ns_ = now_ns() + std::chrono::nanoseconds(ids_.environment_period).count();
      }
      return;
    }
    request(IdsMethod::get_axes_displacement);
  }

  void request(IdsMethod method) {
    if (replaying()) return;  // the recorded requests arrive through on_sent
    in_flight_ = true;
    send(codec_.encode(method));
    sent_ns_ = last_sent_ns();
  }

  void on_sent(std::span<const std::byte> bytes) override {
    codec_.note_requests(bytes);
    sent_ns_ = last_sent_ns();
  }

  void on_bytes(std::span<const std::byte> bytes) override {
    decode(codec_, bytes, frames_);
    for (const auto& r : frames_) handle(r);
  }

  void handle(const codec::IdsResponse& r) {
    in_flight_ = false;
    const std::int64_t t = sent_ns_ + (now_ns() - sent_ns_) / 2;
    switch (r.method) {
      case IdsMethod::get_current_mode:
        running_ = r.error_code == 0 && r.mode == "measurement running";
        if (!running_ && ids_.start_measurement && r.mode == "system idle")
          request(IdsMethod::start_measurement);
        return;
      case IdsMethod::get_axes_displacement:
        return displacement(r, t);
      case IdsMethod::ecu_get_temperature:
        return air(r.temperature_degc, Quantity::air_temperature_degc, t);
      case IdsMethod::ecu_get_pressure:
        return air(r.pressure_pa, Quantity::air_pressure_pa, t);
      case IdsMethod::ecu_get_humidity:
        return air(r.humidity_pct_rh, Quantity::air_humidity_pct, t);
      case IdsMethod::ecu_get_refractive_index:
        return air(r.refractive_index, Quantity::refractive_index, t);
      default:
        return;
    }
  }

  void displacement(const codec::IdsResponse& r, std::int64_t t) {
    const auto status = r.error_code == 0 ? ReadingStatus::ok : ReadingStatus::signal_lost;
    // A non-zero code may also mean the measurement stopped (someone pressed the button):
    // ask for the mode again before the next displacement.
    if (r.error_code != 0) running_ = false;
    for (std::uint8_t a = 0; a < 3; ++a) {
      if (!ids_.axes[a]) continue;
      const auto& v = r.displacement_m[a];
      emit({.time_ns = t,
            .channel = a,
            .quantity = Quantity::displacement_m,
            .status = v ? status : ReadingStatus::out_of_range,
            .value = v.value_or(0.0)});
    }
  }

  void air(const std::optional<double>& v, Quantity q, std::int64_t t) {
    if (v) emit({.time_ns = t, .quantity = q, .value = *v});
  }

  Ids3010Options ids_;
  codec::IdsCodec codec_;
  std::vector<codec::IdsResponse> frames_;
  bool in_flight_ = false;
  bool running_ = false;
  std::int64_t sent_ns_ = 0;
  std::int64_t next_environment_ns_ = 0;
  std::size_t environment_index_ = 0;
  static constexpr std::array<IdsMethod, 4> environment_{
      IdsMethod::ecu_get_temperature, IdsMethod::ecu_get_pressure, IdsMethod::ecu_get_humidity,
      IdsMethod::ecu_get_refractive_index};
};

}  // namespace

std::unique_ptr<Instrument> make_ids3010(boost::asio::io_context& io,
                                         std::unique_ptr<transport::Transport> transport,
                                         InstrumentOptions options, Ids3010Options ids) {
  return std::make_unique<Ids3010>(io, std::move(transport), std::move(options), ids);
}

}  // namespace cal::drivers
