// What each controller format's values mean (see comp_meaning.hpp). Every quote below was read
// in the document named beside it; docs/compensation-tables.md gives the same with the copies
// that were read and what each text leaves open.
#include "cal/analysis/comp_meaning.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::comptable {
namespace {

// clang-format off
constexpr FormatMeaning kMeanings[] = {
    {"csv", "caldaq compensation table (CSV)", Sign::correction,
     "as the header line says (--sign correction or error)", "the grid positions given",
     Evidence::stated, "caldaq's own format (docs/compensation-tables.md)", ""},
    {"linuxcnc", "LinuxCNC COMP_FILE, COMP_FILE_TYPE = 1", Sign::correction,
     "the trim is added to the commanded joint position (and subtracted from the feedback)",
     "machine coordinates, absolute per point", Evidence::stated,
     "LinuxCNC INI documentation, [JOINT_n] COMP_FILE_TYPE; src/emc/motion/control.c (the trim is "
     "added to joint_pos_cmd to make motor_pos_cmd)",
     "Type 1: The second value specifies positive offset from nominal while traveling in the "
     "positive direction."},
    {"linuxcnc-matrixkins", "LinuxCNC matrixkins", Sign::correction,
     "X_joint = C_xx X + C_xy Y + C_xz Z ...: the coefficients map the commanded position to the "
     "joints", "the machine's axes", Evidence::stated,
     "LinuxCNC matrixkins HAL component (2.9 and later), its description",
     "X_joint = C_xx * X_axis + C_xy * Y_axis + C_xz * Z_axis"},
    {"siemens", "SINUMERIK leadscrew / measuring system error compensation (LEC, $AA_ENC_COMP)",
     Sign::error,
     "the value modifies the position actual value; a positive value moves the axis in the "
     "negative direction",
     "machine axis positions, absolute per point ($AA_ENC_COMP_MIN .. _MAX); Siemens advises "
     "zero at the reference point", Evidence::stated,
     "SINUMERIK 840D sl/828D function manual Extended Functions 03/2013 (6FC5397-1BP40-3BA1) "
     "p. 238; SINUMERIK 808D function manual 01/2017 p. 106",
     "The principle of the MSEC is to modify the axis-specific position actual value by the "
     "assigned compensation value ... A positive compensation value causes the corresponding "
     "machine axis to move in the negative direction."},
    {"siemens-cec", "SINUMERIK interpolatory (sag) compensation (CEC, $AN_CEC)", Sign::correction,
     "the output is applied to the compensation axis; the input is the base axis's set-point. "
     "Whether a positive value moves the compensation axis in + or - is not stated: written as "
     "the correction (what the control adds), the reading that fits Siemens' separate display of "
     "sag compensation beside the actual-value compensations",
     "base axis set-point positions, absolute per point", Evidence::not_found,
     "SINUMERIK function manual Extended Functions 03/2013 (6FC5397-1BP40-3BA1) p. 245-249; "
     "SINUMERIK 802D sl function manual 11/2012 p. 215, 222",
     "$AN_CEC_OUTPUT_AXIS ... Name of machine axis to which the output of the compensation table "
     "[<t>] is applied."},
    {"isg", "TwinCAT CNC (ISG) leadscrew error compensation (kw.ssfk)", Sign::error,
     "the position set-point is changed by the value; the values are absolute position errors, "
     "actual - set (the worked example: set 19866.7 um, actual 19856.5 um -> -102 x 0.1 um)",
     "axis coordinates, absolute per point; .pos moving positive, .neg moving negative",
     Evidence::best_reading,
     "Beckhoff Infosys TF5200 axis compensation: the table of kw.ssfk (P-COMP-00023 .. 25) and "
     "its example of a compensation value list; the older TwinCAT CNC edition's formula "
     "delta s = s_ist - s_soll",
     "Compensation values are specified as absolute position errors in the unit specified in "
     "P-COMP-00017."},
    {"isg-cross", "TwinCAT CNC (ISG) cross compensation (kw.crosscomp)", Sign::correction,
     "the slave axis is offset as a function of the master's command position; the sign of the "
     "'relative compensation values' is not stated: written as the correction (the offset the "
     "slave's command position gets)",
     "master axis positions, per point", Evidence::not_found,
     "Beckhoff Infosys TF5200 axis compensation: cross compensation, P-COMP-00003 .. 07",
     "The slave axis command positions displayed are offset with the offset values."},
    {"isg-volumetric", "TwinCAT CNC (ISG) volumetric compensation (TF5280)", Sign::error,
     "the control computes the correction of the axis set-points from the ISO 230-1 error "
     "parameters given (EXX, EYX, ..., C0Y), which are errors; its option 'negate' is not set",
     "the machine model of ISO 230-1", Evidence::best_reading,
     "Beckhoff Infosys TF5280 Volumetric Compensation (overview, units, P-VOLC-00009)",
     "The purpose of compensation is to balance out errors in tool positioning and orientation by "
     "correcting the axis setpoints"},
    {"heidenhain", "HEIDENHAIN nonlinear axis error compensation (*.COM)", Sign::error,
     "the columns hold the measured error curve (HEIDENHAIN ties them to the ISO 230-1 errors: "
     "C1 positioning error EXX, C2 straightness EYX, ...); the control takes it off in the "
     "position control. The *.COM sign is not stated in so many words; HEIDENHAIN's linear "
     "compensation states 'the error is positive if the table travel is too long'",
     "AXISPOS from the machine datum", Evidence::best_reading,
     "HEIDENHAIN Technical Manual iTNC 530 HSCI 07/2013 p. 680; MANUALplus 620 01/2012 p. 716; "
     "TNC 407/415/425 01.98 p. 4-26 (MP720)",
     "The error is positive if the table travel is too long, and negative if the travel is too "
     "short."},
    {"fanuc", "FANUC stored pitch error compensation (parameters 3620 - 3624)", Sign::correction,
     "each point's value is the compensation over the section ending at it, in detection units "
     "times the magnification (3623); the values are named 'compensation values' (a correction); "
     "the sign is not stated in a sentence",
     "incremental, summed from the reference position's point: the table is zero at the "
     "reference position and cannot hold a constant there", Evidence::best_reading,
     "FANUC Series 0i-PB parameter manual B-63980EN/01 p. 100; FANUC technical report A-77810E",
     "The compensation value is output at the compensation position No. corresponding to each "
     "section between the coordinates."},
};
// clang-format on

}  // namespace

