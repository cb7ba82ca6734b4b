#pragma once
// Straightness of a linear axis from a run of perpendicular deviations, with the reference
// lines of ISO 230-1: least squares, end point, minimum zone (two parallel lines enclosing
// all points with the least separation, measured in the deviation direction; exact, from the
// convex hull). Formulas and sources: docs/straightness-squareness.md.
#include <span>
#include <string_view>
#include <vector>

namespace cal::straightness {

enum class Reference { least_squares, end_point, minimum_zone };
std::string_view to_string(Reference r);
Reference reference_from_string(std::string_view s);  // lsq | endpoint | minzone

struct Result {
  Reference reference = Reference::least_squares;
  double straightness_um = 0.0;     // max - min of the residuals from the reference line
  double slope_um_per_m = 0.0;      // of the reference line
  double intercept_um = 0.0;        // at position 0
  std::vector<double> residual_um;  // deviation minus reference line, per point
};

// positions in mm (any order, at least 2 distinct), deviations in um. Throws
// cal::InputError for mismatched lengths, fewer than 2 points, equal positions only, or
// non-finite values.
Result evaluate(std::span<const double> position_mm, std::span<const double> deviation_um,
                Reference reference);

}  // namespace cal::straightness
