// The compensation loop's check (see comp_verify.hpp).
#include "cal/analysis/comp_verify.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/comp_table.hpp"
#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::comptable {

std::string_view to_string(Finding f) {
  using enum Finding;
  // clang-format off
  static constexpr EnumName<Finding> kNames[] = {
      {as_predicted, "as predicted"}, {inverted_sign, "inverted sign"},
      {not_applied, "not applied"}, {unit_scale, "unit error"},
      {constant_shift, "reference-point error"}, {position_shift, "position shift"},
      {too_small, "too small to tell"}, {unexplained, "unexplained"}};
  // clang-format on
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, f, "unknown");
}

namespace {

constexpr double kNoiseFloorUm = 0.3;

void check(const VerifyInput& in) {
  const auto n = in.target_mm.size();
  if (n < 2 || in.before_um.size() != n || in.applied_um.size() != n || in.after_um.size() != n)
    throw InputError(fmt::format(
        "verify: {} targets with {} / {} / {} values (expected the same number, at least 2)", n,
        in.before_um.size(), in.applied_um.size(), in.after_um.size()));
  if (in.table_position_mm.size() != in.table_applied_um.size() || in.table_position_mm.size() == 1)
    throw InputError("verify: the applied table needs as many values as positions (0 or >= 2)");
  for (const auto* v : {&in.target_mm, &in.before_um, &in.applied_um, &in.after_um,
                        &in.table_position_mm, &in.table_applied_um})
    for (double x : *v)
      if (!std::isfinite(x)) throw InputError("verify: a value is not a finite number");
  if (!std::isfinite(in.noise_um) || in.noise_um < 0)
    throw InputError("verify: the noise must be a finite number >= 0");
}

double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// What is left of the as-left measurement once the explanation "the control applied the table
// scaled by s, plus c" is taken off: after - (before + s applied + c).
std::vector<double> mismatch(const VerifyInput& in, double s, double c) {
  std::vector<double> m;
  for (std::size_t i = 0; i < in.after_um.size(); ++i)
    m.push_back(in.after_um[i] - (in.before_um[i] + s * in.applied_um[i] + c));
  return m;
}

double mean_offset(const VerifyInput& in) {
  double sum = 0;
  for (double x : mismatch(in, 1.0, 0.0)) sum += x;
  return sum / static_cast<double>(in.after_um.size());
}

struct Shift {
  double delta_mm = 0, rms_um = 1e300;
};

// The table applied at shifted positions: after = before + table(x - delta). Searched over two
// grid intervals either way in steps of a twentieth of one.
Shift best_shift(const VerifyInput& in) {
  Shift best;
  if (in.table_position_mm.size() < 2) return best;
  const double step = (in.table_position_mm[1] - in.table_position_mm[0]) / 20.0;
  for (int k = -40; k <= 40; ++k) {
    if (k == 0) continue;
    const double d = k * step;
    std::vector<double> m;
    for (std::size_t i = 0; i < in.after_um.size(); ++i)
      m.push_back(in.after_um[i] - in.before_um[i] -
                  correction_at_um(in.table_position_mm, in.table_applied_um, in.target_mm[i] - d));
    if (const double r = rms(m); r < best.rms_um) best = {d, r};
  }
  return best;
}

std::string advice(const Verification& v) {
  switch (v.finding) {
    case Finding::as_predicted:
      return fmt::format(
          "the control applied the table as caldaq reads its vendor's text: largest residual "
          "{:.3f} um, predicted {:.3f} um",
          v.measured_max_um, v.predicted_max_um);
    case Finding::inverted_sign:
      return fmt::format(
          "the error got about twice as large: the control applies this format's values with "
          "the other sign than caldaq's reading of the vendor's text. Load the corrected table "
          "(every value negated: daq verify RUN --corrected FILE) and tell us the control and "
          "its version");
    case Finding::not_applied:
      return "nothing changed: the table is not active (enable it in the control, reference the "
             "axis again) or its values were entered 1000 times too small";
    case Finding::unit_scale:
      return fmt::format(
          "the control applied the table {:g} times as large as meant: a unit error (mm for um, "
          "inch for mm). Load the corrected table (values divided by {:g})",
          v.scale, v.scale);
    case Finding::constant_shift:
      return fmt::format(
          "the table acted as predicted but the axis is off by a constant {:+.3f} um: a "
          "reference-point error (the table is relative to a reference point the control does "
          "not use, or the reference point moved). Shift the reference point, or load the "
          "corrected table (every value {:+.3f} um)",
          v.offset_um, -v.offset_um);
    case Finding::position_shift:
      return fmt::format(
          "the table acted at positions shifted by {:+.3f} mm: its start position does not match "
          "the control's axis position (check the machine datum). Load the corrected table with "
          "its positions shifted",
          v.shift_mm);
    case Finding::too_small:
      return "the table's corrections are within the measurements' noise: there is nothing to "
             "verify";
    case Finding::unexplained:
      return "the as-left measurement matches neither the prediction nor a sign, unit or "
             "reference error: check the machine's state (temperature, warm-up, the table "
             "loaded) and measure again";
  }
  return "";
}

}  // namespace

