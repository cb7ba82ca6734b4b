#pragma once
// The values of `daq ballbar calibrate`, checked before anything is stored (docs/circle.md,
// "Bar calibration"): apart from the command so that the checks are unit-tested and fuzzed.
#include <cstdint>
#include <optional>
#include <string>

namespace daq {

struct BarCalibrationInput {
  double nominal_mm = 0.0, calibrator_mm = 0.0, reading_mm = 0.0;
  std::optional<double> temperature_degc;
  std::string date;  // YYYY-MM-DD[THH:MM[:SS]] UTC, or empty (now)
};

// Limits of physical sense: no bar is longer than 100 m, none is calibrated outside
// -50 .. 100 degC, before 1990 (a date "0026-01-05" is a typing error, not a calibration 2000
// years old) or in the future; a calibrator fits its bar within 5 mm, and a ballbar's
// transducer travels at most 5 mm.
inline constexpr double kMaxBarMm = 100e3, kMinCalibrationDegC = -50.0, kMaxCalibrationDegC = 100.0,
                        kMaxBarTravelMm = 5.0;
inline constexpr int kFirstCalibrationYear = 1990;

// "YYYY-MM-DD" or "YYYY-MM-DDTHH:MM[:SS]" (UTC) as unix ms; InputError naming --date.
std::int64_t parse_utc(const std::string& text);

// The calibration's date in unix ms (0: none given, i.e. now) once every value is within the
// limits above; InputError naming the option and the reason otherwise. `now_unix_s`: the clock.
std::int64_t check_bar_calibration(const BarCalibrationInput& in, std::int64_t now_unix_s);

}  // namespace daq
