#pragma once
// JSON presentation of a circular test (schema caldaq.circle.v2), shared by `daq analyse
// circle`, the stored result of a ballbar run and the reports, so that all three agree. The
// standard chooses which ISO 230-4 values are reported and how they are named
// (cal::circle::StandardInfo); caldaq's other values of the same trace are "informative".
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "cal/analysis/circle.hpp"
#include "cal/analysis/circle_standards.hpp"

namespace daq {

inline constexpr std::string_view circle_schema = "caldaq.circle.v2";
// A stored circle result of any version (v1 before issue 18: H among the ISO 230-4:2005 values).
bool is_circle_schema(std::string_view schema);

// A value of the ISO 230-4 block by its JSON key ("G_bi_um", "H_um", ...).
double iso_value(const cal::circle::Iso230_4& iso, std::string_view key);

nlohmann::json circle_json(
    const cal::circle::Result& r, double radius_mm, std::string_view plane, double feed_mm_per_min,
    cal::circle::CircularStandard standard = cal::circle::CircularStandard::iso230_4_2005);

// One line of what to check on the machine for a diagnostic, by its key ("backlash_X",
// "squareness", "stick_slip_Y"...); empty for a key that is not a diagnostic.
std::string diagnostic_advice(std::string_view key);

// The same for a terminal: the standard's values, then the diagnostics ranked.
void print_circle(
    const cal::circle::Result& r, double radius_mm, std::string_view plane, double feed_mm_per_min,
    cal::circle::CircularStandard standard = cal::circle::CircularStandard::iso230_4_2005);

}  // namespace daq
