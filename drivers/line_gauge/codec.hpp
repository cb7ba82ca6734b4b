#pragma once
// A configurable line-oriented gauge codec for digital length gauges with a serial output
// (the transducer of a telescoping ballbar, a linear gauge, a serial thermometer): one value
// per line, e.g. "+012.3456", "-0.00125 mm", "12.3456 MM", "T=+020.125". The request string
// (for polled gauges), the value pattern, the unit and a scale are configuration, because
// every maker's format differs; docs/codecs.md lists the formats this was checked on.
#include <optional>
#include <regex>
#include <span>
#include <string>
#include <string_view>

#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/codec/decimal.hpp"

namespace cal::drivers::codec {

// Lengths (mm, um, in, m), a temperature (degC), angles (urad, mrad = mm/m, arcsec: an
// electronic level) or a bare number (none).
enum class GaugeUnit { mm, um, inch, m, degc, none, urad, mrad, arcsec };
// mm | um | in | m | degC | none | urad | mrad | mm/m | arcsec
GaugeUnit gauge_unit_from_string(std::string_view s);
// True for the angle units: the gauge is then a level and its readings are angles (rad).
bool is_angle(GaugeUnit u);
// The factor from the unit to SI (m, rad; 1 for degC and none).
double unit_factor(GaugeUnit u);
// The same factor as an exact decimal (mm {1, -3}, in {254, -4}, ...); nullopt for arcsec
// (pi / 648000 is no decimal). A reading in such a unit is stored as the correctly rounded
// double of its printed decimal in SI (parse_number_scaled), never printed x 1e-3.
std::optional<DecimalScale> decimal_scale(GaugeUnit u);

// The output formats of common gauge families, each from its maker's public documentation
// (docs/drivers.md, "Gauge presets"): the request that polls it, the pattern of its line and the
// unit it prints in when the line carries none.
struct GaugePreset {
  std::string_view name;     // the `preset` option's value
  std::string_view request;  // sent to poll (as sent, terminator included)
  std::string_view pattern;  // ECMAScript: group 1 the number, group 2 (if any) a unit word
  std::string_view example;  // a line as the documentation prints it (without terminator)
  double example_mm;         // what that line reads, in mm
  std::string_view source;   // where the format is documented
};
std::span<const GaugePreset> gauge_presets();
const GaugePreset* gauge_preset(std::string_view name);  // nullptr: no such preset

struct GaugeConfig {
  // Sent to poll a gauge ("?\r", "PRINT\r"); empty for a gauge that streams by itself.
  std::string request;
  // ECMAScript regex with one capture group for the number (and optionally a second one for a
  // printed unit word, which then wins over `unit`); empty: the whole line, trimmed, optionally
  // followed by a unit word (mm, um, in, inch), is the number.
  std::string pattern;
  GaugeUnit unit = GaugeUnit::mm;  // the unit of the printed number (a printed unit wins)
  // Applied to the printed number before the unit, and added after scaling (in the printed
  // unit). With the defaults (1, 0) a reading is its printed decimal in SI, correctly rounded;
  // otherwise (printed x scale + offset) x unit_factor, a computed value, not the printed one.
  double scale = 1.0;
  double offset = 0.0;
  // Plausible range of the value in SI (m, or degC for temperatures); outside: out_of_range.
  double min_si = -10.0, max_si = 10.0;
  std::size_t max_line_bytes = 256;
};

struct GaugeFrame {
  // metres (degC for temperature gauges, rad for levels, as printed for `none`)
  double value_si = 0.0;
  std::string text;  // the line as received
};

class GaugeCodec : public CodecBase<GaugeCodec, GaugeFrame> {
 public:
  // Throws cal::InputError for an invalid regex or one without a capture group.
  explicit GaugeCodec(GaugeConfig config = {});
  const GaugeConfig& config() const { return config_; }
  void do_feed(std::span<const std::byte> bytes, std::vector<GaugeFrame>& frames,
               std::vector<CodecError>& errors);
  // The fast path of the instrument: each value goes to on_value(value_si, line) with the line
  // in place (valid during the call), so a 10 kHz stream costs no frame, copy or allocation
  // per line. Same decoding, errors and stats as feed().
  template <class OnValue>
  void feed_values(std::span<const std::byte> bytes, OnValue&& on_value,
                   std::vector<CodecError>& errors) {
    count_bytes(bytes.size());
    splitter_.feed(
        bytes,
        [&](std::string_view line, std::uint64_t off) {
          if (double si; fast_value(line, si)) {
            count_frame();
            on_value(si, line);
          } else if (const auto v = decode_line(line, off, errors)) {
            count_frame();
            on_value(*v, line);
          }
        },
        [&](std::uint64_t off) { report_overlong(off, errors); });
  }

 private:
  // The common line of a streaming gauge, a bare number between blanks ("+100.000123") in
  // range, decoded in one pass, inline: such a line is printable and one token, so
  // decode_line() would give the very same value (parse_number has the same exact fast path,
  // the same arithmetic follows). False: anything else, for decode_line() to decide.
  bool fast_value(std::string_view line, double& si) const {
    if (fast_factor_ == 0.0) return false;  // a pattern: decode_line() only
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
    if (exact_) {  // the printed decimal in SI, one correctly rounded operation
      if (!parse_plain_decimal_scaled(line, *exact_, si)) return false;
    } else {
      double printed;
      if (!parse_plain_decimal(line, printed)) return false;
      si = (printed * config_.scale + config_.offset) * fast_factor_;  // to_si() without a unit
    }
    return si >= config_.min_si && si <= config_.max_si;
  }
  // The value of one line in SI, or nullopt after reporting why not.
  std::optional<double> decode_line(std::string_view line, std::uint64_t offset,
                                    std::vector<CodecError>& errors);
  void report_overlong(std::uint64_t offset, std::vector<CodecError>& errors);
  // The number `text` in SI, from one parse: nullopt when it is no finite number, or a printed
  // number beyond the double's range (e.g. "1e309"). A configured scale or offset may still
  // carry a finite number out of range (inf): the caller's range check refuses that.
  std::optional<double> to_si(std::string_view text, std::optional<GaugeUnit> printed_unit) const;
  // The unit's exact scale when the configuration leaves the printed decimal as it is
  // (scale 1, offset 0); nullopt otherwise.
  std::optional<DecimalScale> exact_scale(GaugeUnit unit) const;

  GaugeConfig config_;
  double fast_factor_ = 0.0;  // the configured unit's factor to SI; 0 when there is a pattern
  std::optional<DecimalScale> exact_;  // exact_scale(config_.unit) without a pattern
  std::optional<std::regex> regex_;
  LineSplitter splitter_;
};

}  // namespace cal::drivers::codec
