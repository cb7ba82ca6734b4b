// The TOML configuration loader on arbitrary text: a Config whose values are all within their
// documented ranges, or cal::InputError with the file:line:column; never a crash or another
// exception (toml++'s own parse errors included).
#include <cmath>
#include <string_view>

#include "cal/analysis/error.hpp"
#include "cal/daq/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto c = cal::daq::parse_config(text, "fuzz.toml");
    if (c.linear) {
      const auto& l = *c.linear;
      if (!std::isfinite(l.first_mm) || !std::isfinite(l.last_mm) || l.runs < 1 ||
          !(l.overrun_mm >= 0 && l.overrun_mm <= 1000))
        __builtin_trap();
    }
    if (c.circle) {
      for (double v : c.circle->centre_mm)
        if (!std::isfinite(v)) __builtin_trap();
      if (!(c.circle->radius_mm > 0) || !std::isfinite(c.circle->radius_mm)) __builtin_trap();
    }
  } catch (const cal::InputError&) {
  }
  return 0;
}
