// The part program of a configured test (see part_program.hpp).
#include "part_program.hpp"

#include <fmt/format.h>

#include "cal/analysis/error.hpp"
#include "cal/daq/gcode.hpp"
#include "linear_run.hpp"

namespace daq {

std::string part_program(const cal::daq::Config& config, std::string_view test,
                         std::string_view dialect_name) {
  const auto dialect = cal::daq::dialect_from_string(dialect_name);
  if (test == "circle") {
    if (!config.circle)
      throw cal::InputError(fmt::format("{}: no [test.circle]", config.source.string()));
    const auto& c = *config.circle;
    return cal::daq::circle_program({.radius_mm = c.radius_mm,
                                     .feed_mm_per_min = c.feed_mm_per_min,
                                     .sample_rate_hz = c.sample_rate_hz,
                                     .overshoot_deg = c.overshoot_deg},
                                    {.centre_x_mm = c.centre_mm[0],
                                     .centre_y_mm = c.centre_mm[1],
                                     .centre_z_mm = c.centre_mm[2],
                                     .plane = cal::daq::plane_from_string(c.plane)},
                                    dialect);
  }
  if (test == "linear") {
    if (!config.linear)
      throw cal::InputError(fmt::format("{}: no [test.linear]", config.source.string()));
    const auto& l = *config.linear;
    return cal::daq::linear_program(
        linear_plan(l),
        {.axis = l.axis[0], .feed_mm_per_min = l.feed_mm_per_min, .dwell_s = l.dwell_s}, dialect);
  }
  throw cal::InputError(fmt::format("no test '{}': linear or circle", test));
}

}  // namespace daq
