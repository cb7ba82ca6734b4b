#pragma once
// The frame of the machine position feeds (halsampler, shdr): the positions a control reports
// (actual or commanded), for the position-assisted trigger.
#include <array>
#include <cstdint>
#include <optional>

namespace cal::drivers::codec {

struct PositionFrame {
  std::array<std::optional<double>, 3> position_m;  // X, Y, Z: those the line carried
  // SHDR: the axis's item said UNAVAILABLE (the adapter has no value from the control, e.g.
  // while the control is disconnected): its position is unknown from now on, not held.
  std::array<bool, 3> unavailable{};
  std::optional<std::uint64_t> sample;  // halsampler's sample number (-t)
  std::uint64_t lost_before = 0;        // samples skipped before this one (-t)
  bool overrun = false;  // halsampler printed "overrun" before this sample: samples were lost
  // SHDR: the timestamp's @duration suffix (s), and a relative timestamp (ms since the first).
  std::optional<double> duration_s;
  std::optional<double> relative_time_ms;
  std::optional<std::int64_t> time_unix_ns;  // SHDR's timestamp (UTC)
};

}  // namespace cal::drivers::codec
