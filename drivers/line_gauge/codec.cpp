// Configurable line gauge codec (see line_gauge/codec.hpp).
#include "line_gauge/codec.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::drivers::codec {
namespace {

bool blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

std::optional<GaugeUnit> unit_word(std::string_view w) {
  std::string lower;
  for (char c : w) lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  if (lower == "mm") return GaugeUnit::mm;
  if (lower == "um" || lower == "µm") return GaugeUnit::um;
  if (lower == "in" || lower == "inch" || lower == "\"") return GaugeUnit::inch;
  if (lower == "m") return GaugeUnit::m;
  if (lower == "urad" || lower == "µrad") return GaugeUnit::urad;
  if (lower == "mrad" || lower == "mm/m") return GaugeUnit::mrad;
  if (lower == "arcsec") return GaugeUnit::arcsec;
  return std::nullopt;
}

}  // namespace

std::span<const GaugePreset> gauge_presets() {
  static constexpr GaugePreset presets[] = {
      // Mitutoyo's Digimatic data format: "0", channel "1", item "A", sign, 8 characters of
      // digits with a floating point, CR (QM-Height manual 99MAF600B, "USB Data Output
      // Specifications": 01A+0000.123[CR]); read out with "1" + CR (rabryan/pytuyo, the USB-ITN
      // reader: request_read sends '1', answers end with CR, data answers start with '0').
      {"mitutoyo_digimatic", "1\r", R"(^0[0-9]A([+-][0-9.]+)$)", "01A+0000.123", 0.123,
       "Mitutoyo QM-Height manual 99MAF600B (USB data output); rabryan/pytuyo (USB-ITN)"},
      // Sylvac's OPTO-RS cable (duplex): "?" + CR requests the displayed value, sent as sign
      // ("+", "-" or a space), integer, ".", fraction, CR; errors as "ERR" + number + CR;
      // in tolerance mode '<', '=' or '>' follows the value (Sylvac Opto/UniCal manuals).
      {"sylvac", "?\r", R"(^ ?([+-]?[0-9]+\.[0-9]+) *[<=>]?$)", "-12.345", -12.345,
       "Sylvac OPTO-RS cable manual (Bowers Group Sylvac Opto Instruments); UniCal manual VIII.5"},
      // Mahr Millimar C1208 over OPTORSD: "?" + CR, answer "xxx.xxx<unit>" CR LF in the unit of
      // the display (mm, in or um: UNI?).
      {"mahr_millimar", "?\r", R"(^ *([+-]?[0-9]*\.?[0-9]+) *(mm|in|um)? *$)", "0.0123mm", 0.0123,
       "Mahr Millimar C1208 manual, OPTORSD interface protocol"},
  };
  return presets;
}

const GaugePreset* gauge_preset(std::string_view name) {
  for (const auto& p : gauge_presets())
    if (p.name == name) return &p;
  return nullptr;
}

GaugeUnit gauge_unit_from_string(std::string_view s) {
  if (s == "degC" || s == "degc") return GaugeUnit::degc;
  if (s == "none") return GaugeUnit::none;
  if (auto u = unit_word(s)) return *u;
  throw InputError(fmt::format(
      "gauge unit '{}' (expected mm, um, in, m, degC, none, urad, mrad, mm/m or arcsec)", s));
}

double unit_factor(GaugeUnit u) {
  switch (u) {
    case GaugeUnit::mm:
      return 1e-3;
    case GaugeUnit::um:
      return 1e-6;
    case GaugeUnit::inch:
      return 0.0254;  // exact, by definition (1959)
    case GaugeUnit::m:
    case GaugeUnit::degc:
    case GaugeUnit::none:
      return 1.0;
    case GaugeUnit::urad:
      return 1e-6;
    case GaugeUnit::mrad:
      return 1e-3;
    case GaugeUnit::arcsec:
      return 3.14159265358979323846 / 648000.0;  // pi / (180 * 3600)
  }
  return 1.0;
}

std::optional<DecimalScale> decimal_scale(GaugeUnit u) {
  switch (u) {
    case GaugeUnit::mm:
    case GaugeUnit::mrad:
      return kMillimetresToMetres;  // 10^-3 (mrad to rad alike)
    case GaugeUnit::um:
    case GaugeUnit::urad:
      return kMicrometresToMetres;  // 10^-6
    case GaugeUnit::inch:
      return kInchesToMetres;  // 0.0254 exactly (1959)
    case GaugeUnit::m:
    case GaugeUnit::degc:
    case GaugeUnit::none:
      return kUnitScale;
    case GaugeUnit::arcsec:
      return std::nullopt;
  }
  return std::nullopt;
}

bool is_angle(GaugeUnit u) {
  return u == GaugeUnit::urad || u == GaugeUnit::mrad || u == GaugeUnit::arcsec;
}

