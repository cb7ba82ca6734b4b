#pragma once
// The part program of a configured test, in a controller dialect: the one function behind
// `daq gcode linear|circle` and the operator's page (GET/POST /api/setup/program), so the
// program the page shows and downloads is the one the command line writes for the same set-up.
#include <string>
#include <string_view>

#include "cal/daq/config.hpp"

namespace daq {

// test: "linear" ([test.linear]) or "circle" ([test.circle]); dialect: fanuc | iso |
// heidenhain | siemens | sinumerik. Throws cal::InputError naming the configuration when the
// test is not configured, or the unknown test or dialect.
// circle: the configuration's test or set (circle_tests, docs/circle.md "The standard set"),
// with `standard_set` the set of XY, ZX, YZ even for a single test; `by_radius` writes arcs by
// radius in pieces of at most 90 deg.
struct PartProgramOptions {
  bool standard_set = false;
  bool by_radius = false;
};
std::string part_program(const cal::daq::Config& config, std::string_view test,
                         std::string_view dialect, const PartProgramOptions& o = {});

}  // namespace daq
