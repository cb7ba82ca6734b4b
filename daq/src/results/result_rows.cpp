#include "result_rows.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <utility>

#include "cal/analysis/circle_standards.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/fixed_text.hpp"
#include "cal/analysis/text.hpp"
#include "circle_output.hpp"
#include "iso230_2_output.hpp"
#include "unit_signs.hpp"

namespace daq {

using nlohmann::json;
namespace ci = cal::circle;

namespace {

std::string text_of(const json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}
double number_of(const json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : 0.0;
}

// Stored text (names, notes) made safe for a terminal (terminal.hpp says why).
std::string safe(std::string_view s) { return cal::text::terminal_safe(std::string(s)); }

// The circular standard of a document; a v1 document (no key) is ISO 230-4:2005.
const ci::StandardInfo& circle_standard(const json& doc) {
  try {
    return ci::info(ci::circular_standard_from_key(text_of(doc, "standard_key")));
  } catch (const cal::InputError&) {
    return ci::info(ci::CircularStandard::iso230_4_2005);
  }
}

// A result's rows (symbol, value in UNIT, description), then its warnings.
void print_rows_and_warnings(const std::vector<ResultRow>& rows, std::string_view unit,
                             const json& doc, std::string_view in) {
  for (const auto& r : rows)
    fmt::print("{}  {:<8} {:>10} {}   {}\n", in, safe(r.symbol), number_text(r.value), unit,
               safe(r.description));
  for (const auto& w : doc.value("warnings", json::array()))
    if (w.is_string()) fmt::print("{}warning: {}\n", in, safe(w.get<std::string>()));
}

void print_linear(const json& doc, std::string_view in) {
  const json standard = doc.value("standard", json::object());
  fmt::print("{}{} ({})\n", in, safe(text_of(standard, "title")), safe(text_of(standard, "note")));
  fmt::print("{}{} targets, {}, {}\n", in, doc.value("targets", json::array()).size(),
             safe(runs_text(doc)),
             doc.value("bidirectional", true) ? "bidirectional" : "unidirectional");
  print_rows_and_warnings(linear_rows(doc), "um", doc, in);
  for (const auto& n : doc.value("notes", json::array()))
    if (n.is_string()) fmt::print("{}note: {}\n", in, safe(n.get<std::string>()));
}

void print_circle_doc(const json& doc, std::string_view in) {
  fmt::print("{}{} circular test, plane {}, R = {:g} mm, feed {:g} mm/min\n", in,
             safe(text_of(doc, "standard")), safe(text_of(doc, "plane")),
             number_of(doc, "radius_mm"), number_of(doc, "feed_mm_per_min"));
  for (const auto& r : circle_rows(doc))
    fmt::print("{}  {:<18} {:>8} um   {}\n", in, safe(r.symbol), number_text(r.value),
               safe(r.description));
  const json iso = doc.value("iso230_4", json::object());
  if (const auto c = iso.find("centre_um"); c != iso.end() && c->is_array() && c->size() == 2)
    fmt::print("{}  {:<18} {:>8}, {} um   least-squares centre (set-up)\n", in, "centre",
               number_text((*c)[0].get<double>()), number_text((*c)[1].get<double>()));
  const json informative = doc.value("informative", json::object());
  for (const auto& x : circle_standard(doc).informative)  // in the standard's order
    if (const auto v = informative.find(x.key); v != informative.end() && v->is_object())
      fmt::print("{}  {:<18} {:>8} um   informative: {}\n", in, safe(x.symbol),
                 number_text(number_of(*v, "value")), safe(x.meaning));
  for (const auto& n : doc.value("not_evaluated", json::array()))
    if (n.is_string()) fmt::print("{}  not evaluated: {}\n", in, safe(n.get<std::string>()));
  const auto diagnostics = diagnostic_rows(doc);
  if (!diagnostics.empty()) {
    fmt::print(
        "\n{0}Diagnostics, ranked by G gain (how much G falls when that error alone is removed;\n"
        "{0}fix an error outside its limit, in the verdict, first, then the first here), with PV\n"
        "{0}(the peak-to-valley of the error's own pattern on the traces) and PV / G (caldaq's "
        "own\n{0}figure, can exceed 100 %; docs/circle.md):\n",
        in);
    fmt::print("{}  {:<48} {:>9} {:<5} {:>10} {:>7} {:>10}\n", in, "", "value", "", "PV", "PV / G",
               "G gain");
  }
  const json listed = doc.value("diagnostics", json::array());
  for (std::size_t i = 0; i < diagnostics.size() && i < listed.size(); ++i) {
    const auto& r = diagnostics[i];
    fmt::print("{}  {:<48} {:>9} {:<5} {:>7} um {:>5} % {:>7} um\n", in, safe(r.symbol),
               signed_number_text(r.value), safe(r.unit),
               number_text(number_of(listed[i], "pv_um")),
               number_text(number_of(listed[i], "share_pct"), 1),
               number_text(number_of(listed[i], "g_reduction_um")));
  }
  const json centre = doc.value("centre", json::object());
  for (const auto& [key, v] : centre.items())
    if (v.is_number())
      fmt::print("{}  {:<48} {:>9} um (set-up)\n", in,
                 safe(key.starts_with("centre_") ? "Centre offset " + key.substr(7) : key),
                 signed_number_text(v.get<double>()));
  if (doc.contains("residual_rms_um"))
    fmt::print("{}  residual rms {} um\n", in, number_text(number_of(doc, "residual_rms_um")));
  for (const auto& n : doc.value("notes", json::array()))
    if (n.is_string()) fmt::print("{}  note: {}\n", in, safe(n.get<std::string>()));
}

// A profile's values as every output prints them (the slope signed: its sign is the line's
// direction; the straightness and the range are spans).
std::string profile_value_text(const ResultRow& r) {
  return r.key == "slope_um_per_m" ? signed_number_text(r.value) : number_text(r.value);
}

void print_profile_doc(const json& doc, std::string_view in) {
  fmt::print("{}{} {} (ISO 230-1), {} targets, the mean of the stops at each\n", in,
             safe(text_of(doc, "kind")), safe(text_of(doc, "component")),
             doc.value("targets", json::array()).size());
  for (const auto& r : profile_rows(doc))
    fmt::print("{}  {:<12} {:>10} {:<4}   {}\n", in, safe(r.symbol), profile_value_text(r),
               safe(r.unit), safe(r.description));
}

}  // namespace

bool is_rotary_schema(std::string_view schema) { return schema == "caldaq.rotary.v1"; }

// A rotary axis's ISO 230-2 values (caldaq.rotary.v1): in arcsec, in the order evaluated.
std::vector<ResultRow> rotary_rows(const json& doc) {
  if (doc.contains("values")) return linear_rows(doc);  // in the evaluation's order, in arcsec
  std::vector<ResultRow> rows;
  const json axis = doc.value("axis", json::object());  // held: items() refers into it
  for (const auto& [key, a] : axis.items())
    if (a.is_object())
      rows.push_back(
          {key, text_of(a, "symbol"), text_of(a, "description"), number_of(a, "value"), "arcsec"});
  return rows;
}

void print_rotary_doc(const json& doc, std::string_view in) {
  fmt::print("{}{} {} (targets in deg, deviations in arcsec)\n", in, safe(text_of(doc, "title")),
             safe(text_of(doc, "component")));
  fmt::print("{}{} targets, {} runs per direction, {}\n", in,
             doc.value("targets", json::array()).size(), number_of(doc, "runs"),
             doc.value("bidirectional", true) ? "bidirectional" : "unidirectional");
  print_rows_and_warnings(rotary_rows(doc), "arcsec", doc, in);
}

namespace {

bool is_ballbar5x_schema(std::string_view schema) { return schema == "caldaq.ballbar5x.v1"; }

// A five-axis ballbar run's location errors (caldaq.ballbar5x.v1, runner/ballbar5x_run.hpp):
// each axis's four, in um and urad, with their standard uncertainty in the description.
std::vector<ResultRow> ballbar5x_rows(const json& doc) {
  std::vector<ResultRow> rows;
  for (const auto& a : doc.value("axes", json::array())) {
    const json loc = a.value("location", json::object());
    for (const auto& n : a.value("names", json::array())) {  // ISO 230-1's order
      const std::string name = n.is_string() ? n.get<std::string>() : std::string();
      if (!loc.contains(name)) continue;
      const json& v = loc[name];
      rows.push_back(
          {name, name,
           fmt::format("location error of the {} axis, u = {} (k = 1); left against "
                       "the control's: {}",
                       safe(text_of(a, "axis")), number_text(number_of(v, "uncertainty"), 3),
                       signed_number_text(number_of(v, "left"), 3)),
           number_of(v, "value"), text_of(v, "unit")});
    }
  }
  return rows;
}

void print_ballbar5x_doc(const json& doc, std::string_view in) {
  fmt::print(
      "{}five-axis ballbar: the rotary axes' location errors (fitted to the bar's mean "
      "reading at each stop)\n",
      in);
  for (const auto& a : doc.value("axes", json::array()))
    fmt::print("{}axis {}: {} tests, residual RMS {} um, sigma {} um\n", in,
               safe(text_of(a, "axis")), a.value("tests", json::array()).size(),
               number_text(number_of(a, "rms_um"), 3), number_text(number_of(a, "sigma_um"), 3));
  for (const auto& r : ballbar5x_rows(doc))
    fmt::print("{}  {:<8} {:>10} {:<4}  {}\n", in, safe(r.symbol), signed_number_text(r.value, 3),
               safe(r.unit), r.description);
}

}  // namespace

std::string number_text(double value, int decimals) { return cal::fixed_text(value, decimals); }

std::string signed_number_text(double value, int decimals) {
  const std::string s = number_text(value, decimals);
  return s.front() == '-' || s.find_first_not_of("0.") == std::string::npos ? s : "+" + s;
}

std::span<const std::pair<std::string_view, std::string_view>> unit_signs() {
  // "urad": an angular or roll run's unit. Longest first: "um/m" is not "um" and "/m".
  static constexpr std::pair<std::string_view, std::string_view> signs[] = {
      {"um/m", "µm/m"}, {"um", "µm"}, {"urad", "µrad"}, {"degC", "°C"}};
  return signs;
}

std::string unit_signs_json() {
  json a = json::array();
  for (const auto& [ascii, sign] : unit_signs()) a.push_back({ascii, sign});
  return a.dump();
}

std::string unit_html(std::string_view unit) {
  for (const auto& [ascii, sign] : unit_signs())
    if (unit == ascii) return std::string(sign);
  return std::string(unit);
}

std::string units_html(std::string_view text) {
  const auto units = unit_signs();
  const auto word_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; };
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const bool starts_word = i == 0 || !word_char(text[i - 1]);
    bool replaced = false;
    for (const auto& [from, to] : units) {
      const std::size_t end = i + from.size();
      if (starts_word && text.substr(i, from.size()) == from &&
          (end == text.size() || !word_char(text[end]))) {
        out += to, i = end, replaced = true;
        break;
      }
    }
    if (!replaced) out += text[i++];
  }
  return out;
}

