#pragma once
// The compensation loop at the machine (docs/compensation-tables.md, "Verification"): a table
// written from a run is stored with what it was predicted to leave; the next run of the same
// axis on the same machine is compared with that prediction (cal/analysis/comp_verify.hpp),
// and a table that the control applied otherwise than meant is diagnosed (sign, units,
// reference point) with the corrected table on offer.
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cal/analysis/comp_formats.hpp"
#include "cal/analysis/comp_table.hpp"
#include "cal/analysis/comp_verify.hpp"
#include "cal/storage/store.hpp"

namespace daq {

// How a positioning table is written in a format (the options a writer takes besides the
// table), stored with the compensation so that a corrected table can be written the same way.
struct TableWriter {
  std::string format;  // csv, linuxcnc, siemens, isg, heidenhain, fanuc
  int axis_number = 1;
  cal::comptable::FanucOptions fanuc;
};
nlohmann::json to_json(const TableWriter& w);
TableWriter table_writer_from_json(const nlohmann::json& j);
// The file's text; throws cal::InputError for an unknown format (naming the known ones).
std::string write_table(const TableWriter& w, const cal::comptable::Table& t);
// What the written table does on the machine (comp_table.hpp, Applied).
cal::comptable::Applied applied_of(const TableWriter& w, const cal::comptable::Table& t);

// A cross-axis or volumetric compensation as written (SINUMERIK CEC, ISG cross and volumetric
// lists, LinuxCNC matrixkins, caldaq's cross CSV; cal::comptable::is_cross_format): its files
// and the control's axis numbers, stored so that the next straightness (or squareness) run of
// an axis it corrects is checked against what the files do (docs/compensation-tables.md,
// "Verification").
struct CrossCompensation {
  std::string format;
  std::vector<std::pair<std::string, std::string>> files;  // name ("" for one file), text
  std::map<std::string, int> axis_numbers{{"X", 1}, {"Y", 2}, {"Z", 3}};
  std::string file;  // the path one file was written to (-o), named by the report; "": stdout
};
// Stored with the machine (returns the id); `source_run_id` 0 for one from a model. The
// compensation's axis is the axes it corrects ("Y", "XYZ"). Throws cal::InputError for files the
// control's reader cannot read (the same reader the check uses).
std::int64_t store_cross_compensation(cal::storage::Store& store, std::int64_t machine_id,
                                      std::int64_t source_run_id, const std::string& source,
                                      const CrossCompensation& c,
                                      const nlohmann::json& origin = nlohmann::json::object());

struct LoopCheck {
  cal::storage::CompensationRecord compensation;  // the table the as-left run is checked against
  cal::comptable::Verification verification;
  std::size_t points = 0;  // targets and directions compared
  // A straightness run checked against a cross-axis compensation: the component ("E_YX") and
  // the as-found run of it the change is measured from (the compensation's source run, or the
  // newest run of the component before the compensation was stored).
  std::string component;
  std::int64_t as_found_run = 0;
  // What was compared, per point (a target and a direction, '+' or '-'): the as-found error,
  // what the table adds there, the as-left error (um); the report draws and lists them.
  cal::comptable::VerifyInput input;
  std::vector<char> direction;
};
// The newest compensation stored for the run's machine and axis before the run started (or the
// one given), checked against the run's captured stops. A straightness run is checked against
// the newest cross-axis compensation of its machine that corrects the axis it reads: the change
// from the as-found run of its component is compared with what the files add along the line.
// nullopt when there is none, or the run has no stops where the table was made; cal::InputError for
// a given id that does not exist or is of another axis.
std::optional<LoopCheck> check_run(const cal::storage::RunReader& store, std::int64_t run_id,
                                   std::optional<std::int64_t> compensation_id = std::nullopt);
// The table with the finding's fix applied (negated, rescaled, offset, shifted), in the
// compensation's format; cal::InputError when there is nothing to correct (as predicted, too
// small, unexplained) or the format cannot hold the fix (FANUC's constant).
std::string corrected_table(const LoopCheck& c);
// The same for any compensation: its files corrected (name, text; one file named ""). A
// cross-axis compensation is corrected for an inverted sign or a unit error (every value
// scaled), a reference-point error (the table of the read axis moved by the constant) and a
// position shift (the positions of the read axis's table over the moving axis shifted);
// cal::InputError for a format that cannot hold the fix (matrixkins, volumetric).
std::vector<std::pair<std::string, std::string>> corrected_files(const LoopCheck& c);
nlohmann::json to_json(const LoopCheck& c);
// A line or two for the terminal: the finding and what to do.
std::string loop_text(const LoopCheck& c);

}  // namespace daq
