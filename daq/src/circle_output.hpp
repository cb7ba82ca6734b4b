#pragma once
// JSON presentation of a circular test (schema caldaq.circle.v1), shared by `daq analyse
// circle`, the stored result of a ballbar run and the reports, so that all three agree.
#include <nlohmann/json.hpp>
#include <string_view>

#include "cal/analysis/circle.hpp"

namespace daq {

nlohmann::json circle_json(const cal::circle::Result& r, double radius_mm, std::string_view plane,
                           double feed_mm_per_min);

// The same for a terminal: ISO 230-4 values, then the diagnostics ranked.
void print_circle(const cal::circle::Result& r, double radius_mm, std::string_view plane,
                  double feed_mm_per_min);

}  // namespace daq
