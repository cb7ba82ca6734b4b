#pragma once
// Instruments: a transport plus a codec plus the device's state machine, emitting typed,
// timestamped readings in SI units (see ../shared/DESIGN.md). The common part here owns the
// life cycle: open, configure, stream or poll, signal lost, error, reconnect with backoff
// (the gap is reported, never hidden), closed. Each device adds only its protocol steps.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/drivers/transport/transport.hpp"

namespace cal::drivers {

enum class Quantity : std::uint8_t {
  displacement_m,  // interferometer axis, raw (vacuum-wavelength) optical length
  length_m,        // gauge / ballbar transducer reading
  air_temperature_degc,
  air_pressure_pa,
  air_humidity_pct,  // relative humidity, %RH
  dew_point_degc,
  refractive_index,  // as computed by the instrument (e.g. the IDS ECU)
  material_temperature_degc,
  machine_position_m,  // a machine position feed (actual or commanded)
  angle_rad,           // an angular measurement (e.g. an imported angular laser capture)
};
std::string_view to_string(Quantity q);

enum class ReadingStatus : std::uint8_t {
  ok,
  signal_lost,   // beam interrupted / weak signal: the value is not a measurement
  out_of_range,  // the device flagged the value
};
// "ok", "signal_lost", "out_of_range": the words of `daq decode --json` and the Python package.
std::string_view to_string(ReadingStatus s);

struct Reading {
  std::int64_t time_ns = 0;  // monotonic, from the instrument's clock (see Instrument::Clock)
  std::uint16_t device = 0;  // the instrument's id in the session
  std::uint8_t channel = 0;  // axis or sensor number on the device
  Quantity quantity = Quantity::displacement_m;
  ReadingStatus status = ReadingStatus::ok;
  // When the value was measured is known only to within [time_ns, time_ns + this]: a polled
  // device's answer came this many milliseconds (rounded up, at most 65535) after its request,
  // and the device measured somewhere in between. 0: at time_ns. A run takes a sample for a
  // stop only when the whole interval lies where the machine stood (docs/iso230-2.md, "Which
  // samples make a stop's value").
  std::uint16_t measured_within_ms = 0;
  double value = 0.0;  // SI (m, Pa, degC, %RH)
};

enum class InstrumentState : std::uint8_t {
  closed,
  connecting,    // the transport is opening
  configuring,   // opened; the device is being set up (start measurement, INTV, ...)
  streaming,     // readings flow
  signal_lost,   // connected, but the device says its readings are not valid
  reconnecting,  // the connection failed or dropped; waiting for the next attempt
};
std::string_view to_string(InstrumentState s);

// A period without readings because the connection was down; reported when it ends (or when
// the instrument is stopped), with the reason of the drop.
struct Gap {
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  std::string reason;
};

struct Backoff {
  std::chrono::milliseconds initial{250};
  std::chrono::milliseconds max{8000};
  double factor = 2.0;
  int max_attempts = -1;  // -1: forever; otherwise give up (state closed) after that many
};

// What a device says that is not a reading, with its own number and text where it has them
// (an IDS3010's error or warning number and errorNumberToString text, a TEMPer's firmware).
struct DeviceMessage {
  enum class Severity : std::uint8_t { info, warning, error };
  Severity severity = Severity::info;
  std::int64_t code = 0;  // the device's number; 0 when it has none
  std::string text;
};
std::string_view to_string(DeviceMessage::Severity s);

struct InstrumentEvents {
  std::function<void(const Reading&)> reading;
  // Optional, for high-rate consumers: when set, an instrument that decodes several readings
  // from one chunk of bytes (a streaming gauge: ten lines per USB read at 10 kHz) hands them
  // over in one call, in order, instead of one `reading` call each (`reading` is then not
  // called for them). Any state change or gap they cause is reported before the call.
  std::function<void(std::span<const Reading>)> readings;
  std::function<void(InstrumentState, std::string_view why)> state;
  std::function<void(const Gap&)> gap;
  std::function<void(const codec::CodecError&)> codec_error;
  std::function<void(const DeviceMessage&)> message;
};

// Receives the exact bytes an instrument exchanged with its device, with the instrument's
// clock: the capture file (replay/) implements it. Recording at the instrument boundary,
// right after the transport, gives the readings and the recorded bytes one timestamp, so a
// replay reproduces the readings exactly.
// Must not throw: instruments record from their stop(), which runs in destructors (a failing
// recorder keeps its error and reports it another way; see cal::replay::CaptureRecorder).
class WireRecorder {
 public:
  virtual ~WireRecorder() = default;
  virtual void received(std::uint16_t device, std::int64_t time_ns,
                        std::span<const std::byte> bytes) = 0;
  virtual void sent(std::uint16_t device, std::int64_t time_ns,
                    std::span<const std::byte> bytes) = 0;
  virtual void event(std::uint16_t device, std::int64_t time_ns, std::string_view text) = 0;
};

struct InstrumentOptions {
  std::uint16_t device = 0;
  std::string name;  // for logs and errors, e.g. "laser" or "PTU300 #1"
  Backoff backoff;
  // Poll period of polled devices (IDS displacement, PTU300 in SEND mode, polled gauges).
  std::chrono::microseconds poll_period{10'000};
  // A connected device that sends nothing for this long is treated as a dropped connection.
  std::chrono::milliseconds silence_timeout{3000};
  Clock clock;                       // empty: loop_clock(io), the steady clock in real mode
  WireRecorder* recorder = nullptr;  // not owned; must outlive the instrument
  // Replay: the transport is a replay transport and the clock its recorded time. The
  // instrument then sends nothing and starts no timer (no polling, watchdog or reconnection
  // delays): the recorded session drives it, so the same capture always gives the same
  // readings.
  bool replay = false;
};

// How late a polled device's answers came after their requests (answer time - request time),
// over the answers of the session so far; the median and max are of the last kLatencyWindow.
struct AnswerLatency {
  static constexpr std::size_t kLatencyWindow = 4096;
  std::uint64_t answers = 0;    // answers matched to a request
  std::uint64_t unmatched = 0;  // answers with no request outstanding (stamped on arrival)
  std::int64_t median_ns = 0, max_ns = 0;
};

class Instrument {
 public:
  virtual ~Instrument() = default;
  Instrument() = default;
  Instrument(const Instrument&) = delete;
  Instrument& operator=(const Instrument&) = delete;

  virtual void start(InstrumentEvents events) = 0;
  virtual void stop() = 0;
  virtual InstrumentState state() const = 0;
  virtual const codec::CodecStats& codec_stats() const = 0;
  virtual std::string describe() const = 0;
  // A polled device whose readings are stamped with their request's time: how late its
  // answers came. nullopt for a device that streams, or stamps its readings otherwise.
  virtual std::optional<AnswerLatency> answer_latency() const { return std::nullopt; }
};

}  // namespace cal::drivers
