// The part program of a configured test (see part_program.hpp).
#include "part_program.hpp"

#include <fmt/format.h>

#include "cal/analysis/error.hpp"
#include "cal/daq/gcode.hpp"
#include "circle_run.hpp"
#include "linear_run.hpp"

namespace daq {

std::string part_program(const cal::daq::Config& config, std::string_view test,
                         std::string_view dialect_name, const PartProgramOptions& o) {
  const auto dialect = cal::daq::dialect_from_string(dialect_name);
  if (test == "circle") {
    if (!config.circle)
      throw cal::InputError(fmt::format("{}: no [test.circle]", config.source.string()));
    std::vector<cal::daq::BallbarSetTest> set;
    for (const auto& t : circle_tests(config, o.standard_set)) set.push_back({t.plane, t.program});
    auto setup = circle_program_setup(config);
    if (o.by_radius) setup.arcs = cal::daq::ArcForm::radius;
    return cal::daq::circle_set_program(set, setup, dialect);
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
