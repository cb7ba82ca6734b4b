#pragma once
// Where a run's instrument readings came from, stored with each instrument (schema 5,
// docs/storage.md "Origin") so that nothing derived from a simulated or replayed run can pass
// for a measurement of a real machine, whatever its names say.
#include <map>
#include <string>

namespace daq {

struct InstrumentOrigin {
  // "real", "simulated" (a twin of the built-in simulated shop), "replay" (a capture pushed
  // through the driver again), "imported" (another tool's file); "" not recorded.
  std::string kind;
  std::string detail;  // which capture (and what it recorded), which shop, which file
};

// A run's instruments' origins by role ("laser", "air", "material", "position", "indicator",
// "level", "ballbar"). A role missing here is stored as not recorded (""), never as real.
using Origins = std::map<std::string, InstrumentOrigin>;

// The origin of a configured device's readings: its configured origin ("real" or "simulated"),
// or a replay of `capture` (not empty) that recorded such a device.
InstrumentOrigin origin_of(const std::string& configured, const std::string& replay_capture);

}  // namespace daq
