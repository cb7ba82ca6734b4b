// The keys of the configuration's plain sections (see config_fields.hpp and docs/config.md).
#include "cal/daq/config_fields.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/iso230_2_targets.hpp"

namespace cal::daq::fields {
namespace {

// Positions within +-100 m, feeds up to 200 m/min, dwells up to an hour: beyond any machine
// this calibrates, and small enough that nothing written into a part program overflows.
constexpr double kMaxPositionMm = 100'000, kMaxFeedMmPerMin = 200'000, kMaxDwellS = 3600;

constexpr Range closed(double lo, double hi, std::string_view unit) { return {lo, hi, unit}; }
constexpr Range above(double lo, double hi, std::string_view unit) {
  return {lo, hi, unit, true, false};
}
constexpr Range position{-kMaxPositionMm, kMaxPositionMm, "mm"};
constexpr Range feed = above(0, kMaxFeedMmPerMin, "mm/min");
constexpr Range dwell = above(0, kMaxDwellS, "s");

constexpr std::string_view kEquations[] = {"ciddor", "edlen", "shop-floor"};
constexpr std::string_view kPolicies[] = {"stop", "fallback"};
constexpr std::string_view kAxes[] = {"X", "Y", "Z", "A", "B", "C"};  // A, B, C: rotary
constexpr std::string_view kCycles[] = {"linear", "pendulum", "pilgrim-step"};
constexpr std::string_view kKinds[] = {"positioning", "straightness", "angular", "roll", "rotary"};
constexpr std::string_view kPlanes[] = {"XY", "YZ", "ZX"};

using E = EnvironmentConfig;
using T = TriggerConfig;
using L = LinearTestConfig;
using M = MeasureConfig;
using C = CircleTestConfig;

// Ranges of the air: those the refractive-index equations accept (NIST's calculator: -40 ..
// 100 degC, 10 .. 140 kPa, 0 .. 100 %RH, 0 .. 2000 umol/mol, 300 .. 1700 nm).
const Field<E> kEnvironment[] = {
    {"equation", &E::equation, {}, kEquations, Shown::when_set},
    {"stale_after_s", &E::stale_after_s, above(0, 86400, "s")},
    {"on_stale", &E::on_stale, {}, kPolicies},
    {"fallback_temperature_degc", &E::fallback_temperature_degc, closed(-40, 100, "degC")},
    {"fallback_pressure_pa", &E::fallback_pressure_pa, closed(10e3, 140e3, "Pa")},
    {"fallback_humidity_pct", &E::fallback_humidity_pct, closed(0, 100, "%")},
    {"fallback_material_degc", &E::fallback_material_degc, closed(-50, 150, "degC")},
    {"co2_umol_per_mol", &E::co2_umol_per_mol, closed(0, 2000, "umol/mol")},
    {"wavelength_nm", &E::wavelength_nm, closed(300, 1700, "nm")},
    {"expansion_ppm_per_k", &E::expansion_ppm_per_k, closed(-100, 300, "ppm/K")},
};

const Field<T> kTrigger[] = {
    {"tolerance_um", &T::tolerance_um, above(0, 10'000, "um"), {}, Shown::always},
    {"dwell_s", &T::dwell_s, dwell, {}, Shown::always},
    {"window_mm", &T::window_mm, above(0, 1000, "mm"), {}, Shown::always},
};

const Field<L> kLinear[] = {
    {"axis", &L::axis, {}, kAxes, Shown::always},
    {"first_mm", &L::first_mm, position, {}, Shown::always},
    {"last_mm", &L::last_mm, position, {}, Shown::always},
    {"interval_mm", &L::interval_mm, above(0, kMaxPositionMm, "mm")},
    {"count", &L::count, closed(2, iso230_2::max_plan_targets, "")},
    {"random_fraction", &L::random_fraction, Range{0, 0.5, "", false, true}},
    {"cycle", &L::cycle, {}, kCycles},
    {"runs", &L::runs, closed(1, iso230_2::max_plan_runs, ""), {}, Shown::always},
    {"bidirectional", &L::bidirectional},
    {"overrun_mm", &L::overrun_mm, closed(0, 1000, "mm"), {}, Shown::always},
    {"feed_mm_per_min", &L::feed_mm_per_min, feed, {}, Shown::always},
    {"dwell_s", &L::dwell_s, dwell, {}, Shown::always},
    {"dead_path_mm", &L::dead_path_mm, closed(0, kMaxPositionMm, "mm")},
    {"standard", &L::standard, {}, {}, Shown::always},  // checked by cal::iso230_2
};

// In the TOML file these stand in [test.linear] itself; in the capture header they are an
// object "measure" beside the linear keys, where the kind is "kind".
const Field<M> kMeasure[] = {
    {.key = "measure", .member = &M::kind, .words = kKinds, .header_key = "kind"},
    {.key = "direction", .member = &M::direction},  // checked against the kind and axis
    {.key = "stationary_mm", .member = &M::stationary_mm, .range = position},
    {.key = "probe_offset_mm", .member = &M::probe_offset_mm, .range = position},
    {.key = "beams", .member = &M::beams, .range = closed(0, 2, "")},
    {.key = "separation_mm", .member = &M::separation_mm, .range = position},
    {.key = "sign", .member = &M::sign},  // 1 or -1: checked by the reader
    {.key = "square", .member = &M::square},
    {.key = "reference", .member = &M::reference},  // rotary only: checked by the reader
};

const Field<C> kCircle[] = {
    {"plane", &C::plane, {}, kPlanes, Shown::always},
    {"radius_mm", &C::radius_mm, above(0, 5000, "mm"), {}, Shown::always},
    {"feed_mm_per_min", &C::feed_mm_per_min, feed, {}, Shown::always},
    {"sample_rate_hz", &C::sample_rate_hz, above(0, 1e6, "Hz")},
    {"overshoot_deg", &C::overshoot_deg, closed(0, 180, "deg"), {}, Shown::always},
    {"centre_mm", &C::centre_mm, position},  // three numbers: checked by the reader
    {"calibrated_radius_mm", &C::calibrated_radius_mm, closed(0, 5000, "mm")},  // 0: not given
    {"standard", &C::standard},  // checked by cal::circle
    {"planes", &C::planes, {}, kPlanes},
    {"feeds_mm_per_min", &C::feeds_mm_per_min, feed},
    {"radii_mm", &C::radii_mm, above(0, 5000, "mm")},
    {"partial_arc_deg", &C::partial_arc_deg, closed(180, 360, "deg")},
    {"partial_overshoot_deg", &C::partial_overshoot_deg, closed(0, 45, "deg")},
    {"feed_in_mm", &C::feed_in_mm, above(0, 100, "mm")},
    {"dwell_s", &C::dwell_s, dwell},
    {.key = "bar", .member = &C::bar, .name = true},
};

}  // namespace

std::span<const Field<EnvironmentConfig>> environment() { return kEnvironment; }
std::span<const Field<TriggerConfig>> trigger() { return kTrigger; }
std::span<const Field<LinearTestConfig>> linear() { return kLinear; }
std::span<const Field<MeasureConfig>> measure() { return kMeasure; }
std::span<const Field<CircleTestConfig>> circle() { return kCircle; }

std::optional<std::string> range_error(const Range& r, double v) {
  if (!std::isfinite(v)) return fmt::format("{} is not a finite number", v);
  const bool low_ok = r.open_low ? v > r.lo : v >= r.lo;
  const bool high_ok = r.open_high ? v < r.hi : v <= r.hi;
  if (low_ok && high_ok) return std::nullopt;
  const std::string u = r.unit.empty() ? "" : " " + std::string(r.unit);
  if (r.open_low) return fmt::format("{} must be > {} and at most {}{}", v, r.lo, r.hi, u);
  if (r.open_high) return fmt::format("{} must be >= {} and < {}{}", v, r.lo, r.hi, u);
  return fmt::format("{} must be within {} .. {}{}", v, r.lo, r.hi, u);
}

std::optional<std::string> word_error(std::span<const std::string_view> words,
                                      std::string_view value) {
  if (words.empty() || std::find(words.begin(), words.end(), value) != words.end())
    return std::nullopt;
  return fmt::format("'{}' is not one of: {}", value, fmt::join(words, ", "));
}

std::optional<std::string> name_error(std::string_view value) {
  for (unsigned char c : value)
    if (c < 0x20 || c == 0x7f) return "control characters are not allowed";
  if (value.size() > 200) return fmt::format("{} bytes is too long", value.size());
  return std::nullopt;
}

std::string_view to_string(StalePolicy p) { return p == StalePolicy::stop ? "stop" : "fallback"; }

std::optional<StalePolicy> stale_policy(std::string_view word) {
  if (word == "stop") return StalePolicy::stop;
  if (word == "fallback") return StalePolicy::fallback;
  return std::nullopt;
}

}  // namespace cal::daq::fields