std::size_t linear_order(std::string_view key) {
  static constexpr std::string_view order[] = {"E_up",   "E_down", "E_bi", "R_up",
                                               "R_down", "R_bi",   "A_up", "A_down",
                                               "A_bi",   "M",      "B",    "B_mean"};
  const auto* at = std::find(std::begin(order), std::end(order), key);
  return static_cast<std::size_t>(at - std::begin(order));
}

std::vector<ResultRow> linear_rows(const json& doc) {
  std::vector<ResultRow> rows;
  // The values in their evaluation's order (a json object is read by key: "values" keeps the
  // order where the document has it, else the evaluation's keys as stored).
  if (const auto v = doc.find("values"); v != doc.end() && v->is_array()) {
    for (const auto& r : *v)
      rows.push_back({text_of(r, "key"), text_of(r, "symbol"), text_of(r, "description"),
                      number_of(r, "value"), text_of(r, "unit")});
  } else {
    // A named copy: items() of a temporary dangles in the range-for.
    const json axis = doc.value("axis", json::object());
    for (const auto& [key, a] : axis.items())
      rows.push_back(
          {key, a.value("symbol", key), text_of(a, "description"), number_of(a, "value_um"), "um"});
  }
  std::stable_sort(rows.begin(), rows.end(), [](const ResultRow& a, const ResultRow& b) {
    return linear_order(a.key) < linear_order(b.key);
  });
  return rows;
}

