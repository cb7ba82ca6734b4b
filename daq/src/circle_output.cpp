#include "circle_output.hpp"

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
  for (const auto& d : r.diagnostics)
    j["diagnostics"].push_back({{"key", d.key},
                                {"name", d.name},
                                {"value", d.value},
                                {"unit", d.unit},
                                {"pv_um", d.pv_um},
                                {"share_pct", d.share_pct},
                                {"g_reduction_um", d.g_reduction_um}});
  j["centre"] = {{r.centre_u.key, r.centre_u.value}, {r.centre_v.key, r.centre_v.value}};
  return j;
}

}  // namespace daq
