#include "serve/volumetric_checklist.hpp"

#include <fmt/format.h>

#include <array>
#include <map>
#include <string_view>

#include "cal/analysis/error.hpp"
#include "cal/storage/store.hpp"
#include "model/stored_model.hpp"

namespace daq::serve {
namespace {
using nlohmann::json;

// A word for a POSIX shell: single-quoted, a quote in it closed, escaped and reopened.
std::string shell_word(std::string_view s) {
  std::string out = "'";
  for (const char ch : s) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}

// The walkthrough's order: each axis' angles, then its positioning and straightness.
constexpr std::array<std::string_view, 18> kComponents{
    "E_BX", "E_CX", "E_AX", "E_AY", "E_CY", "E_BY", "E_AZ", "E_BZ", "E_CZ",
    "E_XX", "E_YX", "E_ZX", "E_YY", "E_XY", "E_ZY", "E_ZZ", "E_XZ", "E_YZ"};

// What a component's test is, from its name E_<error><moving axis> (docs/kinematics.md).
json setup_of(std::string_view c) {
  const std::string error(1, c[2]), axis(1, c[3]);
  const bool angle = error == "A" || error == "B" || error == "C";
  const bool own = angle ? (error == "A" && axis == "X") || (error == "B" && axis == "Y") ||
                               (error == "C" && axis == "Z")
                         : error == axis;
  const char* kind = angle ? (own ? "roll" : "angular") : own ? "positioning" : "straightness";
  const char* instrument = std::string_view(kind) == "straightness" ? "indicator"
                           : std::string_view(kind) == "roll"       ? "level"
                                                                    : "laser";
  return {{"component", c},
          {"kind", kind},
          {"axis", axis},
          {"direction", error},
          {"instrument", instrument}};
}

struct Plane {
  const char* name;
  const char* error;
  std::array<const char*, 2> straightness;
};
constexpr std::array<Plane, 3> kPlanes{{{"XY", "E_C0Y", {"E_YX", "E_XY"}},
                                        {"ZX", "E_B0Z", {"E_ZX", "E_XZ"}},
                                        {"YZ", "E_A0Z", {"E_ZY", "E_YZ"}}}};
}  // namespace

json volumetric_checklist(const cal::storage::Store* store, const std::string& machine,
                          const std::string& database) {
  StoredProfiles stored;
  std::string note;
  if (store) {
    try {
      stored = stored_profiles(*store, machine);
    } catch (const cal::InputError& e) {
      note = e.what();  // no run of this machine yet: everything is to do
    }
  }
  std::map<std::string, const cal::daq::model::MeasuredProfile*> by_component;
  for (const auto& p : stored.profiles) by_component[p.component] = &p;
  json tests = json::array();
  std::map<std::string, json> days;  // "2026-11-28" -> components
  for (const auto c : kComponents) {
    json t = setup_of(c);
    const auto it = by_component.find(std::string(c));
    if (it == by_component.end()) {
      t["run"] = nullptr;
    } else {
      const auto& p = *it->second;
      t["run"] = p.run_id;
      t["started_utc"] = p.started_utc;
      t["stationary_mm"] = p.stationary_mm;
      t["probe_offset_mm"] = p.probe_offset_mm;
      t["square"] = p.square;
      t["targets"] = p.position_mm.size();
      days[p.started_utc.substr(0, 10)].push_back(std::string(c));
    }
    tests.push_back(std::move(t));
  }
  json squareness = json::array();
  for (const auto& pl : kPlanes) {
    json runs = json::array();
    bool square = true;
    for (const auto* s : pl.straightness) {
      const auto it = by_component.find(s);
      if (it == by_component.end()) continue;
      runs.push_back(it->second->run_id);
      square = square && it->second->square;
    }
    squareness.push_back({{"plane", pl.name},
                          {"error", pl.error},
                          {"from", pl.straightness},
                          {"runs", runs},
                          {"measured", runs.size() == 2 && square},
                          {"square", square}});
  }
  json day_list = json::array();
  for (auto& [day, list] : days) day_list.push_back({{"day", day}, {"components", list}});
  std::size_t done = 0;
  for (const auto& t : tests) done += t["run"].is_null() ? 0 : 1;
  for (const auto& s : squareness) done += s["measured"].get<bool>() ? 1 : 0;
  return {{"schema", "caldaq.volumetric-checklist.v1"},
          {"machine", machine},
          {"tests", tests},
          {"squareness", squareness},
          {"measured", done},
          {"of", 21},
          {"days", day_list},
          {"skipped", stored.skipped},
          {"note", note},
          {"build", fmt::format("daq model build --machine {} --db {} -o model.json",
                                shell_word(machine), shell_word(database))},
          {"map", "daq model map model.json"}};
}

}  // namespace daq::serve
