#pragma once
// Recording and replaying whole sessions through the real instruments.
//
// CaptureRecorder: the instruments' WireRecorder writing into a capture file (thread: the
// event loop's; flushed on a timer by its owner, and on close). It never throws into the
// instruments (their stop() runs in destructors): the first write error (a full disk) is kept,
// reported once through on_failure, and every later record is dropped, as the writer would
// refuse it anyway; what was flushed before stays readable.
//
// ReplayBus: reads a capture and plays it into replay transports, one per recorded device, on
// the io_context: received bytes to the instrument's data handler, sent bytes to its `sent`
// handler, "opened"/"error: ..." events as the transport's opened/error. The bus's clock is the
// recorded time of the record being delivered, so instruments built with
// InstrumentOptions{.clock = bus.clock(), .replay = true} produce exactly the readings of the
// recorded session. As fast as possible (speed 0) or paced (speed > 0, by the wall clock).
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "cal/drivers/instrument.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "cal/replay/capture.hpp"

namespace cal::replay {

class CaptureRecorder final : public drivers::WireRecorder {
 public:
  explicit CaptureRecorder(CaptureWriter& writer,
                           std::function<void(const std::string&)> on_failure = {})
      : writer_(writer), on_failure_(std::move(on_failure)) {}
  void received(std::uint16_t device, std::int64_t t, std::span<const std::byte> b) override {
    guarded([&] { writer_.record(t, device, RecordKind::received, b); });
  }
  void sent(std::uint16_t device, std::int64_t t, std::span<const std::byte> b) override {
    guarded([&] { writer_.record(t, device, RecordKind::sent, b); });
  }
  void event(std::uint16_t device, std::int64_t t, std::string_view text) override {
    guarded([&] { writer_.event(t, device, text); });
  }
  // The owner's periodic flush and the final close, with the same error handling.
  void flush() {
    guarded([&] { writer_.flush(); });
  }
  void close() {
    guarded([&] { writer_.close(); });
  }
  void on_failure(std::function<void(const std::string&)> f) { on_failure_ = std::move(f); }
  // The first write error (the writer's message: file, byte offset, errno text), if any.
  const std::optional<std::string>& failure() const { return failure_; }

 private:
  template <class F>
  void guarded(F&& f) noexcept {
    if (failure_) return;
    try {
      f();
    } catch (const std::exception& e) {
      failure_ = e.what();
      if (on_failure_) {
        try {
          on_failure_(*failure_);
        } catch (...) {  // the owner's handler must not throw into an instrument either
        }
      }
    }
  }
  CaptureWriter& writer_;
  std::function<void(const std::string&)> on_failure_;
  std::optional<std::string> failure_;
};

struct ReplayEnd {
  std::uint64_t records = 0;
  std::optional<Damage> damage;  // the capture was damaged or not closed: where
};

class ReplayBus {
 public:
  // Throws CaptureError (file named) if the capture cannot be opened.
  ReplayBus(boost::asio::io_context& io, const std::filesystem::path& capture, double speed = 0.0);
  ~ReplayBus();
  ReplayBus(const ReplayBus&) = delete;
  ReplayBus& operator=(const ReplayBus&) = delete;

  const std::string& header_json() const;
  // The transport of a recorded device (create them all before start()).
  std::unique_ptr<drivers::transport::Transport> transport(std::uint16_t device,
                                                           std::string description);
  drivers::Clock clock() const;
  // Plays the capture; `done` is called on the loop after the last record.
  void start(std::function<void(const ReplayEnd&)> done);
  // Reads what is left of the capture without delivering it and says how it ends: after a
  // run that ended before the capture did, damage further on is still found and reported.
  ReplayEnd read_to_end();

  struct Impl;  // implementation, shared with the replay transports (session.cpp)

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::replay
