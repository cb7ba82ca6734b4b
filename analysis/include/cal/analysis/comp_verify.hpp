#pragma once
// Closing the compensation loop on the machine: a table was written from a measured error and
// predicted to leave a residual; the axis was measured again (as left). Did the control apply
// the table as caldaq read its vendor's text? If not, the change between the two measurements
// says how it applied it instead: with the other sign (the residual about twice the original
// error), scaled by a unit error (1000, 25.4), not at all, offset by a constant (a reference
// point), or at shifted positions. Pure: the caller reads the runs and the stored table.
#include <span>
#include <string>
#include <vector>

namespace cal::comptable {

struct VerifyInput {
  // Per point (a target and a direction of the as-left run): the error the table was made
  // from (the source run's mean there, um), the correction the table applies there as written
  // (um, what the control adds), and the as-left run's mean deviation there (um).
  std::vector<double> target_mm, before_um, applied_um, after_um;
  // The applied table itself (for the position-shift test): grid and values (um) per point.
  std::vector<double> table_position_mm, table_applied_um;
  // What counts as agreement: the measurements' repeatability (um). A floor of 0.3 um is used.
  double noise_um = 0.0;
};

enum class Finding {
  as_predicted,    // the residual is what the table was predicted to leave
  inverted_sign,   // the control applied it with the other sign: about twice the error
  not_applied,     // nothing changed: the table is not active (or scaled down by 1000)
  unit_scale,      // applied scaled by `scale` (1000, 1/25.4, 25.4): a unit error
  constant_shift,  // applied as predicted plus a constant `offset_um`: a reference-point error
  position_shift,  // applied at positions shifted by `shift_mm`: the table's start is off
  too_small,       // the table's corrections are within the noise: nothing to tell
  unexplained,     // none of the above fits: measure again, check the machine's state
};
std::string_view to_string(Finding f);

struct Verification {
  Finding finding = Finding::unexplained;
  double scale = 1.0;      // the factor the control applied the table with (unit_scale)
  double offset_um = 0.0;  // constant_shift
  double shift_mm = 0.0;   // position_shift
  double predicted_max_um = 0.0, measured_max_um = 0.0;
  double mismatch_rms_um = 0.0;  // of the measured residual against the finding's explanation
  double tolerance_um = 0.0;
  std::string text;  // the diagnosis and what to do, in a sentence or two
};

// Throws cal::InputError for inputs of unequal lengths, fewer than 2 points or non-finite
// values.
Verification verify(const VerifyInput& in);

}  // namespace cal::comptable
