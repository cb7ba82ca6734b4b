#pragma once
// Private to drivers/: the life cycle shared by every instrument (open, configure, stream,
// signal lost, reconnect with backoff and gap reporting, silence watchdog). Includes
// Boost.Asio, so only instrument .cpp files include it.
#include <boost/asio/io_context.hpp>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cal/drivers/instrument.hpp"

namespace cal::drivers::detail {

// The silence watchdog's decision when its timer fires: nullopt when the device has been
// silent for `timeout` or longer (the connection is lost), else how long to wait before the
// next check: the time remaining until `timeout` of silence, so that a lost connection is
// seen at `timeout`, not up to twice that (a silence shorter than zero, a clock stepped back,
// waits the whole timeout).
std::optional<std::chrono::nanoseconds> silence_wait(std::chrono::nanoseconds timeout,
                                                     std::chrono::nanoseconds silent);

class InstrumentCore : public Instrument {
 public:
  InstrumentCore(boost::asio::io_context& io, std::unique_ptr<transport::Transport> transport,
                 InstrumentOptions options);
  ~InstrumentCore() override;

  void start(InstrumentEvents events) final;
  void stop() final;
  InstrumentState state() const final { return state_; }
  std::string describe() const override;

 protected:
  // Device steps. on_connected: the transport is open; send the set-up (state is
  // configuring). on_bytes: bytes from the device. on_poll: the poll timer fired (only while
  // polling is on). on_disconnected: forget in-flight requests.
  virtual void on_connected() = 0;
  virtual void on_bytes(std::span<const std::byte> bytes) = 0;
  virtual void on_poll() {}
  virtual void on_disconnected() {}
  // Replay only: bytes the instrument sent in the recorded session (see Handlers::sent).
  virtual void on_sent(std::span<const std::byte> /*bytes*/) {}

  void send(std::string_view text);
  void emit(Reading r);
  // The readings decoded from one chunk of bytes, in order: one events.readings call when the
  // consumer takes batches, else emit() each. Sets their device.
  void emit_all(std::span<Reading> readings);
  void set_state(InstrumentState s, std::string_view why = {});
  // Ends the connection and schedules a reconnection (reason recorded in the gap).
  void fail(const std::string& reason);
  // A period without readings while connected (samples the device says it lost), reported at
  // once; `start_ns` may equal `end_ns` when the device does not say how long.
  void report_gap(const Gap& gap);
  // What the device said that is not a reading: a warning or an error with its own text.
  void report_message(const DeviceMessage& message);
  void start_polling();
  // The poll period from now on (the device said how often it wants to be asked).
  void set_poll_period(std::chrono::microseconds period) { poll_period_ = period; }
  // How long a connected device may be silent before the connection counts as lost; nullopt:
  // never (a feed that sends only on change is silent while nothing changes). Re-arms the
  // watchdog from now.
  void set_silence_timeout(std::optional<std::chrono::milliseconds> timeout);
  void report_codec_errors(std::span<const codec::CodecError> errors);
  // Feeds the bytes to the codec: `frames` holds the frames they completed (cleared first), and
  // each codec error is reported through the events.
  template <class Codec>
  void decode(Codec& codec, std::span<const std::byte> bytes,
              std::vector<typename Codec::Frame>& frames) {
    frames.clear();
    codec_errors_.clear();
    codec.feed(bytes, frames, codec_errors_);
    report_codec_errors(codec_errors_);
  }
  // The time of the event being handled: inside a data handler the arrival time of the bytes
  // (one value for the whole chunk, the one recorded), else the clock.
  std::int64_t now_ns() const { return latched_ns_ ? *latched_ns_ : clock_(); }
  std::int64_t last_sent_ns() const { return last_sent_ns_; }
  bool replaying() const { return options_.replay; }
  const InstrumentOptions& options() const { return options_; }
  boost::asio::io_context& io() { return io_; }

 private:
  void connect();
  void schedule_reconnect();
  // Arms the silence watchdog to check again after `after` (the whole timeout by default).
  void arm_watchdog(std::optional<std::chrono::nanoseconds> after = std::nullopt);
  void poll_tick();

  boost::asio::io_context& io_;
  std::unique_ptr<transport::Transport> transport_;
  InstrumentOptions options_;
  Clock clock_;
  InstrumentEvents events_;
  InstrumentState state_ = InstrumentState::closed;
  Timer reconnect_timer_, poll_timer_, watchdog_;  // on the loop's time (loop_time.hpp)
  std::chrono::milliseconds next_delay_{};
  int attempts_ = 0;
  bool running_ = false;
  bool polling_ = false;
  std::int64_t last_bytes_ns_ = 0;
  std::chrono::microseconds poll_period_;
  std::optional<std::chrono::milliseconds> silence_timeout_;
  std::optional<Gap> gap_;  // open while the connection is down
  std::optional<std::int64_t> latched_ns_;
  std::vector<codec::CodecError> codec_errors_;
  std::int64_t last_sent_ns_ = 0;
  // The gap and state bookkeeping of one reading (before it is handed over).
  void note_reading(const Reading& r);
  void record_event(std::string_view text);
  void on_opened();
  void on_data(std::span<const std::byte> bytes);
  void on_replayed_sent(std::span<const std::byte> bytes);
  // Shared with the timers' handlers: a handler that runs after destruction does nothing.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace cal::drivers::detail