std::vector<ResultRow> circle_rows(const json& doc) {
  std::vector<ResultRow> rows;
  const json iso = doc.value("iso230_4", json::object());
  for (const auto& v : circle_standard(doc).values)
    if (const auto it = iso.find(v.key); it != iso.end() && it->is_number())
      rows.push_back({v.key, v.symbol, v.meaning, it->get<double>(), "um"});
  return rows;
}

std::vector<ResultRow> diagnostic_rows(const json& doc) {
  std::vector<ResultRow> rows;
  for (const auto& d : doc.value("diagnostics", json::array()))
    rows.push_back({text_of(d, "key"), text_of(d, "name"), diagnostic_advice(text_of(d, "key")),
                    number_of(d, "value"), text_of(d, "unit")});
  return rows;
}

bool is_profile_schema(std::string_view schema) { return schema == "caldaq.profile.v1"; }

std::vector<ResultRow> profile_rows(const json& doc) {
  const std::string kind = text_of(doc, "kind"), component = text_of(doc, "component");
  const std::string unit = text_of(doc, "unit");
  std::vector<ResultRow> rows;
  if (kind == "straightness") {
    if (doc.contains("straightness_um"))
      rows.push_back({"straightness_um", component,
                      "straightness: the range of the means about the least-squares line",
                      number_of(doc, "straightness_um"), "um"});
    if (doc.contains("slope_um_per_m"))
      rows.push_back({"slope_um_per_m", "slope",
                      "of the least-squares line (the straightedge's alignment, removed)",
                      number_of(doc, "slope_um_per_m"), "um/m"});
    rows.push_back(
        {"range", "range", "of the means, no line removed", number_of(doc, "range"), unit});
  } else {
    rows.push_back({"range", component, "angular deviation: the range of the means",
                    number_of(doc, "range"), unit});
  }
  return rows;
}

