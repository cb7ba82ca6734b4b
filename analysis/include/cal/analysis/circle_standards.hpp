#pragma once
// The circular-test standards caldaq can evaluate by, with what each defines and what could not
// be established from public material (docs/circle.md, "Standards"). The values themselves are
// computed once (cal::circle::analyse); a standard chooses which of them it reports and how it
// names them.
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cal::circle {

enum class CircularStandard {
  iso230_4_2005,    // G(b), G (each direction), F; the default
  gbt17421_4_2016,  // identical to ISO 230-4:2005 (IDT)
  iso230_4_1996,    // G (each direction), H, F: the first edition
};

// One value a standard reports, in the order a table shows them.
struct StandardValue {
  std::string key;      // the JSON key, e.g. "G_bi_um"
  std::string symbol;   // as the standard writes it, e.g. "G(b)"
  std::string meaning;  // e.g. "bi-directional circular deviation"
};

struct StandardInfo {
  CircularStandard id;
  std::string key;    // as given on the command line and in a configuration: "iso230-4:2005"
  std::string label;  // as printed and stored: "ISO 230-4:2005"
  std::string title;
  std::vector<std::string> identical;  // other standards with the same text, e.g. GB/T
  std::vector<StandardValue> values;   // what it reports (keys of cal::circle::Iso230_4)
  // What the standard defines that caldaq does not evaluate, and why.
  std::vector<std::string> not_evaluated;
  // caldaq's values that this standard does not define, shown apart as informative (e.g. H,
  // dropped by the 2005 edition), with why.
  std::vector<StandardValue> informative;
  std::string note;
};

const StandardInfo& info(CircularStandard s);
std::span<const StandardInfo> circular_standards();  // every one caldaq evaluates by

// "iso230-4:2005" (also "iso230-4"), "gb/t17421.4-2016" (also "gbt17421.4-2016", "gb/t17421.4"),
// "iso230-4:1996". Throws cal::InputError for an unknown key, and for a standard that is known
// but whose definitions could not be established from public material (ISO 230-4:2022,
// JIS B 6190-4, ASME B5.54, ASME B5.57), saying so and where the docs explain it.
CircularStandard circular_standard_from_key(std::string_view key);

}  // namespace cal::circle
