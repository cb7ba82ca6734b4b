#pragma once
// Vaisala PTU300 family (and the PTB330/HMT330 transmitters that share its serial language):
// ASCII lines over RS-232/USB serial. Source: Vaisala PTU300 User's Guide M210796EN
// (chapter 4 "Operation": SEND, R, S, SMODE, INTV, FORM, Table 30 "FORM command modifiers",
// examples "P= 1033.7 hPa T= 22.2 'C RH= 38.3 %RH"), and for the checksum equations the
// Vaisala user guides that print them (PTB330 Table 12, HMP155 Table 14, PTB220 appendix I).
// Details, units and what is not covered: docs/codecs.md.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cal/drivers/codec/common.hpp"

namespace cal::drivers::codec {

// ---- commands (each ends with the <cr> the manual asks for) ----
enum class Ptu300Mode { stop, run, poll, send };
std::string ptu300_send(std::optional<int> address = std::nullopt);  // "SEND\r", "SEND 3\r"
std::string ptu300_run();                                            // "R\r"
std::string ptu300_stop();                                           // "S\r"
std::string ptu300_smode(Ptu300Mode mode);                           // "SMODE RUN\r"
enum class IntervalUnit { s, min, h };
// "INTV 10 S\r"; throws cal::InputError unless 0 <= n <= 255 (the manual's range).
std::string ptu300_intv(int n, IntervalUnit unit);
// "FORM <formatter>\r", "FORM /\r" restores the default; throws cal::InputError if the
// formatter holds a CR or LF (it would end the command early).
std::string ptu300_form(std::string_view formatter);

// ---- checksums (the FORM fields CS2, CS4, CSX) ----
enum class Ptu300Checksum { none, cs2, cs4, csx };
// The checksum of `message` (all bytes before the checksum field): CS2 = sum mod 256,
// CS4 = sum mod 65536, CSX = XOR of the bytes with '$' and '*' counted as 0 (NMEA style).
std::uint32_t ptu300_checksum(Ptu300Checksum kind, std::string_view message);
// Its ASCII form: 2 (CS2, CSX) or 4 (CS4) upper-case hexadecimal digits.
std::string ptu300_checksum_hex(Ptu300Checksum kind, std::string_view message);

// ---- output lines ----
enum class Ptu300Quantity {
  pressure,           // P (also P1, P2: the transducers of a two-barometer unit)
  gauge_pressure,     // P in barg or psig: relative to a reference the user's guide does not
                      // state, so never used as the absolute air pressure
  pressure_tendency,  // P3H
  temperature,        // T
  relative_humidity,  // RH
  dew_point,          // TD, TDP, TDF (dew/frost point)
  other,              // anything else: value kept as printed
};

struct Ptu300Field {
  std::string label;  // as printed, without '=' (e.g. "P1", "Tfrost")
  Ptu300Quantity quantity = Ptu300Quantity::other;
  // Pa for pressures, degC for temperatures, %RH for humidity; as printed for `other`.
  double value_si = 0.0;
  std::string unit;  // as printed, e.g. "hPa", "'F"
  // False when the device printed stars: the value does not fit or is in error (the user's
  // guide); the device's statement, not a codec error. value_si is then 0.
  bool available = true;
  bool operator==(const Ptu300Field&) const = default;
};

struct Ptu300Frame {
  // The main quantities (P, T, RH, TD) when the line carries them, in SI / named units.
  std::optional<double> pressure_pa;
  std::optional<double> temperature_degc;
  std::optional<double> relative_humidity_pct;
  std::optional<double> dew_point_degc;
  std::vector<Ptu300Field> fields;  // every value of the line, in order
  // A line without any number (a command echo, "OK", "Output intrv. : 10 s"): its text.
  std::string text;
  bool operator==(const Ptu300Frame&) const = default;
};

struct Ptu300Config {
  Ptu300Checksum checksum = Ptu300Checksum::none;  // a FORM with CS2/CS4/CSX as last field
  // Extra labels of a custom FORM, e.g. {"Temp", temperature}; matched case-insensitively.
  std::vector<std::pair<std::string, Ptu300Quantity>> aliases;
  // Plausible ranges (a value outside is an out_of_range error and is left out of the frame).
  double min_pressure_pa = 50e3, max_pressure_pa = 120e3;  // PTU300 barometer range 500..1100 hPa
  double min_temperature_degc = -70.0, max_temperature_degc = 180.0;  // HMP probe range
  double min_relative_humidity_pct = 0.0, max_relative_humidity_pct = 100.0;
  std::size_t max_line_bytes = LineSplitter::default_max_line_bytes;
};

class Ptu300Codec : public CodecBase<Ptu300Codec, Ptu300Frame> {
 public:
  explicit Ptu300Codec(Ptu300Config config = {});
  void do_feed(std::span<const std::byte> bytes, std::vector<Ptu300Frame>& frames,
               std::vector<CodecError>& errors);

 private:
  void decode_line(std::string_view line, std::uint64_t offset, std::vector<Ptu300Frame>& frames,
                   std::vector<CodecError>& errors);
  Ptu300Quantity quantity_of(std::string_view label, std::string_view unit) const;

  Ptu300Config config_;
  LineSplitter splitter_;
};

}  // namespace cal::drivers::codec