std::vector<ResultRow> result_rows(const json& doc) {
  if (is_profile_schema(doc.value("schema", ""))) return profile_rows(doc);
  if (is_rotary_schema(doc.value("schema", ""))) return rotary_rows(doc);
  if (is_ballbar5x_schema(doc.value("schema", ""))) return ballbar5x_rows(doc);
  if (!is_circle_schema(doc.value("schema", ""))) return linear_rows(doc);
  auto rows = circle_rows(doc);
  for (auto& d : diagnostic_rows(doc)) rows.push_back(std::move(d));
  return rows;
}

json rows_json(const std::vector<ResultRow>& rows) {
  json j = json::array();
  for (const auto& r : rows)
    j.push_back({{"key", r.key},
                 {"symbol", r.symbol},
                 {"description", r.description},
                 {"value", r.value},
                 {"unit", r.unit}});
  return j;
}

void print_result(const json& doc, std::string_view indent) {
  if (is_profile_schema(doc.value("schema", "")))
    print_profile_doc(doc, indent);
  else if (is_rotary_schema(doc.value("schema", "")))
    print_rotary_doc(doc, indent);
  else if (is_ballbar5x_schema(doc.value("schema", "")))
    print_ballbar5x_doc(doc, indent);
  else if (is_circle_schema(doc.value("schema", "")))
    print_circle_doc(doc, indent);
  else
    print_linear(doc, indent);
}

}  // namespace daq
