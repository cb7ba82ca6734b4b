#pragma once
// One device of a capture rewritten at its highest rate, for measuring `daq replay` per device
// kind (`daq bench replay`, docs/benchmarks.md "Replay speed of every device kind"). The input
// is a capture of the simulated shop (`daq sim --acquire --capture`); the other devices'
// records are copied unchanged and every record stays in time order, so the output is the
// same run, only denser, and `daq replay` of it finishes as the original did.
#include <filesystem>
#include <span>
#include <string_view>

namespace cal::replay {

struct DenseKind {
  std::string_view kind;  // the name densify() takes
  std::string_view test;  // the template it needs: "linear" (with the position feed), "circle"
  double rate_hz;         // its highest rate
  std::string_view what;  // the device and why this rate (docs/benchmarks.md)
};

// ids3010     the laser's getAxesDisplacement pairs, more of them between the recorded ones
//             (new ids; every later id of the laser shifted), displacements interpolated
// ptu300      the air's SEND and its line, repeated at the rate
// gauge       the material thermometer's "?" and its answer, repeated at the rate
// ballbar     the bar's streamed lines at the rate (config.circle.sample_rate_hz too),
//             lengths interpolated between the recorded samples
// shdr        the position feed's Xcom lines at the rate while the axis moves (gaps up to
//             50 ms between recorded lines), positions interpolated
// halsampler  the SHDR feed replaced by halsampler lines at the rate to the capture's end,
//             the same positions
// temper      the material thermometer replaced by a TEMPer (family gold, channel 0) read
//             at the rate, the same temperatures
std::span<const DenseKind> dense_kinds();

// Writes `out`: `in` with the device of `kind` at `rate_hz` (in (0, 1e6]). Throws
// std::runtime_error (what and which file): an unknown kind, a capture without that device or
// its values, a damaged capture.
void densify(const std::filesystem::path& in, const std::filesystem::path& out,
             std::string_view kind, double rate_hz);

}  // namespace cal::replay