Verification verify(const VerifyInput& in) {
  check(in);
  Verification v;
  v.tolerance_um = std::max(kNoiseFloorUm, 2.0 * in.noise_um);
  std::vector<double> predicted;
  for (std::size_t i = 0; i < in.before_um.size(); ++i)
    predicted.push_back(in.before_um[i] + in.applied_um[i]);
  v.predicted_max_um = max_abs(predicted);
  v.measured_max_um = max_abs(in.after_um);
  const auto fits = [&](double r) { return r <= v.tolerance_um; };
  const auto done = [&](Finding f, double r) {
    v.finding = f;
    v.mismatch_rms_um = r;
    v.text = advice(v);
    return v;
  };
  const double predicted_rms = rms(mismatch(in, 1.0, 0.0));
  if (max_abs(in.applied_um) < v.tolerance_um)
    return done(fits(predicted_rms) ? Finding::too_small : Finding::unexplained, predicted_rms);
  if (fits(predicted_rms)) return done(Finding::as_predicted, predicted_rms);
  // The control applied the values scaled: by -1 (sign), 0 (not at all), or a unit factor.
  struct Candidate {
    Finding finding;
    double scale;
  };
  constexpr Candidate candidates[] = {
      {Finding::inverted_sign, -1.0},       {Finding::not_applied, 0.0},
      {Finding::unit_scale, 1000.0},        {Finding::unit_scale, 25.4},
      {Finding::unit_scale, 1.0 / 25.4},    {Finding::unit_scale, 1.0 / 1000.0},
      {Finding::unit_scale, 1000.0 / 25.4}, {Finding::unit_scale, 25.4 / 1000.0},
  };
  const Candidate* best = nullptr;
  double best_rms = 1e300;
  for (const auto& c : candidates)
    if (const double r = rms(mismatch(in, c.scale, 0.0)); r < best_rms) best = &c, best_rms = r;
  if (fits(best_rms)) {
    v.scale = best->scale;
    // A table scaled down by 1000 looks like one not applied: say so, as not applied.
    if (best->finding == Finding::unit_scale && best->scale < 0.01)
      return done(Finding::not_applied, best_rms);
    return done(best->finding, best_rms);
  }
  const double c = mean_offset(in);
  if (const double r = rms(mismatch(in, 1.0, c)); fits(r)) {
    v.offset_um = c;
    return done(Finding::constant_shift, r);
  }
  if (const auto s = best_shift(in); fits(s.rms_um)) {
    v.shift_mm = s.delta_mm;
    return done(Finding::position_shift, s.rms_um);
  }
  return done(Finding::unexplained, predicted_rms);
}

}  // namespace cal::comptable
