#pragma once
// Pass/fail of a result against the machine's specification (the tolerances of the run's
// context, docs/config.md): each limited value, and the run as a whole. Simple acceptance:
// the measured value as printed (0.001 of its unit) against the limit; the expanded
// uncertainty is shown beside it in the report but no ISO 14253-1 guard band is applied.
// Where no limit applies, the verdict says "no tolerance configured", never a pass.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace daq {

struct Check {
  std::string key;     // the result's key: "E_bi", "G_bi_um", "squareness"
  std::string symbol;  // as printed: "E", "G", "Squareness XY"
  double value = 0.0;  // signed, in `unit`
  double limit = 0.0;  // on the magnitude
  std::string unit;    // "um", "um/m", "ms"
  bool pass = false;
};

struct Verdict {
  bool configured = false;  // at least one limit applied
  bool pass = false;        // every check passed (false when not configured)
  std::string basis;        // e.g. "tolerances.X (travel up to 500 mm)"
  std::vector<Check> checks;
  std::vector<std::string> notes;  // limits that could not be applied, and why
  // With no limit and no note: where the limits that would judge it are given (to_text of
  // limits_where; run_verdict fills it), else empty.
  std::string hint;
};

// Where the limits that would judge a run are given (docs/config.md), for a verdict that has
// none: the limits in force when a run starts are stored with it, so no limit was stored with
// this one. The keys, the tables they go under, and the file that holds those tables.
struct LimitsWhere {
  std::vector<std::string> keys;  // "E_um", ...; a five-axis ballbar run's location_um, _urad
  // What each key judges, when each judges values of its own (a five-axis ballbar run's:
  // "each position", "each tilt"); empty: any one of the keys judges the run.
  std::vector<std::string> each;
  std::vector<std::string> tables;  // "tolerances.X"; a five-axis ballbar run's, one per axis
  // The option of the command that made the run whose file holds the tables ("daq model
  // ballbar5x-run --tolerances"); "" when the run's configuration does.
  std::string option;
  std::string configuration;  // the configuration the run was made with ("" when unrecorded)
};

// tolerances: the run context's "tolerances" (null when none); result: a caldaq.iso230-2.v1
// or caldaq.circle.v1 document.
Verdict linear_verdict(const nlohmann::json& tolerances, const nlohmann::json& result);
Verdict circle_verdict(const nlohmann::json& tolerances, const nlohmann::json& result);
// A straightness, angular or roll profile (caldaq.profile.v1) against the axis's
// straightness_um or angular_urad (docs/config.md).
Verdict profile_verdict(const nlohmann::json& tolerances, const nlohmann::json& result);
// A five-axis ballbar run (caldaq.ballbar5x.v1) against each rotary axis's location_um and
// location_urad ([tolerances.C] ...): the magnitude of each location error left.
Verdict ballbar5x_verdict(const nlohmann::json& tolerances, const nlohmann::json& result);
// The verdict of a result of a stored run by its settings (the context's tolerances).
Verdict verdict_of(const nlohmann::json& settings, const nlohmann::json& result);
// Where the limits of a run of `kind` on `axis` are given: `kind` and `axis` the stored run's (a
// circle's axis is its plane, a five-axis ballbar run's the axes it tested, "CA"); `settings`
// its stored settings (the context's configuration); `result` its result (a VDI/DGQ 3441
// evaluation is judged by P_um, ...).
LimitsWhere limits_where(std::string_view kind, std::string_view axis,
                         const nlohmann::json& settings, const nlohmann::json& result);
// How to_text marks what it quotes: a key, a table or an option (`code`), a file's name
// (`path`), other text (`text`). A terminal's: each as it is; a report's: escaped HTML.
struct LimitsMarkup {
  std::string (*code)(std::string_view);
  std::string (*path)(std::string_view);
  std::string (*text)(std::string_view);
};
// "no limit was stored with this run: E_um, ... or M_um under [tolerances.X] in the
// configuration it was made with (cfg.toml) judge the runs made with it (docs/config.md)", its
// quotes marked by `m`. `subject`: "this run" or "these runs"; `maker`: whose configuration
// ("it", "the newest"). One sentence for the terminal and the report.
std::string to_text(const LimitsWhere& w, const LimitsMarkup& m,
                    std::string_view subject = "this run", std::string_view maker = "it");
// The same for a terminal (nothing marked).
std::string to_text(const LimitsWhere& w);
// verdict_of, and where the limits would be given when none judged the result (Verdict::hint):
// what daq show, daq analyse and daq run print, for every kind of run.
Verdict run_verdict(std::string_view kind, std::string_view axis, const nlohmann::json& settings,
                    const nlohmann::json& result);

nlohmann::json to_json(const Verdict& v);
// "PASS", "FAIL", "no tolerance configured", or "no tolerance applies" (limits configured for
// values this evaluation does not give, e.g. E under VDI/DGQ 3441).
std::string summary(const Verdict& v);
// For a terminal: the verdict, each check with its limit, and the notes.
void print_verdict(const Verdict& v);
// The same of a verdict's JSON (to_json; daq show prints a stored result's), each line led by
// `indent`. With no limit it says where they would be given (its "hint"), else only that none
// was configured.
void print_verdict(const nlohmann::json& verdict, std::string_view indent = "");
// The limits that would judge a run's result, as keys under its [tolerances.AXIS] or
// [tolerances.PLANE] table (docs/config.md): `kind` the stored run's ("linear", "rotary",
// "circle", "straightness", "angular", "roll"), `standard_title` a positioning result's
// ("VDI/DGQ 3441:1977" takes P, Pa, Ps, U). One list for the report's verdict line and the
// terminal's (daq replay named only "[tolerances] in the configuration"). A five-axis ballbar
// run ("ballbar5x") is judged by location_um and location_urad.
std::vector<std::string> tolerance_keys(std::string_view kind,
                                        std::string_view standard_title = {});
// "a", "a or b", "a, b or c".
std::string either_of(const std::vector<std::string>& items);
// The check of a result key, or nullptr.
const Check* find_check(const Verdict& v, const std::string& key);

}  // namespace daq
