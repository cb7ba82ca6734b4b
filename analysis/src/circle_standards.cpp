// Circular-test standards (see circle_standards.hpp). Sources, per standard, in docs/circle.md
// ("Standards"): only catalogue pages, scopes and forewords were available, never a full text.
#include "cal/analysis/circle_standards.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>

#include "cal/analysis/error.hpp"

namespace cal::circle {
namespace {

// The mean bi-directional radial deviation is named in the scope of the 2005 edition (AFNOR and
// UNI catalogue pages) but its definition was not in any public text found.
const char* mean_radial =
    "mean bi-directional radial deviation: named in the standard's scope, but its definition "
    "could not be established from public material, so it is not evaluated (docs/circle.md)";

StandardValue g_bi{"G_bi_um", "G(b)", "bi-directional circular deviation"};
StandardValue g_ccw{"G_ccw_um", "G (ccw)", "circular deviation, counter-clockwise"};
StandardValue g_cw{"G_cw_um", "G (cw)", "circular deviation, clockwise"};
StandardValue f_max{"F_max_um", "F max", "largest radial deviation from the nominal radius"};
StandardValue f_min{"F_min_um", "F min", "smallest radial deviation from the nominal radius"};
StandardValue h{"H_um", "H", "circular hysteresis"};

const std::array<StandardInfo, 3>& table() {
  static const std::array<StandardInfo, 3> t = {
      StandardInfo{
          .id = CircularStandard::iso230_4_2005,
          .key = "iso230-4:2005",
          .label = "ISO 230-4:2005",
          .title = "Test code for machine tools - Part 4: Circular tests for numerically "
                   "controlled machine tools (2nd edition)",
          .identical = {"GB/T 17421.4-2016"},
          .values = {g_bi, g_ccw, g_cw, f_max, f_min},
          .not_evaluated = {mean_radial},
          .informative = {{"H_um", "H",
                           "circular hysteresis of ISO 230-4:1996; the 2005 edition replaced it "
                           "by G(b)"}},
          .note = "GB/T 17421.4-2016 is an identical adoption (IDT) and gives the same values"},
      StandardInfo{.id = CircularStandard::gbt17421_4_2016,
                   .key = "gb/t17421.4-2016",
                   .label = "GB/T 17421.4-2016",
                   .title = "Test code for machine tools - Part 4: Circular tests for numerically "
                            "controlled machine tools (identical to ISO 230-4:2005)",
                   .identical = {"ISO 230-4:2005"},
                   .values = {g_bi, g_ccw, g_cw, f_max, f_min},
                   .not_evaluated = {mean_radial},
                   .informative = {{"H_um", "H",
                                    "circular hysteresis of ISO 230-4:1996; not a quantity of GB/T "
                                    "17421.4-2016 (= ISO 230-4:2005)"}},
                   .note = "an identical adoption (IDT) of ISO 230-4:2005"},
      StandardInfo{
          .id = CircularStandard::iso230_4_1996,
          .key = "iso230-4:1996",
          .label = "ISO 230-4:1996",
          .title = "Test code for machine tools - Part 4: Circular tests for numerically "
                   "controlled machine tools (1st edition, withdrawn)",
          .identical = {},
          .values = {g_ccw, g_cw, h, f_max, f_min},
          .not_evaluated = {},
          .informative = {{"G_bi_um", "G(b)",
                           "bi-directional circular deviation of ISO 230-4:2005; not a quantity "
                           "of the 1996 edition"}},
          .note = "withdrawn: replaced by ISO 230-4:2005. H is caldaq's reading of the circular "
                  "hysteresis (the largest radial difference of the two directions at one "
                  "angle, about one centre): the 1996 text was not available"},
  };
  return t;
}

std::string normalised(std::string_view key) {
  std::string out;
  for (char c : key)
    if (c != ' ' && c != '_') out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

const StandardInfo& info(CircularStandard s) {
  for (const auto& i : table())
    if (i.id == s) return i;
  return table().front();
}

std::span<const StandardInfo> circular_standards() { return table(); }

CircularStandard circular_standard_from_key(std::string_view key) {
  const std::string k = normalised(key);
  if (k == "iso230-4:2005" || k == "iso230-4") return CircularStandard::iso230_4_2005;
  if (k == "gb/t17421.4-2016" || k == "gbt17421.4-2016" || k == "gb/t17421.4" || k == "gbt17421.4")
    return CircularStandard::gbt17421_4_2016;
  if (k == "iso230-4:1996") return CircularStandard::iso230_4_1996;
  const auto refuse = [&](const char* why) {
    throw InputError(
        fmt::format("circular standard '{}': {} (docs/circle.md, \"Standards\")", key, why));
  };
  if (k == "iso230-4:2022")
    refuse(
        "its public scope renames the quantities (\"error\" for \"deviation\") and adds rotary "
        "axes, but whether the definitions changed could not be established; evaluate by "
        "iso230-4:2005");
  if (k.starts_with("jisb6190-4") || k.starts_with("jis-b6190-4") || k.starts_with("jis"))
    refuse("no public text of JIS B 6190-4 was found (not even its year or adoption degree)");
  if (k.starts_with("asme"))
    refuse(
        "only the scopes of ASME B5.54-2005 and B5.57-2012 are public; their circular-test "
        "quantities could not be established");
  throw InputError(fmt::format(
      "circular standard '{}' (expected iso230-4:2005, gb/t17421.4-2016 or iso230-4:1996)", key));
}

}  // namespace cal::circle
