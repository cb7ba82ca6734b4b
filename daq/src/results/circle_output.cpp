#include "circle_output.hpp"

#include <fmt/format.h>

#include <utility>

#include "result_rows.hpp"

namespace daq {

using nlohmann::json;
namespace ci = cal::circle;

bool is_circle_schema(std::string_view schema) {
  return schema == "caldaq.circle.v1" || schema == circle_schema;
}

double iso_value(const ci::Iso230_4& iso, std::string_view key) {
  if (key == "G_bi_um") return iso.G_bi_um;
  if (key == "G_cw_um") return iso.G_cw_um;
  if (key == "G_ccw_um") return iso.G_ccw_um;
  if (key == "H_um") return iso.H_um;
  if (key == "F_max_um") return iso.F_max_um;
  if (key == "F_min_um") return iso.F_min_um;
  return 0.0;
}

json circle_json(const ci::Result& r, double radius_mm, std::string_view plane,
                 double feed_mm_per_min, ci::CircularStandard standard) {
  const auto& st = ci::info(standard);
  json iso = json::object();
  for (const auto& v : st.values) iso[v.key] = iso_value(r.iso, v.key);
  iso["centre_um"] = {r.iso.centre_u_um, r.iso.centre_v_um};
  iso["arc_deg"] = r.iso.arc_deg;
  json informative = json::object();
  for (const auto& v : st.informative)
    informative[v.key] = {
        {"value", iso_value(r.iso, v.key)}, {"symbol", v.symbol}, {"about", v.meaning}};
  json j{{"schema", circle_schema},
         {"standard", st.label},
         {"standard_key", st.key},
         {"identical_standards", st.identical},
         {"radius_mm", radius_mm},
         {"feed_mm_per_min", feed_mm_per_min},
         {"plane", plane},
         {"iso230_4", iso},
         {"informative", informative},
         {"not_evaluated", st.not_evaluated},
         {"residual_rms_um", r.residual_rms_um},
         {"notes", r.notes}};
  if (r.cyclic_period_mm) j["cyclic_period_mm"] = *r.cyclic_period_mm;
  j["diagnostics"] = json::array();
  for (const auto& d : r.diagnostics) {
    json dj{{"key", d.key},
            {"name", d.name},
            {"value", d.value},
            {"unit", d.unit},
            {"pv_um", d.pv_um},
            {"share_pct", d.share_pct},
            {"g_reduction_um", d.g_reduction_um}};
    if (d.frequency_hz) dj["frequency_hz"] = *d.frequency_hz;
    j["diagnostics"].push_back(std::move(dj));
  }
  j["centre"] = {{r.centre_u.key, r.centre_u.value}, {r.centre_v.key, r.centre_v.value}};
  j["values"] = rows_json(result_rows(j));  // as every output lists them (result_rows.hpp)
  return j;
}

std::string diagnostic_advice(std::string_view key) {
  // A term of one axis: its key ends in the axis' letter ("backlash_X"); the advice names it.
  struct AxisAdvice {
    std::string_view prefix, before, after;
  };
  static constexpr AxisAdvice kAxisTerms[] = {
      {"backlash_", "check the ", " axis' backlash compensation and its drive (ball screw, nut)"},
      {"lateral_play_", "check the ",
       " axis' guideway gibs and preload: it shifts sideways at reversal"},
      {"reversal_spike_", "tune the ",
       " axis' reversal (friction) compensation and its servo gains"},
      {"cyclic_", "check the ", " axis' ball screw and encoder for a periodic (pitch) error"},
      {"straightness_", "check the straightness of the ", " axis' guideways (level, wear)"},
      {"stick_slip_", "check the ", " axis' lubrication and friction compensation"},
  };
  // The plane's terms.
  static constexpr std::pair<std::string_view, std::string_view> kPlaneTerms[] = {
      {"squareness",
       "check the squareness of the plane's axes (alignment, or the control's squareness "
       "compensation)"},
      {"scale_mismatch",
       "check the axes' pitch (scale) compensation and thermal growth of the screws"},
      {"servo_mismatch", "match the two axes' servo gains (position loop, feed-forward)"},
      {"radius_error", "check the bar's calibration and the axes' scale"},
      {"vibration", "look for the source of the vibration (spindle, fan, floor)"},
  };
  const std::string axis =
      key.size() > 2 && key[key.size() - 2] == '_' ? std::string(1, key.back()) : std::string();
  // Only the prefix then the axis letter: "straightness_um" (a straightness run's limit) is no
  // circle term and gets no advice.
  for (const auto& t : kAxisTerms)
    if (!axis.empty() && key.size() == t.prefix.size() + 1 && key.starts_with(t.prefix))
      return std::string(t.before) + axis + std::string(t.after);
  for (const auto& [term, advice] : kPlaneTerms)
    if (key == term) return std::string(advice);
  return "";  // not a diagnostic (a value of the standard, e.g. G)
}

void print_circle(const ci::Result& r, double radius_mm, std::string_view plane,
                  double feed_mm_per_min, ci::CircularStandard standard) {
  print_result(circle_json(r, radius_mm, plane, feed_mm_per_min, standard));
}

}  // namespace daq
