#pragma once
// The machine model file, caldaq.model.v1 and v2 (JSON; documented in docs/model-file.md): the
// kinematic chain, the offsets, each of the 18 component errors as a table or a polynomial, the
// three squareness errors with their stated convention, method, placement and carrier, and
// where each came from; v2 adds up to two rotary axes (their pivots, range, four location
// errors as constants and six component errors as functions of the angle). Reading validates
// everything and names the file and the key at fault; writing gives the same model back when read.
// The maths is in cal::kinematics (analysis/); this is its file form (analysis does no I/O).
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/kinematics.hpp"
#include "cal/analysis/rotary.hpp"
#include "cal/analysis/volumetric_comp.hpp"

namespace cal::daq::model {

inline constexpr std::string_view kSchema = "caldaq.model.v1";
// v1 and the rotary axes (a v1 file is a v2 file without them; both are read). A model without
// rotary axes is written as v1, so that older readers keep reading it.
inline constexpr std::string_view kSchemaRotary = "caldaq.model.v2";

// Where an error came from (a stored run, another tool, a hand entry). `json` is the JSON text
// of the file's "source" value, kept as written (empty: none given).
struct Source {
  std::string json;
};

struct ComponentEntry {
  bool given = false;  // false: not in the file, taken as zero
  Source source;
};

// How the squareness of one plane was measured and who carries its correction.
struct SquarenessEntry {
  bool given = false;
  // The convention the file stated the value in: "iso230_1_urad" (the model's location error)
  // or "angle_over_90_urad" (as daq analyse squareness reports it), converted on reading.
  std::string stated_as = "iso230_1_urad";
  std::string method;     // straightness, diagonal, circle, circles, other ("" unknown)
  std::string placement;  // global or local ("" unknown)
  std::optional<kinematics::Vec3> position_mm;  // where a local measurement was made
  Source source;
};

// A location error of a rotary axis: its value is in the RotaryAxis; how well it is known and
// where it came from here.
struct LocationEntry {
  bool given = false;
  std::optional<double> uncertainty;  // standard uncertainty, um or urad
  Source source;
};

// One rotary axis of a v2 file: the model's axis (pivot, location errors, component errors as
// functions of the angle in degrees), the range of its angle and what the file said of each.
struct RotaryEntry {
  kinematics::RotaryAxis axis;
  std::array<double, 2> range_deg{};         // [min, max], the default range of maps
  std::array<LocationEntry, 4> location;     // in the order of location_error_names
  std::array<ComponentEntry, 6> components;  // E_X?, E_Y?, E_Z?, E_A?, E_B?, E_C?
  std::string note;
};

struct Model {
  std::string name;
  kinematics::Machine machine;
  // Travel of each axis, [min, max] mm; the default volume of maps and the range every table
  // must cover.
  std::optional<std::array<std::array<double, 2>, 3>> travel_mm;
  std::array<ComponentEntry, 18> components;  // indexed by kinematics::Component
  std::array<SquarenessEntry, 3> squareness;  // indexed by kinematics::Plane
  volcomp::Carriers carriers;                 // who carries each squareness correction
  Source provenance;                          // the file's "provenance" value, kept as written
  // Rotary axes (v2), in chain order from the workpiece to the tool, table axes first.
  std::vector<RotaryEntry> rotary;
};

// The model's machine with its rotary axes, for cal::kinematics::five_axis_error.
kinematics::FiveAxisMachine five_axis(const Model& m);
// The ISO 230-1 name of component `dir` (0..5: X, Y, Z, A, B, C) of a rotary axis: "E_ZC".
std::string rotary_component_name(kinematics::RotaryLetter l, std::size_t dir);
// Component error `dir` (0..5: X, Y, Z, A, B, C) of a rotary axis's motion.
kinematics::ErrorFunction& rotary_component(kinematics::RotaryAxis& r, std::size_t dir);
const kinematics::ErrorFunction& rotary_component(const kinematics::RotaryAxis& r, std::size_t dir);
// InputError "FILE: rotary: `what` does not model rotary axes yet" for the commands that use the
// linear axes only, so that a five-axis model is never silently read as a 3-axis one.
void require_no_rotary(const Model& m, std::string_view file, std::string_view what);

// Parses the text of a model file. `where` names it in errors ("FILE: key: what").
// Throws cal::InputError on anything malformed, unknown, non-finite, out of convention or
// inconsistent (a table that does not cover the stated travel, a carrier outside its plane).
Model parse(std::string_view text, std::string_view where);
Model read(const std::string& path);  // parse(file contents, path); InputError if unreadable

// The model as caldaq.model.v1 JSON text (v2 when it has rotary axes) (pretty-printed, ends in a
// newline).
std::string to_json(const Model& m);
// Writes to_json(m) to path; throws cal::InputError if it cannot (nothing partial is left).
void write(const Model& m, const std::string& path);

// A grid over the model's travel with `count` points per axis; InputError without travel.
kinematics::Grid travel_grid(const Model& m, std::array<std::size_t, 3> count);

}  // namespace cal::daq::model