std::string_view to_string(Evidence e) {
  using enum Evidence;
  static constexpr EnumName<Evidence> kNames[] = {
      {stated, "stated by the vendor"},
      {best_reading, "the best reading of the vendor's text, not stated in so many words"},
      {not_found, "NOT STATED in the public text read"}};
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, e, "unknown");
}

std::span<const FormatMeaning> format_meanings() { return kMeanings; }

const FormatMeaning& format_meaning(std::string_view format) {
  const auto* it = std::find_if(std::begin(kMeanings), std::end(kMeanings),
                                [&](const FormatMeaning& m) { return m.format == format; });
  if (it != std::end(kMeanings)) return *it;
  std::string known;
  for (const auto& m : kMeanings) known += (known.empty() ? "" : ", ") + std::string(m.format);
  throw InputError(fmt::format("compensation format '{}' (known: {})", format, known));
}

namespace {
std::string_view sign_words(Sign s) {
  return s == Sign::error ? "the measured error (measured - target)"
                          : "the correction (-error: what the control adds)";
}
}  // namespace

std::string meaning_header(const FormatMeaning& m, std::string_view c) {
  std::string out = fmt::format("{}{}\n{}Values are {}: {}.\n{}Reference: {}.\n", c, m.name, c,
                                sign_words(m.written), m.applied, c, m.reference);
  out += fmt::format("{}Sign: {} ({}).\n", c, to_string(m.evidence), m.source);
  if (m.evidence != Evidence::stated)
    out += fmt::format(
        "{}VERIFY BEFORE TRUSTING: load the table, measure the axis again (a cross-axis table: "
        "the straightness it corrects), run daq verify on that run and check that the error "
        "got smaller, not about twice as large.\n",
        c);
  return out;
}

std::string meaning_text(const FormatMeaning& m) {
  std::string out =
      fmt::format("{}: the values are {}; {}. Reference: {}. Sign {} ({})", m.name,
                  sign_words(m.written), m.applied, m.reference, to_string(m.evidence), m.source);
  if (!m.quote.empty()) out += fmt::format(": \"{}\"", m.quote);
  out += ".";
  if (m.evidence != Evidence::stated)
    out +=
        " Verify before trusting it: load the table, measure the axis again (a cross-axis table: "
        "the straightness it corrects) and compare (daq verify RUN); an error about twice as "
        "large as before means the sign is the other way.";
  return out;
}

}  // namespace cal::comptable
