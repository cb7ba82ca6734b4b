#include "circle_output.hpp"

#include <fmt/format.h>

namespace daq {

using nlohmann::json;

json circle_json(const cal::circle::Result& r, double radius_mm, std::string_view plane,
                 double feed_mm_per_min) {
  json j{{"schema", "caldaq.circle.v1"},
         {"standard", "ISO 230-4:2005"},
         {"radius_mm", radius_mm},
         {"feed_mm_per_min", feed_mm_per_min},
         {"plane", plane},
         {"iso230_4",
          {{"G_bi_um", r.iso.G_bi_um},
           {"G_cw_um", r.iso.G_cw_um},
           {"G_ccw_um", r.iso.G_ccw_um},
           {"H_um", r.iso.H_um},
           {"F_max_um", r.iso.F_max_um},
           {"F_min_um", r.iso.F_min_um},
           {"centre_um", {r.iso.centre_u_um, r.iso.centre_v_um}},
           {"arc_deg", r.iso.arc_deg}}},
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
  return j;
}

void print_circle(const cal::circle::Result& r, double radius_mm, std::string_view plane,
                  double feed_mm_per_min) {
  fmt::print("ISO 230-4 circular test, plane {}, R = {} mm, feed {} mm/min\n", plane, radius_mm,
             feed_mm_per_min);
  fmt::print("  G (bidirectional)  {:8.3f} um\n", r.iso.G_bi_um);
  if (r.iso.G_ccw_um > 0) fmt::print("  G ccw              {:8.3f} um\n", r.iso.G_ccw_um);
  if (r.iso.G_cw_um > 0) fmt::print("  G cw               {:8.3f} um\n", r.iso.G_cw_um);
  fmt::print("  H                  {:8.3f} um\n", r.iso.H_um);
  fmt::print("  F max / min        {:8.3f} / {:.3f} um\n", r.iso.F_max_um, r.iso.F_min_um);
  fmt::print("  LSQ centre         {:8.3f}, {:.3f} um\n\n", r.iso.centre_u_um, r.iso.centre_v_um);
  fmt::print(
      "Diagnostics, ranked by PV (the peak-to-valley of the error's own pattern on the traces),\n"
      "with PV / G (the share of G; caldaq's own figure, can exceed 100 %) and G gain (how much\n"
      "G falls when that error alone is removed; docs/circle.md):\n");
  fmt::print("  {:<40} {:>9} {:<5} {:>10} {:>7} {:>10}\n", "", "value", "", "PV", "PV / G",
             "G gain");
  for (const auto& d : r.diagnostics)
    fmt::print("  {:<40} {:+9.3f} {:<5} {:7.3f} um {:5.1f} % {:7.3f} um\n", d.name, d.value, d.unit,
               d.pv_um, d.share_pct, d.g_reduction_um);
  fmt::print("  {:<40} {:+9.3f} um (set-up)\n", r.centre_u.name, r.centre_u.value);
  fmt::print("  {:<40} {:+9.3f} um (set-up)\n", r.centre_v.name, r.centre_v.value);
  fmt::print("  residual rms {:.3f} um\n", r.residual_rms_um);
  for (const auto& n : r.notes) fmt::print("  note: {}\n", n);
}

}  // namespace daq