GaugeCodec::GaugeCodec(GaugeConfig config)
    : config_(std::move(config)), splitter_(config_.max_line_bytes) {
  if (config_.pattern.empty()) {
    fast_factor_ = unit_factor(config_.unit);
    exact_ = exact_scale(config_.unit);
    return;
  }
  try {
    regex_.emplace(config_.pattern, std::regex::ECMAScript | std::regex::optimize);
  } catch (const std::regex_error& e) {
    throw InputError(fmt::format("gauge pattern '{}': {}", config_.pattern, e.what()));
  }
  if (regex_->mark_count() < 1)
    throw InputError(
        fmt::format("gauge pattern '{}' has no capture group for the value", config_.pattern));
}

void GaugeCodec::do_feed(std::span<const std::byte> bytes, std::vector<GaugeFrame>& frames,
                         std::vector<CodecError>& errors) {
  splitter_.feed(
      bytes,
      [&](std::string_view line, std::uint64_t off) {
        if (const auto v = decode_line(line, off, errors))
          emit(frames, GaugeFrame{*v, std::string(line)});
      },
      [&](std::uint64_t off) { report_overlong(off, errors); });
}

void GaugeCodec::report_overlong(std::uint64_t off, std::vector<CodecError>& errors) {
  report(errors, ErrorKind::overlong_line, off,
         fmt::format("gauge: line longer than {} bytes", config_.max_line_bytes));
}

std::optional<DecimalScale> GaugeCodec::exact_scale(GaugeUnit unit) const {
  if (config_.scale != 1.0 || config_.offset != 0.0) return std::nullopt;
  return decimal_scale(unit);
}

std::optional<double> GaugeCodec::to_si(std::string_view text,
                                        std::optional<GaugeUnit> printed_unit) const {
  const GaugeUnit unit = printed_unit.value_or(config_.unit);
  // The printed decimal itself in SI (strtod of its digits with the exponent moved), where
  // the unit is an exact decimal and nothing is added: "100.000123" mm is 0.100000123 m, not
  // 100.000123 x 1e-3 = 0.10000012300000001. inf and nan come back as read (a positive factor).
  if (const auto exact = exact_scale(unit)) {
    const auto si = parse_number_scaled(text, *exact);
    if (!si || !std::isfinite(*si)) return std::nullopt;
    // A printed number beyond the double's range ("1e309" mm) is no value even where its SI
    // value is one (1e306 m): read as printed only then (|si| > 1e290: the factors are >= 1e-6).
    if (std::abs(*si) > 1e290)
      if (const auto printed = parse_number(text); !printed || !std::isfinite(*printed))
        return std::nullopt;
    return si;
  }
  const auto printed = parse_number(text);
  if (!printed || !std::isfinite(*printed)) return std::nullopt;
  return (*printed * config_.scale + config_.offset) * unit_factor(unit);
}

std::optional<double> GaugeCodec::decode_line(std::string_view line, std::uint64_t off,
                                              std::vector<CodecError>& errors) {
  if (!is_printable_ascii(line)) {
    report(errors, ErrorKind::garbage, off, "gauge: non-printable bytes in a line");
    return std::nullopt;
  }
  std::optional<GaugeUnit> printed_unit;
  bool found = false;     // a number's text, with no unit or one of this gauge's kind
  std::string matched;    // the regex's number group
  std::string_view text;  // the number as printed
  if (regex_) {
    std::match_results<std::string_view::const_iterator> m;
    if (std::regex_search(line.begin(), line.end(), m, *regex_)) {
      matched = m[1].str();
      text = trim(matched);
      found = true;
      if (m.size() > 2 && m[2].matched) {  // a printed unit word
        printed_unit = unit_word(m[2].str());
        found = printed_unit && is_angle(*printed_unit) == is_angle(config_.unit);
      }
    }
  } else {
    std::array<std::string_view, 2> tokens;
    const std::size_t count = split_whitespace(line, tokens);
    if (count == 1 || count == 2) {
      text = tokens[0];
      found = true;
      if (count == 2) {
        printed_unit = unit_word(tokens[1]);
        // A printed unit of the other kind (an angle on a length gauge) is not this gauge's.
        found = printed_unit && is_angle(*printed_unit) == is_angle(config_.unit);
      }
    }
  }
  // The number parsed once, straight to SI (to_si): a good line ends here.
  if (found)
    if (const auto si = to_si(text, printed_unit);
        si && *si >= config_.min_si && *si <= config_.max_si)
      return si;
  // A bad line: read again as printed, for what to say (no finite number, or one out of range:
  // its SI value, or that value, beyond the double's range).
  const auto number = found ? parse_number(text) : std::nullopt;
  if (!number || !std::isfinite(*number)) {
    report(errors, ErrorKind::malformed, off,
           fmt::format("gauge: no value in '{}'", line.substr(0, 40)));
    return std::nullopt;
  }
  report(errors, ErrorKind::out_of_range, off,
         fmt::format("gauge: value {} outside [{}, {}]", *number, config_.min_si, config_.max_si));
  return std::nullopt;
}

}  // namespace cal::drivers::codec
