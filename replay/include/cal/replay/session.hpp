#pragma once
// Recording and replaying whole sessions through the real instruments.
//
// CaptureRecorder: the instruments' WireRecorder writing into a capture file (thread: the
// event loop's; flushed on a timer by its owner, and on close).
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
  explicit CaptureRecorder(CaptureWriter& writer) : writer_(writer) {}
  void received(std::uint16_t device, std::int64_t t, std::span<const std::byte> b) override {
    writer_.record(t, device, RecordKind::received, b);
  }
  void sent(std::uint16_t device, std::int64_t t, std::span<const std::byte> b) override {
    writer_.record(t, device, RecordKind::sent, b);
  }
  void event(std::uint16_t device, std::int64_t t, std::string_view text) override {
    writer_.event(t, device, text);
  }

 private:
  CaptureWriter& writer_;
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

  struct Impl;  // implementation, shared with the replay transports (session.cpp)

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::replay
