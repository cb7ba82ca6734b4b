// Numbers in fixed notation (see fixed_text.hpp).
#include "cal/analysis/fixed_text.hpp"

#include <fmt/format.h>

#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal {

std::string fixed_text(double v, int decimals) {
  const double r = fixed_value(v, decimals);  // refuses decimals < 0 first, as before
  if (std::isnan(r)) return "nan";            // whatever its sign bit
  return fmt::format("{:.{}f}", r, decimals);
}

double fixed_value(double v, int decimals) {
  if (decimals < 0)
    throw InputError(fmt::format("{} decimal places: expected 0 or more", decimals));
  // Rounded at the last place by std::round of v x 10^decimals (half away from zero) rather
  // than by the binary value's digits: 0.0035 is stored a little over 7/2000 and 0.0045 a
  // little under 9/2000, yet a table of decimal data should round both up ("0.004", "0.005";
  // the binary digits give "0.004" twice). The product lands on such a tie exactly; a value
  // within an ulp or so of a tie rounds as the product does (12.34565 x 10^4 is 123456.49...).
  const double scale = std::pow(10.0, decimals);
  const double scaled = v * scale;
  // From 2^52 on the product is whole and dividing it back would move v (1e20 to 3 places
  // would read 99999999999999983616.000): v has no digits that fine to round, write it as is.
  double r = std::abs(scaled) < 0x1p52 ? std::round(scaled) / scale : v;
  if (r == 0.0) r = 0.0;  // -0.0 and whatever rounds to zero: "0.000", never "-0.000"
  return r;
}

std::string control_text(double v, int decimals, std::string_view role) {
  if (!std::isfinite(v))
    throw InputError(fmt::format(
        "{} is {}: nothing non-finite goes into a controller table or a part program", role, v));
  return fixed_text(v, decimals);
}

}  // namespace cal
