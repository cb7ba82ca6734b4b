// CMM points of the test piece (CSV feature,x_mm,y_mm, `daq model testpiece --cmm`) on arbitrary
// text: results that are all finite, or cal::InputError naming the file, line or feature (no
// rows, a point 100 m away, bore points on one side). Never a crash, a hang or another
// exception.
#include <cmath>
#include <string_view>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/analysis/testpiece.hpp"
#include "csv_columns.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace tp = cal::testpiece;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto csv = daq::parse_csv_columns(text, "fuzz.csv", {"x_mm", "y_mm"}, {"feature"});
    std::vector<tp::Point> pts;
    for (std::size_t r = 0; r < csv.rows(); ++r)
      pts.push_back(
          {csv.texts.at("feature")[r], csv.numbers.at("x_mm")[r], csv.numbers.at("y_mm")[r]});
    const tp::Layout layout;
    const auto result = tp::evaluate(layout, tp::measured_profiles(layout, pts));
    for (const auto& f : result.faces)
      if (!std::isfinite(f.straightness_um)) __builtin_trap();
    for (const auto& b : result.bores)
      if (!std::isfinite(b.circularity_um) || !std::isfinite(b.position_x_um) ||
          !std::isfinite(b.position_y_um))
        __builtin_trap();
    for (const auto& [name, v] : result.squareness_um_per_m)
      if (!std::isfinite(v)) __builtin_trap();
  } catch (const cal::InputError&) {
  }
  return 0;
}
