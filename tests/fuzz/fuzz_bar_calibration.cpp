// The values of `daq ballbar calibrate` on arbitrary text (one value a line: nominal mm,
// calibrator mm, reading mm, temperature degC or empty, date), read as loosely as strtod does
// (nan, inf, hex: what the command line refuses must be refused here too): a calibration within
// the limits of bar_calibration_input.hpp, or cal::InputError. Never a crash or another
// exception (sscanf's %4d on "-0x", timegm of year 9999).
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "bar_calibration_input.hpp"
#include "cal/analysis/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> lines(1);
  for (std::size_t i = 0; i < size && lines.size() <= 5; ++i) {
    if (data[i] == '\n')
      lines.emplace_back();
    else
      lines.back().push_back(static_cast<char>(data[i]));
  }
  lines.resize(5);
  const auto number = [](const std::string& s) { return std::strtod(s.c_str(), nullptr); };
  daq::BarCalibrationInput in{
      .nominal_mm = number(lines[0]),
      .calibrator_mm = number(lines[1]),
      .reading_mm = number(lines[2]),
      .temperature_degc = lines[3].empty() ? std::nullopt : std::optional(number(lines[3])),
      .date = lines[4]};
  constexpr std::int64_t now_s = 1'795'000'000;  // 2026-11
  try {
    const std::int64_t at_ms = daq::check_bar_calibration(in, now_s);
    if (!(in.nominal_mm > 0 && in.nominal_mm <= daq::kMaxBarMm) ||
        !(std::abs(in.reading_mm) <= daq::kMaxBarTravelMm) ||
        (in.temperature_degc && !(*in.temperature_degc >= daq::kMinCalibrationDegC &&
                                  *in.temperature_degc <= daq::kMaxCalibrationDegC)) ||
        (!in.date.empty() && (at_ms < 631'152'000'000 || at_ms > (now_s + 86400) * 1000)))
      __builtin_trap();
  } catch (const cal::InputError&) {
  }
  return 0;
}
