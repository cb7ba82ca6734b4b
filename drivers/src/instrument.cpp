// The common instrument life cycle (see instrument_core.hpp).
#include <fmt/format.h>

#include <algorithm>

#include "cal/analysis/enum_names.hpp"
#include "instrument_core.hpp"

namespace cal::drivers {

std::string_view to_string(Quantity q) {
  using enum Quantity;
  static constexpr EnumName<Quantity> kNames[] = {
      {displacement_m, "displacement_m"},
      {length_m, "length_m"},
      {air_temperature_degc, "air_temperature_degc"},
      {air_pressure_pa, "air_pressure_pa"},
      {air_humidity_pct, "air_humidity_pct"},
      {dew_point_degc, "dew_point_degc"},
      {refractive_index, "refractive_index"},
      {material_temperature_degc, "material_temperature_degc"},
      {machine_position_m, "machine_position_m"},
      {angle_rad, "angle_rad"}};
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, q, "unknown");
}

std::string_view to_string(ReadingStatus s) {
  using enum ReadingStatus;
  static constexpr EnumName<ReadingStatus> kNames[] = {
      {ok, "ok"}, {signal_lost, "signal_lost"}, {out_of_range, "out_of_range"}};
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, s, "unknown");
}

constexpr EnumName<InstrumentState> kInstrumentStateNames[] = {
    {InstrumentState::closed, "closed"},           {InstrumentState::connecting, "connecting"},
    {InstrumentState::configuring, "configuring"}, {InstrumentState::streaming, "streaming"},
    {InstrumentState::signal_lost, "signal lost"}, {InstrumentState::reconnecting, "reconnecting"}};
static_assert(cal::names_every_value(kInstrumentStateNames));

std::string_view to_string(InstrumentState s) {
  return name_of(kInstrumentStateNames, s, "unknown");
}

constexpr EnumName<DeviceMessage::Severity> kSeverityNames[] = {
    {DeviceMessage::Severity::info, "info"},
    {DeviceMessage::Severity::warning, "warning"},
    {DeviceMessage::Severity::error, "error"}};
static_assert(cal::names_every_value(kSeverityNames));

std::string_view to_string(DeviceMessage::Severity s) {
  return name_of(kSeverityNames, s, "unknown");
}

