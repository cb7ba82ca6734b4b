#pragma once
// Squareness between two linear axes A (reference, e.g. X) and B (e.g. Y) by the methods of
// ISO 230-1, and the diagonal displacement test of ISO 230-6. Sign convention (ISO 230-1
// E_C0Y): the squareness alpha is positive when the angle between the positive directions of
// A and B exceeds 90 degrees; then travel along B moves the tool by -alpha b along A.
// Derivations: docs/straightness-squareness.md and the comments in squareness.cpp.
#include <span>
#include <vector>

namespace cal::squareness {

struct Run {  // a straightness run: positions along the moving axis, deviations across it
  std::vector<double> position_mm;
  std::vector<double> deviation_um;
};

struct Result {
  double squareness_um_per_m = 0.0;
  double arcsec() const { return squareness_um_per_m * 0.206264806; }  // 1 um/m = 0.2063"
};

// Two straightness measurements against one square reference (a square artefact or an
// optical square): `along_a` moves A and measures the deviation in +B; `along_b` moves B and
// measures the deviation in +A. With the least-squares slopes mA (um/m, B per A) and mB
// (A per B): alpha = -(mA + mB) - square_error, where square_error is the reference's own
// departure from 90 degrees (same convention; 0 for a calibrated square). Valid for the
// L, T and cross configurations alike: only the slopes of the lines enter.
Result from_straightness(const Run& along_a, const Run& along_b,
                         double square_error_um_per_m = 0.0);

// Reversal of the square (ISO 230-1 reversal: the artefact turned over, so its own error
// enters with the opposite sign): the mean of the two results cancels the square's error.
Result from_reversal(const Result& normal, const Result& reversed);

// ISO 230-6 diagonal displacement test on a rectangle X by Y (mm): d1 is the length error
// (um) of the diagonal from (X, 0) to (0, Y), d2 of the diagonal from (0, 0) to (X, Y).
// alpha = D0 (d1 - d2) / (2 X Y), D0 = sqrt(X^2 + Y^2).
Result from_diagonals(double x_mm, double y_mm, double d1_um, double d2_um);

// One circular test (radial deviations in the A-B plane about the table ball, angle from +A
// towards +B): fits r = r0 + a cos t + b sin t + c cos 2t + d sin 2t; alpha = -2 d / R. A pair
// of cw and ccw traces should be combined (their mean cancels the servo mismatch, which also
// appears as sin 2t with the sign of the direction).
struct CircleTrace {
  std::vector<double> angle_deg;
  std::vector<double> deviation_um;
};
Result from_circle(double radius_mm, std::span<const CircleTrace> traces);

// Several circles along a long axis (or overlapping circles covering a larger area): each
// gives the squareness local to its own position; their mean is the estimate of the global
// squareness over the covered length.
struct Local {
  double centre_a_mm = 0.0;
  Result result;
};
Result from_circles(std::span<const Local> circles);

}  // namespace cal::squareness
