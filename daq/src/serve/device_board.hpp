#pragma once
// The state of every configured instrument for the operator's page: connecting, streaming,
// signal lost, reconnecting (attempt n of m), silent, failed, each with its reason; its newest
// values while they are fresh (a device that has gone silent shows no value at all, never the
// last one); the share of valid readings (beam or signal quality where the device reports
// readings as invalid); and the environment (air, material, refractive index, compensation
// factor) from fresh values only. Fed by the instruments of the idle monitor and of the runs
// alike, so the page shows the same thing before, during and after a run.
//
// Whether a test may start: every device the test uses must be streaming valid, fresh
// readings (the ballbar: reachable, as a bar sends nothing until it is mounted and moving).
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cal/daq/config.hpp"
#include "cal/drivers/instrument.hpp"

namespace daq::serve {

// Whether a run of `test` ("linear" | "circle") opens device `dc` itself: the ballbar for a
// circle; for a linear run the air, the material thermometers, the instrument its kind reads
// (indicator, level, angle) and, unless that instrument gives the stops (rotary), the laser and
// the position feed. Start's readiness and the idle monitors both ask this one question.
bool run_uses(const cal::daq::Config& c, std::string_view test, const cal::daq::DeviceConfig& dc);

class DeviceBoard {
 public:
  using Clock = std::chrono::steady_clock;
  using WallClock = std::function<Clock::time_point()>;  // tests give their own time

  explicit DeviceBoard(const cal::daq::Config& config, WallClock wall = {});
  DeviceBoard(const DeviceBoard&) = delete;
  DeviceBoard& operator=(const DeviceBoard&) = delete;

  // The instrument now serving device `id` reads about every `period` (wall clock) and gives
  // up after `max_attempts` failed connections (-1: never).
  void expect(const std::string& id, std::chrono::milliseconds period, int max_attempts);
  void on_state(const std::string& id, cal::drivers::InstrumentState s, std::string_view why);
  void on_reading(const std::string& id, const cal::drivers::Reading& r);
  // The device's instrument could not be made (e.g. its transport text), or was given up.
  void on_failed(const std::string& id, const std::string& why);

  // caldaq.devices-state.v1: {"devices": [...], "environment": {...}} (docs/web.md).
  nlohmann::json to_json() const;

  // Why `test` ("linear" | "circle") cannot start now, naming the device and its state and
  // reason; nullopt when every device it uses is ready.
  std::optional<std::string> refusal(std::string_view test) const;

 private:
  struct Value {
    double value = 0.0;
    Clock::time_point at;
  };
  struct Device {
    const cal::daq::DeviceConfig* config = nullptr;
    cal::drivers::InstrumentState state = cal::drivers::InstrumentState::closed;
    std::string reason;
    bool failed = false;  // could not be made, or gave up
    bool opened = false;  // the transport opened at the latest attempt
    int attempts = 0;     // connection attempts since the last reading
    int max_attempts = -1;
    std::chrono::milliseconds period{1000};
    std::optional<Clock::time_point> last_reading;
    std::map<std::pair<int, int>, Value> values;  // (quantity, channel) -> newest valid value
    // Valid and invalid readings in the current and the previous second.
    Clock::time_point bucket_start{};
    std::uint64_t ok[2] = {0, 0}, bad[2] = {0, 0};
  };

  Clock::time_point now() const;
  bool fresh(const Device& d) const;
  std::string condition(const Device& d) const;  // the state the page shows
  std::optional<double> value(const Device& d, cal::drivers::Quantity q, int channel = 0) const;
  nlohmann::json device_json(const Device& d) const;
  nlohmann::json environment_json() const;
  std::optional<std::string> not_ready(const Device& d, bool may_be_silent) const;

  cal::daq::Config config_;
  WallClock wall_;
  std::map<std::string, Device> devices_;
};

// An instrument that tells the board about its states and readings (and then its owner, a
// run or the idle monitor, exactly as it would without the board).
std::unique_ptr<cal::drivers::Instrument> watched(std::unique_ptr<cal::drivers::Instrument> inner,
                                                  std::string id,
                                                  std::shared_ptr<DeviceBoard> board);

}  // namespace daq::serve