namespace detail {

InstrumentCore::InstrumentCore(boost::asio::io_context& io,
                               std::unique_ptr<transport::Transport> transport,
                               InstrumentOptions options)
    : io_(io),
      transport_(std::move(transport)),
      options_(std::move(options)),
      clock_(options_.clock ? options_.clock : loop_clock(io)),
      reconnect_timer_(io),
      poll_timer_(io),
      watchdog_(io),
      next_delay_(options_.backoff.initial),
      poll_period_(options_.poll_period),
      silence_timeout_(options_.silence_timeout) {}

InstrumentCore::~InstrumentCore() {
  *alive_ = false;
  running_ = false;
  transport_->close();
}

std::string InstrumentCore::describe() const {
  return options_.name.empty() ? transport_->describe()
                               : options_.name + " (" + transport_->describe() + ")";
}

void InstrumentCore::start(InstrumentEvents events) {
  events_ = std::move(events);
  running_ = true;
  attempts_ = 0;
  next_delay_ = options_.backoff.initial;
  connect();
}

void InstrumentCore::stop() {
  if (!running_) return;
  running_ = false;
  polling_ = false;
  reconnect_timer_.cancel();
  poll_timer_.cancel();
  watchdog_.cancel();
  transport_->close();
  on_disconnected();
  record_event("closed");
  if (gap_ && events_.gap) {  // a gap still open at the end is reported, not dropped
    gap_->end_ns = now_ns();
    events_.gap(*gap_);
  }
  gap_.reset();
  set_state(InstrumentState::closed, "stopped");
}

void InstrumentCore::connect() {
  set_state(InstrumentState::connecting);
  ++attempts_;
  // Each handler only forwards to a member function: a transport may destroy its handlers
  // while one runs (closing from inside a data handler), so nothing may touch the lambda's
  // captures after the call.
  transport::Transport::Handlers handlers;
  handlers.opened = [this, alive = alive_] {
    if (*alive && running_) on_opened();
  };
  handlers.data = [this, alive = alive_](std::span<const std::byte> bytes) {
    if (*alive && running_) on_data(bytes);
  };
  handlers.sent = [this, alive = alive_](std::span<const std::byte> bytes) {
    if (*alive && running_) on_replayed_sent(bytes);
  };
  handlers.error = [this, alive = alive_](const transport::Error& e) {
    if (*alive && running_) fail(e.message);
  };
  transport_->open(std::move(handlers));
}

void InstrumentCore::on_opened() {
  record_event("opened");
  set_state(InstrumentState::configuring);
  last_bytes_ns_ = now_ns();
  // Each connection starts from the configured period and watchdog (a device may change them).
  poll_period_ = options_.poll_period;
  silence_timeout_ = options_.silence_timeout;
  arm_watchdog();
  on_connected();
}

void InstrumentCore::on_data(std::span<const std::byte> bytes) {
  latched_ns_ = clock_();
  last_bytes_ns_ = *latched_ns_;
  if (options_.recorder) options_.recorder->received(options_.device, *latched_ns_, bytes);
  on_bytes(bytes);
  latched_ns_.reset();
}

void InstrumentCore::on_replayed_sent(std::span<const std::byte> bytes) {
  latched_ns_ = clock_();
  last_sent_ns_ = *latched_ns_;
  on_sent(bytes);
  latched_ns_.reset();
}

void InstrumentCore::record_event(std::string_view text) {
  if (options_.recorder) options_.recorder->event(options_.device, now_ns(), text);
}

void InstrumentCore::fail(const std::string& reason) {
  if (!running_) return;
  record_event("error: " + reason);
  polling_ = false;
  poll_timer_.cancel();
  watchdog_.cancel();
  transport_->close();
  on_disconnected();
  if (!gap_) gap_ = Gap{now_ns(), 0, reason};
  if (options_.backoff.max_attempts >= 0 && attempts_ >= options_.backoff.max_attempts) {
    running_ = false;
    if (events_.gap) {
      gap_->end_ns = now_ns();
      events_.gap(*gap_);
    }
    gap_.reset();
    return set_state(InstrumentState::closed,
                     fmt::format("gave up after {} attempts: {}", attempts_, reason));
  }
  set_state(InstrumentState::reconnecting, reason);
  if (options_.replay) return connect();  // the recording says when it reopened
  schedule_reconnect();
}

void InstrumentCore::schedule_reconnect() {
  reconnect_timer_.expires_after(next_delay_);
  next_delay_ = std::min(options_.backoff.max,
                         std::chrono::milliseconds(static_cast<std::int64_t>(
                             static_cast<double>(next_delay_.count()) * options_.backoff.factor)));
  reconnect_timer_.async_wait([this, alive = alive_](const boost::system::error_code& ec) {
    if (!ec && *alive && running_) connect();
  });
}

// A silent device is a dropped connection (a TCP peer that vanished without a FIN, a serial
// adapter whose instrument was switched off): without this, the gap would never be seen.
void InstrumentCore::arm_watchdog(std::optional<std::chrono::nanoseconds> after) {
  if (options_.replay || !silence_timeout_) return;
  const auto timeout = *silence_timeout_;
  watchdog_.expires_after(after.value_or(timeout));
  watchdog_.async_wait([this, alive = alive_, timeout](const boost::system::error_code& ec) {
    if (ec || !*alive || !running_) return;
    const auto wait = silence_wait(timeout, std::chrono::nanoseconds(now_ns() - last_bytes_ns_));
    if (!wait) return fail(fmt::format("no data for {} ms", timeout.count()));
    arm_watchdog(*wait);  // the time remaining, not a whole timeout more
  });
}

std::optional<std::chrono::nanoseconds> silence_wait(std::chrono::nanoseconds timeout,
                                                     std::chrono::nanoseconds silent) {
  if (silent >= timeout) return std::nullopt;
  if (silent < std::chrono::nanoseconds::zero()) return timeout;
  return timeout - silent;
}

void InstrumentCore::set_silence_timeout(std::optional<std::chrono::milliseconds> timeout) {
  silence_timeout_ = timeout;
  watchdog_.cancel();
  if (running_) arm_watchdog();
}

void InstrumentCore::send(std::string_view text) {
  if (options_.replay) return;
  const auto bytes = std::as_bytes(std::span(text.data(), text.size()));
  last_sent_ns_ = now_ns();
  if (options_.recorder) options_.recorder->sent(options_.device, last_sent_ns_, bytes);
  transport_->write(bytes);
}

void InstrumentCore::note_reading(const Reading& r) {
  if (gap_) {  // the first reading after a reconnection closes the gap
    gap_->end_ns = r.time_ns;
    if (events_.gap) events_.gap(*gap_);
    gap_.reset();
    attempts_ = 0;
    next_delay_ = options_.backoff.initial;
  }
  if (r.status == ReadingStatus::signal_lost) {
    if (state_ != InstrumentState::signal_lost) set_state(InstrumentState::signal_lost);
  } else if (state_ != InstrumentState::streaming) {
    set_state(InstrumentState::streaming);
  }
}

void InstrumentCore::emit(Reading r) {
  r.device = options_.device;
  note_reading(r);
  if (events_.reading) events_.reading(r);
}

void InstrumentCore::emit_all(std::span<Reading> readings) {
  if (readings.empty()) return;
  if (!events_.readings) {
    for (const auto& r : readings) emit(r);
    return;
  }
  for (auto& r : readings) {
    r.device = options_.device;
    // note_reading() has nothing to do for an ok reading while streaming without a gap open:
    // skip the call for each reading of a 10 kHz stream.
    if (gap_ || r.status != ReadingStatus::ok || state_ != InstrumentState::streaming)
      note_reading(r);
  }
  events_.readings(readings);
}

void InstrumentCore::set_state(InstrumentState s, std::string_view why) {
  state_ = s;
  if (events_.state) events_.state(s, why);
}

void InstrumentCore::start_polling() {
  if (polling_ || options_.replay) return;
  polling_ = true;
  poll_tick();
}

void InstrumentCore::poll_tick() {
  if (!polling_ || !running_) return;
  on_poll();
  poll_timer_.expires_after(poll_period_);
  poll_timer_.async_wait([this, alive = alive_](const boost::system::error_code& ec) {
    if (!ec && *alive) poll_tick();
  });
}

void InstrumentCore::report_gap(const Gap& gap) {
  record_event("gap: " + gap.reason);
  if (events_.gap) events_.gap(gap);
}

void InstrumentCore::report_message(const DeviceMessage& message) {
  record_event(fmt::format("{}{}: {}", to_string(message.severity),
                           message.code ? fmt::format(" {}", message.code) : "", message.text));
  if (events_.message) events_.message(message);
}

void InstrumentCore::report_codec_errors(std::span<const codec::CodecError> errors) {
  if (!events_.codec_error) return;
  for (const auto& e : errors) events_.codec_error(e);
}

}  // namespace detail
}  // namespace cal::drivers
