// The values of `daq ballbar calibrate`, checked (see bar_calibration_input.hpp).
#include "bar_calibration_input.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <utility>

#include "cal/analysis/error.hpp"

namespace daq {

std::int64_t parse_utc(const std::string& text) {
  std::tm tm{};
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0;
  char rest = 0;
  const int n =
      std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%c", &y, &mo, &d, &h, &mi, &s, &rest);
  const bool date_only = n == 3 && text.size() == 10;
  const bool with_time = (n == 5 && text.size() == 16) || (n == 6 && text.size() == 19);
  if (!(date_only || with_time) || mo < 1 || mo > 12 || d < 1 || d > 31 || h < 0 || h > 23 ||
      mi < 0 || mi > 59 || s < 0 || s > 59)
    throw cal::InputError(
        fmt::format("--date '{}': expected YYYY-MM-DD or YYYY-MM-DDTHH:MM[:SS] (UTC)", text));
  tm.tm_year = y - 1900, tm.tm_mon = mo - 1, tm.tm_mday = d;
  tm.tm_hour = h, tm.tm_min = mi, tm.tm_sec = s;
  const std::time_t t = timegm(&tm);
  std::tm back{};
  gmtime_r(&t, &back);
  if (back.tm_mday != d || back.tm_mon != mo - 1)
    throw cal::InputError(fmt::format("--date '{}': no such day", text));
  return static_cast<std::int64_t>(t) * 1000;
}

std::int64_t check_bar_calibration(const BarCalibrationInput& in, std::int64_t now_unix_s) {
  for (double v : {in.nominal_mm, in.calibrator_mm, in.reading_mm})
    if (!std::isfinite(v)) throw cal::InputError("ballbar calibrate: the lengths must be finite");
  for (const auto& [v, option] :
       {std::pair{in.nominal_mm, "--nominal-mm"}, std::pair{in.calibrator_mm, "--calibrator-mm"}})
    if (!(v > 0 && v <= kMaxBarMm))
      throw cal::InputError(
          fmt::format("ballbar calibrate: {} {} mm: a bar is longer than 0 and at most {:g} m",
                      option, v, kMaxBarMm / 1e3));
  if (in.temperature_degc &&
      !(*in.temperature_degc >= kMinCalibrationDegC && *in.temperature_degc <= kMaxCalibrationDegC))
    throw cal::InputError(fmt::format(
        "ballbar calibrate: --temperature-degc {}: outside {:g} .. {:g} degC, where no bar is "
        "calibrated",
        *in.temperature_degc, kMinCalibrationDegC, kMaxCalibrationDegC));
  // Sanity, not physics: a calibrator fits the bar it calibrates, and a ballbar's transducer
  // travels a few mm at most.
  if (std::abs(in.calibrator_mm - in.nominal_mm) > kMaxBarTravelMm)
    throw cal::InputError(fmt::format(
        "ballbar calibrate: a calibrator of {} mm does not fit a {} mm bar (--calibrator-mm is "
        "the calibrator's certified length, --nominal-mm the bar's with its extensions)",
        in.calibrator_mm, in.nominal_mm));
  if (std::abs(in.reading_mm) > kMaxBarTravelMm)
    throw cal::InputError(
        fmt::format("ballbar calibrate: a reading of {} mm is beyond a ballbar transducer's travel "
                    "(--reading-mm is the bar's reading in the calibrator, in mm)",
                    in.reading_mm));
  if (in.date.empty()) return 0;
  const std::int64_t at_ms = parse_utc(in.date);
  std::tm first{};
  first.tm_year = kFirstCalibrationYear - 1900, first.tm_mday = 1;
  const std::int64_t first_ms = static_cast<std::int64_t>(timegm(&first)) * 1000;
  const std::int64_t tomorrow_ms = (now_unix_s + 86400) * 1000;
  if (at_ms < first_ms || at_ms > tomorrow_ms)
    throw cal::InputError(
        fmt::format("ballbar calibrate: --date '{}': before {} or in the future (a typing error?)",
                    in.date, kFirstCalibrationYear));
  return at_ms;
}

}  // namespace daq
