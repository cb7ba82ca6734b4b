// Attocube IDS3010 over JSON-RPC (codec: ids3010/codec.hpp; the steps: instrument.hpp).
#include "ids3010/instrument.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <deque>
#include <map>
#include <optional>
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
    detected_ = false;
    ecu_ready_ = false;
    start_refusals_ = 0;
    lookups_.clear();
    last_code_.clear();
    failing_.reset();
    if (ids_.api == IdsApiChoice::automatic) {
      codec_.set_api(codec::IdsApi::sen);  // the newer first; an old firmware answers -32601
      request(IdsMethod::get_current_mode);
    } else {
      codec_.set_api(ids_.api == IdsApiChoice::sen ? codec::IdsApi::sen : codec::IdsApi::ids);
      detected(false);
    }
    start_polling();
  }

  void on_disconnected() override { in_flight_ = false; }

  // The generation is known: enable the ECU (if read), then start the measurement.
  void detected(bool found_out) {
    detected_ = true;
    if (found_out)
      report_message(
          {.text = fmt::format("API {} (firmware {} 1.9.1)", codec::to_string(codec_.api()),
                               codec_.api() == codec::IdsApi::sen ? ">=" : "<")});
    if (ids_.read_environment) return request(IdsMethod::ecu_enable);
    ecu_ready_ = false;
    if (ids_.start_measurement) request(IdsMethod::start_measurement);
  }

  void on_poll() override {
    if (failing_ && now_ns() >= failing_->deadline_ns)  // the text did not come: the number
      return fail(fmt::format("{} (error {}; the device gave no text for it)", failing_->what,
                              failing_->code));
    if (in_flight_ || !detected_) return;  // one request at a time: answers arrive in order
    if (!lookups_.empty()) {               // the device's text for a number it reported
      const codec::IdsParam params[] = {std::int64_t{1}, lookups_.front()};
      lookups_.pop_front();
      return request(IdsMethod::error_number_to_string, params);
    }
    if (failing_) return;  // nothing else while the device explains why it refused
    if (!running_) return request(IdsMethod::get_current_mode);
    if (ecu_ready_ && now_ns() >= next_environment_ns_) {
      request(environment_[environment_index_]);
      if (++environment_index_ == environment_.size()) {
        environment_index_ = 0;
        next_environment_ns_ = now_ns() + std::chrono::nanoseconds(ids_.environment_period).count();
      }
      return;
    }
    request(IdsMethod::get_axes_displacement);
  }

  void request(IdsMethod method, std::span<const codec::IdsParam> params = {}) {
    if (replaying()) return;  // the recorded requests arrive through on_sent
    in_flight_ = true;
    send(codec_.encode(method, params));
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
    if (r.method == IdsMethod::get_current_mode && !detected_) return detection(r);
    if (r.method == IdsMethod::error_number_to_string) return explained(r);
    if (r.error_code != 0) device_code(r);
    switch (r.method) {
      case IdsMethod::get_current_mode:
        running_ = r.error_code == 0 && r.mode == "measurement running";
        if (!running_ && ids_.start_measurement && r.mode == "system idle")
          request(IdsMethod::start_measurement);
        return;
      case IdsMethod::ecu_enable:
        ecu_ready_ = r.error_code == 0;
        if (!ecu_ready_)
          return fail_with_text(r, "ECU interface not enabled (com.attocube.ecu.enable)");
        if (ids_.start_measurement) request(IdsMethod::start_measurement);
        return;
      case IdsMethod::start_measurement:
        if (r.error_code != 0 && ++start_refusals_ >= 3)
          return fail_with_text(r,
                                fmt::format("startMeasurement refused {} times", start_refusals_));
        return;
      case IdsMethod::get_axes_displacement:
        return displacement(r, t);
      case IdsMethod::ecu_get_temperature:
        return air(r, r.temperature_degc, Quantity::air_temperature_degc, t);
      case IdsMethod::ecu_get_pressure:
        return air(r, r.pressure_pa, Quantity::air_pressure_pa, t);
      case IdsMethod::ecu_get_humidity:
        return air(r, r.humidity_pct_rh, Quantity::air_humidity_pct, t);
      case IdsMethod::ecu_get_refractive_index:
        return air(r, r.refractive_index, Quantity::refractive_index, t);
      default:
        return;
    }
  }

  // getCurrentMode in a generation not yet known: a JSON-RPC error says "not this one".
  void detection(const codec::IdsResponse& r) {
    if (!r.rpc_error) {
      detected(true);
      running_ = r.error_code == 0 && r.mode == "measurement running";
      return;
    }
    if (replaying()) return;  // the recorded session tried the other generation next
    if (r.api == codec::IdsApi::sen) {
      codec_.set_api(codec::IdsApi::ids);
      return request(IdsMethod::get_current_mode);
    }
    fail(fmt::format("neither com.attocube.sen nor com.attocube.ids answers getCurrentMode ({})",
                     describe_code(r)));
  }

  // A non-zero result[0] or a JSON-RPC error: said once per new number (its text asked of the
  // device), a warning for the displacement getters, an error otherwise.
  void device_code(const codec::IdsResponse& r) {
    const bool warning = codec::returns_warning(r.method) && !r.rpc_error;
    auto& last = last_code_[warning];
    if (last == r.error_code) return;
    last = r.error_code;
    const auto severity =
        warning ? DeviceMessage::Severity::warning : DeviceMessage::Severity::error;
    const std::string where = codec::method_name(r.method, r.api);
    if (r.rpc_error)  // the JSON-RPC error carries its own text
      return report_message(
          {severity, r.error_code, fmt::format("{}: {}", where, r.error_message)});
    if (const auto known = texts_.find(r.error_code); known != texts_.end())
      return report_message({severity, r.error_code, fmt::format("{}: {}", where, known->second)});
    pending_[r.error_code] = {severity, where};
    if (std::find(lookups_.begin(), lookups_.end(), r.error_code) == lookups_.end())
      lookups_.push_back(r.error_code);
  }

  // Ends the connection for a refusal, saying the device's number and its own text: a
  // JSON-RPC error carries its text; a result[0] number's text is asked of the device first
  // (errorNumberToString), waiting at most kTextWait before failing with the number alone.
  void fail_with_text(const codec::IdsResponse& r, std::string what) {
    if (r.rpc_error)
      return fail(fmt::format("{} (JSON-RPC error {}: {})", what, r.error_code, r.error_message));
    if (const auto known = texts_.find(r.error_code); known != texts_.end())
      return fail(fmt::format("{} (error {}: {})", what, r.error_code, known->second));
    if (replaying()) return fail(fmt::format("{} (error {})", what, r.error_code));
    failing_ = Failing{r.error_code, std::move(what),
                       now_ns() + std::chrono::nanoseconds(kTextWait).count()};
    if (std::find(lookups_.begin(), lookups_.end(), r.error_code) == lookups_.end())
      lookups_.push_back(r.error_code);
  }

  // The device's text for a number (errorNumberToString [language 1, number]).
  void explained(const codec::IdsResponse& r) {
    if (r.params.size() < 2) return;
    const std::int64_t code = r.params[1];
    const std::string text =
        r.error_code == 0 && !r.text.empty()
            ? r.text
            : fmt::format("(no text: errorNumberToString answered {})", describe_code(r));
    if (r.error_code == 0) texts_[code] = text;
    if (failing_ && failing_->code == code) {  // the refusal that ends the connection
      const std::string reason = fmt::format("{} (error {}: {})", failing_->what, code, text);
      if (const auto it = pending_.find(code); it != pending_.end()) {
        report_message({it->second.first, code, fmt::format("{}: {}", it->second.second, text)});
        pending_.erase(it);
      }
      return fail(reason);
    }
    const auto it = pending_.find(code);
    if (it == pending_.end()) return;
    report_message({it->second.first, code, fmt::format("{}: {}", it->second.second, text)});
    pending_.erase(it);
  }

  static std::string describe_code(const codec::IdsResponse& r) {
    if (r.rpc_error) return fmt::format("JSON-RPC error {}: {}", r.error_code, r.error_message);
    return fmt::format("code {}", r.error_code);
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

  // An ECU value answered with a non-zero error number (result[0], attocube's errNo) is not a
  // measurement: no reading; the number and its text are reported (device_code).
  void air(const codec::IdsResponse& r, const std::optional<double>& v, Quantity q,
           std::int64_t t) {
    if (v && r.error_code == 0) emit({.time_ns = t, .quantity = q, .value = *v});
  }

  Ids3010Options ids_;
  codec::IdsCodec codec_;
  std::vector<codec::IdsResponse> frames_;
  bool in_flight_ = false;
  bool running_ = false;
  bool detected_ = false;
  bool ecu_ready_ = false;
  int start_refusals_ = 0;
  std::int64_t sent_ns_ = 0;
  std::int64_t next_environment_ns_ = 0;
  std::size_t environment_index_ = 0;
  std::map<bool, std::int64_t> last_code_;     // the last number reported, warnings and errors
  std::map<std::int64_t, std::string> texts_;  // the device's texts of numbers, once asked
  std::map<std::int64_t, std::pair<DeviceMessage::Severity, std::string>> pending_;
  std::deque<std::int64_t> lookups_;
  struct Failing {
    std::int64_t code;
    std::string what;
    std::int64_t deadline_ns;
  };
  std::optional<Failing> failing_;  // a refusal waiting for the device's text
  static constexpr std::chrono::seconds kTextWait{2};
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
