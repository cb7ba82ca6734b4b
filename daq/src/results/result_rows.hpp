#pragma once
// One presentation of each result (issue 30): the rows of a result document (caldaq.iso230-2.v1,
// caldaq.circle.v1/v2, caldaq.profile.v1) in one order, with one name, unit and rounding, read by
// every output: the terminal (daq run, replay, recompensate, analyse and show print the same
// block), the JSON (its "values" array), and the reports (their tables, the campaign summary, the
// comparison). Numbers are printed to 0.001 of their unit (the verdict compares the value as
// printed) and never read
// "-0.000".
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace daq {

struct ResultRow {
  std::string key;          // the document's key: "E_bi", "G_bi_um", "squareness"
  std::string symbol;       // as printed: "E", "E↑", "G(b)", "Squareness XY"
  std::string description;  // "bidirectional systematic positional deviation"
  double value = 0.0;
  std::string unit;  // "um", "um/m", "ms"
};

// A number to `decimals` places; a value that rounds to zero is 0 ("0.000", never "-0.000").
std::string number_text(double value, int decimals = 3);
// The same with its sign: "+1.234", "-0.500", "0.000".
std::string signed_number_text(double value, int decimals = 3);
// A unit as a terminal prints it ("um") and as a page does ("µm").
std::string unit_html(std::string_view unit);
// A sentence of caldaq's own (a run's quality, an uncertainty's model) as a document prints
// it: the terminal's unit words ("um", "um/m", "urad", "degC") as µm, µm/m, µrad, °C.
std::string units_html(std::string_view text);

// The rank of an ISO 230-2 value on every output: as the report's grid reads, row by row (E↑,
// E↓, E; R↑, R↓, R; A↑, A↓, A; M, B, B̄), then any other in its evaluation's order.
std::size_t linear_order(std::string_view key);

// The values of a linear evaluation (caldaq.iso230-2.v1) in that order.
std::vector<ResultRow> linear_rows(const nlohmann::json& doc);
// The values of a circular test's standard (caldaq.circle.v1/v2), in the standard's order
// (G(b), G ccw, G cw, F max, F min...); a v1 document in ISO 230-4:2005's order.
std::vector<ResultRow> circle_rows(const nlohmann::json& doc);
// The diagnostics of a circular test as ranked (by what correcting each would gain).
std::vector<ResultRow> diagnostic_rows(const nlohmann::json& doc);
// Whether a document is the profile of a straightness, angular (pitch, yaw) or roll run
// (caldaq.profile.v1, runner/kinds/kind.hpp).
bool is_profile_schema(std::string_view schema);
// A rotary axis's ISO 230-2 evaluation (caldaq.rotary.v1: targets in deg, values in arcsec).
bool is_rotary_schema(std::string_view schema);
// The ISO 230-1 values of a profile: a straightness run's straightness about the least-squares
// line, that line's slope and the range; an angular or roll run's angular deviation (the range
// of its target means).
std::vector<ResultRow> profile_rows(const nlohmann::json& doc);
// The rows of any result document: linear_rows, profile_rows, or circle_rows then
// diagnostic_rows.
std::vector<ResultRow> result_rows(const nlohmann::json& doc);

// The rows as JSON, for the document's "values" array.
nlohmann::json rows_json(const std::vector<ResultRow>& rows);

// The block every terminal output prints of a result document (daq run, replay, recompensate,
// analyse, show), each line led by `indent`; stored text in it is made terminal-safe.
void print_result(const nlohmann::json& doc, std::string_view indent = "");

}  // namespace daq
