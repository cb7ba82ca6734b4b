// The measurement CSV reader on arbitrary text, both syntaxes (point and comma decimals):
// every number it returns is finite, every refusal is cal::InputError naming the line.
#include <cmath>
#include <string_view>

#include "cal/analysis/error.hpp"
#include "csv_table.hpp"
#include "measurement_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const bool comma : {false, true}) {
    try {
      const auto t = daq::CsvTable::parse(text, "fuzz.csv", {.decimal_comma = comma});
      for (std::string_view col : {"position_mm", "deviation_um", "angle_deg", "time_s"}) {
        if (!t.has(col)) continue;
        for (std::size_t r = 0; r < t.rows(); ++r) try {
            if (!std::isfinite(t.number(r, col))) __builtin_trap();
          } catch (const cal::InputError&) {
          }
      }
    } catch (const cal::InputError&) {
    }
    try {
      for (const auto& m : daq::parse_measurements(text, "fuzz.csv", {.decimal_comma = comma}))
        if (!std::isfinite(m.target_mm) || !std::isfinite(m.deviation_um) || m.run < 1)
          __builtin_trap();
    } catch (const cal::InputError&) {
    }
  }
  return 0;
}
