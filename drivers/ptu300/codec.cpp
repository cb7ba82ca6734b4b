// Vaisala PTU300 serial codec. Sources (all Vaisala user guides, quoted in docs/codecs.md):
//  - PTU300 User's Guide M210796EN, chapter 4: commands R, S, SEND [addr], SMODE
//    STOP/RUN/POLL/SEND, INTV 0..255 S/MIN/H, FORM (Table 30 modifiers), output examples
//    "P= 1033.7 hPa T= 22.2 'C RH= 38.3 %RH" and "RH= 14.98%RH T= 74.68'F"; values that do not
//    fit or are in error are printed as stars.
//  - Checksum equations (printed identically in the PTB330, HMP155 and MMT162 guides):
//    cs2 = sum(b_i) mod 256, cs4 = sum(b_i) mod 65536 over the n bytes before the field,
//    csx = b'_1 xor ... xor b'_n with b'_i = 0 for '$' (36) and '*' (42), b_i otherwise.
#include "ptu300/codec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::drivers::codec {
namespace {

enum class UnitKind { pressure, gauge_pressure, temperature, humidity };

// value_si = (printed - zero) * factor. Pressure factors: NIST SP 811 (2008) appendix B.8
// (mmHg 1.333224E+02 Pa, inHg 3.386389E+03 Pa, psi 6.894757E+03 Pa, inH2O 2.490889E+02 Pa,
// mmH2O (conventional) 9.80665 Pa); torr = 101325/760 Pa by definition; bar = 1E+05 Pa;
// degF -> degC = (F - 32) * 5/9. The PTU300 user's guide lists hPa, psia, inHg, torr, bara,
// barg, psig, mbar, mmHg, kPa, Pa, mmH2O and inH2O; barg and psig are gauge pressures whose
// reference it does not state: decoded, in Pa, but as gauge_pressure.
struct UnitInfo {
  std::string_view name;
  UnitKind kind;
  double zero;
  double factor;
  // The factor as an exact power of ten (hPa {1, 2}); multiplier 0 where it is not one. A
  // reading in such a unit is stored as its printed decimal in SI, correctly rounded ("1033.7"
  // hPa is strtod("1033.7e2") = 103370 Pa; 1033.7 x 100 would round twice: 15 % of one-decimal
  // hPa readings end one ulp off).
  DecimalScale exact;
};
constexpr DecimalScale kNotDecimal{0, 0};
constexpr UnitInfo kUnits[] = {
    {"Pa", UnitKind::pressure, 0.0, 1.0, {1, 0}},
    {"hPa", UnitKind::pressure, 0.0, 100.0, {1, 2}},
    {"mbar", UnitKind::pressure, 0.0, 100.0, {1, 2}},
    {"kPa", UnitKind::pressure, 0.0, 1000.0, {1, 3}},
    {"bar", UnitKind::pressure, 0.0, 1e5, {1, 5}},
    {"bara", UnitKind::pressure, 0.0, 1e5, {1, 5}},
    {"barg", UnitKind::gauge_pressure, 0.0, 1e5, {1, 5}},
    {"mmH2O", UnitKind::pressure, 0.0, 9.80665, kNotDecimal},
    {"mmHg", UnitKind::pressure, 0.0, 133.322387415, kNotDecimal},
    {"torr", UnitKind::pressure, 0.0, 101325.0 / 760.0, kNotDecimal},
    {"inHg", UnitKind::pressure, 0.0, 3386.389, kNotDecimal},
    {"inH2O", UnitKind::pressure, 0.0, 249.0889, kNotDecimal},
    {"psi", UnitKind::pressure, 0.0, 6894.757, kNotDecimal},
    {"psia", UnitKind::pressure, 0.0, 6894.757, kNotDecimal},
    {"psig", UnitKind::gauge_pressure, 0.0, 6894.757, kNotDecimal},
    {"'C", UnitKind::temperature, 0.0, 1.0, {1, 0}},
    {"'F", UnitKind::temperature, 32.0, 5.0 / 9.0, kNotDecimal},
    {"%RH", UnitKind::humidity, 0.0, 1.0, {1, 0}},
};

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

const UnitInfo* find_unit(std::string_view name) {
  for (const auto& u : kUnits) {
    if (iequals(u.name, name)) return &u;
  }
  return nullptr;
}

// One lexical piece of an output line.
struct Atom {
  enum Kind { label, number, stars, word } kind;
  std::string_view text;
  double value = 0.0;
};

bool starts_number(std::string_view t) {
  std::size_t i = (t.front() == '+' || t.front() == '-') ? 1 : 0;
  if (i < t.size() && t[i] == '.') ++i;
  return i < t.size() && std::isdigit(static_cast<unsigned char>(t[i]));
}

// Splits "RH=38.3", "14.98%RH", "74.68'F" into their label / number / unit pieces.
void lex_token(std::string_view t, std::vector<Atom>& atoms) {
  while (!t.empty()) {
    if (const auto eq = t.find('='); eq != std::string_view::npos && !starts_number(t)) {
      atoms.push_back({Atom::label, t.substr(0, eq)});
      t.remove_prefix(eq + 1);
      continue;
    }
    if (t.find_first_not_of("*.") == std::string_view::npos && t.find('*') != t.npos) {
      atoms.push_back({Atom::stars, t});
      return;
    }
    if (starts_number(t)) {
      const std::size_t skip = t.front() == '+' ? 1 : 0;
      double v = 0.0;
      const auto [ptr, ec] = std::from_chars(t.data() + skip, t.data() + t.size(), v);
      const auto used = static_cast<std::size_t>(ptr - t.data());
      if (ec == std::errc()) {
        atoms.push_back({Atom::number, t.substr(0, used), v});
        t.remove_prefix(used);
        continue;
      }
    }
    atoms.push_back({Atom::word, t});
    return;
  }
}

struct RawField {
  std::string_view label;
  double value = 0.0;
  std::string_view text;  // the number as printed
  std::string_view unit;
  bool stars = false;
};

// Pairs labels, numbers and units: "P= 1033.7 hPa", "RH 43.0 %RH T 21.0 'C", " 994.16".
std::vector<RawField> group_fields(const std::vector<Atom>& atoms) {
  std::vector<RawField> fields;
  std::string_view label;
  bool awaiting_unit = false;
  for (std::size_t i = 0; i < atoms.size(); ++i) {
    const Atom& a = atoms[i];
    switch (a.kind) {
      case Atom::label:
        label = a.text;
        awaiting_unit = false;
        break;
      case Atom::number:
      case Atom::stars:
        fields.push_back({label, a.value, a.text, {}, a.kind == Atom::stars});
        label = {};
        awaiting_unit = true;
        break;
      case Atom::word: {
        const bool next_is_value = i + 1 < atoms.size() && (atoms[i + 1].kind == Atom::number ||
                                                            atoms[i + 1].kind == Atom::stars);
        if (awaiting_unit && (find_unit(a.text) != nullptr || !next_is_value)) {
          fields.back().unit = a.text;
        } else {
          label = a.text;
        }
        awaiting_unit = false;
        break;
      }
    }
  }
  return fields;
}

bool is_hex(std::string_view t) {
  return !t.empty() && std::all_of(t.begin(), t.end(), [](char c) {
    return std::isxdigit(static_cast<unsigned char>(c)) != 0;
  });
}

std::string with_cr(std::string s) { return s + "\r"; }

}  // namespace

std::string ptu300_send(std::optional<int> address) {
  if (!address) return with_cr("SEND");
  if (*address < 0 || *address > 255) {
    throw InputError(fmt::format("PTU300 SEND address {}: expected 0..255", *address));
  }
  return with_cr(fmt::format("SEND {}", *address));
}
std::string ptu300_run() { return with_cr("R"); }
std::string ptu300_stop() { return with_cr("S"); }

std::string ptu300_smode(Ptu300Mode mode) {
  switch (mode) {
    case Ptu300Mode::stop:
      return with_cr("SMODE STOP");
    case Ptu300Mode::run:
      return with_cr("SMODE RUN");
    case Ptu300Mode::poll:
      return with_cr("SMODE POLL");
    case Ptu300Mode::send:
      return with_cr("SMODE SEND");
  }
  return with_cr("SMODE");
}

std::string ptu300_intv(int n, IntervalUnit unit) {
  if (n < 0 || n > 255) {
    throw InputError(fmt::format("PTU300 INTV interval {}: expected 0..255", n));
  }
  const char* u = unit == IntervalUnit::s ? "S" : unit == IntervalUnit::min ? "MIN" : "H";
  return with_cr(fmt::format("INTV {} {}", n, u));
}

std::string ptu300_form(std::string_view formatter) {
  if (formatter.find_first_of("\r\n") != std::string_view::npos || !is_printable_ascii(formatter)) {
    throw InputError(
        fmt::format("PTU300 FORM formatter {:?}: expected printable ASCII (write #r#n, not CR LF)",
                    std::string(formatter)));
  }
  return with_cr(formatter.empty() ? std::string("FORM") : fmt::format("FORM {}", formatter));
}

std::uint32_t ptu300_checksum(Ptu300Checksum kind, std::string_view message) {
  std::uint32_t sum = 0, x = 0;
  for (char c : message) {
    const auto b = static_cast<unsigned char>(c);
    sum += b;
    if (b != '$' && b != '*') x ^= b;
  }
  switch (kind) {
    case Ptu300Checksum::cs2:
      return sum % 256u;
    case Ptu300Checksum::cs4:
      return sum % 65536u;
    case Ptu300Checksum::csx:
      return x;
    case Ptu300Checksum::none:
      break;
  }
  return 0;
}

std::string ptu300_checksum_hex(Ptu300Checksum kind, std::string_view message) {
  const std::uint32_t v = ptu300_checksum(kind, message);
  return kind == Ptu300Checksum::cs4 ? fmt::format("{:04X}", v) : fmt::format("{:02X}", v);
}

Ptu300Codec::Ptu300Codec(Ptu300Config config)
    : config_(std::move(config)), splitter_(config_.max_line_bytes) {}

void Ptu300Codec::do_feed(std::span<const std::byte> bytes, std::vector<Ptu300Frame>& frames,
                          std::vector<CodecError>& errors) {
  splitter_.feed(
      bytes,
      [&](std::string_view line, std::uint64_t offset) {
        decode_line(line, offset, frames, errors);
      },
      [&](std::uint64_t offset) {
        report(errors, ErrorKind::overlong_line, offset, "PTU300: line longer than the buffer");
      });
}

Ptu300Quantity Ptu300Codec::quantity_of(std::string_view label, std::string_view unit) const {
  for (const auto& [name, q] : config_.aliases) {
    if (iequals(name, label)) return q;
  }
  if (iequals(label, "P") || iequals(label, "P1") || iequals(label, "P2")) {
    return Ptu300Quantity::pressure;
  }
  if (iequals(label, "P3H")) return Ptu300Quantity::pressure_tendency;
  if (iequals(label, "T")) return Ptu300Quantity::temperature;
  if (iequals(label, "RH")) return Ptu300Quantity::relative_humidity;
  if (iequals(label, "TD") || iequals(label, "TDP") || iequals(label, "TDF") ||
      iequals(label, "Td/f")) {
    return Ptu300Quantity::dew_point;
  }
  if (label.empty()) {  // an unlabelled custom FORM field: the unit says what it is
    if (const UnitInfo* u = find_unit(unit)) {
      return u->kind == UnitKind::pressure         ? Ptu300Quantity::pressure
             : u->kind == UnitKind::gauge_pressure ? Ptu300Quantity::gauge_pressure
             : u->kind == UnitKind::temperature    ? Ptu300Quantity::temperature
                                                   : Ptu300Quantity::relative_humidity;
    }
  }
  return Ptu300Quantity::other;
}

void Ptu300Codec::decode_line(std::string_view line, std::uint64_t offset,
                              std::vector<Ptu300Frame>& frames, std::vector<CodecError>& errors) {
  if (!is_printable_ascii(line)) {
    report(errors, ErrorKind::garbage, offset, "PTU300: non-printable bytes in a line");
    return;
  }
  // The '>' prompt (echo on, STOP mode) precedes the message; it is not part of it.
  const std::size_t start = line.find_first_not_of('>');
  if (start == std::string_view::npos) return;
  std::string_view msg = line.substr(start);
  const std::uint64_t msg_offset = offset + start;

  std::vector<Atom> atoms;
  const auto tokens = split_whitespace(msg);
  std::string_view checksum_token;
  if (config_.checksum != Ptu300Checksum::none && !tokens.empty()) {
    const std::size_t width = config_.checksum == Ptu300Checksum::cs4 ? 4 : 2;
    if (tokens.back().size() == width && is_hex(tokens.back())) checksum_token = tokens.back();
  }
  for (const auto t : tokens) {
    if (t.data() != checksum_token.data()) lex_token(t, atoms);
  }
  const bool has_values = std::any_of(atoms.begin(), atoms.end(), [](const Atom& a) {
    return a.kind == Atom::number || a.kind == Atom::stars;
  });
  if (!has_values) {
    Ptu300Frame f;
    f.text = std::string(msg);
    emit(frames, std::move(f));
    return;
  }
  if (config_.checksum != Ptu300Checksum::none) {
    if (checksum_token.empty()) {
      report(errors, ErrorKind::bad_checksum, msg_offset, "PTU300: checksum field missing");
      return;
    }
    const auto covered =
        msg.substr(0, static_cast<std::size_t>(checksum_token.data() - msg.data()));
    const std::string expected = ptu300_checksum_hex(config_.checksum, covered);
    if (!iequals(expected, checksum_token)) {
      report(errors, ErrorKind::bad_checksum, msg_offset,
             fmt::format("PTU300: checksum {} printed, {} computed", checksum_token, expected));
      return;
    }
  }

  Ptu300Frame f;
  for (const RawField& raw : group_fields(atoms)) {
    const std::string label(raw.label);
    Ptu300Quantity q = quantity_of(raw.label, raw.unit);
    const UnitInfo* printed = find_unit(raw.unit);
    // P in barg or psig: a gauge pressure (its reference is not stated), not the air's.
    if (q == Ptu300Quantity::pressure && printed && printed->kind == UnitKind::gauge_pressure)
      q = Ptu300Quantity::gauge_pressure;
    // Stars: the device says the value does not fit or is in error. Its statement, kept as an
    // unavailable field, not a codec error (a tendency code A3H is "*" until 3 h have passed).
    if (raw.stars) {
      f.fields.push_back({label, q, 0.0, std::string(raw.unit), false});
      continue;
    }
    Ptu300Field field{label, q, raw.value, std::string(raw.unit)};
    if (q != Ptu300Quantity::other) {
      const UnitKind want =
          q == Ptu300Quantity::relative_humidity ? UnitKind::humidity
          : q == Ptu300Quantity::gauge_pressure  ? UnitKind::gauge_pressure
          : (q == Ptu300Quantity::pressure || q == Ptu300Quantity::pressure_tendency)
              ? UnitKind::pressure
              : UnitKind::temperature;
      const UnitInfo* u = find_unit(raw.unit);
      if (u == nullptr || u->kind != want) {
        report(errors, ErrorKind::malformed, msg_offset,
               fmt::format("PTU300: {} has unit '{}', which is not a unit of its quantity", label,
                           raw.unit));
        continue;
      }
      if (u->exact.multiplier != 0) {
        field.value_si = parse_number_scaled(raw.text, u->exact).value_or(NAN);
      } else {
        field.value_si = (raw.value - u->zero) * u->factor;
      }
    }
    double lo = -INFINITY, hi = INFINITY;
    switch (q) {
      case Ptu300Quantity::pressure:
        lo = config_.min_pressure_pa, hi = config_.max_pressure_pa;
        break;
      case Ptu300Quantity::temperature:
      case Ptu300Quantity::dew_point:
        lo = config_.min_temperature_degc, hi = config_.max_temperature_degc;
        break;
      case Ptu300Quantity::relative_humidity:
        lo = config_.min_relative_humidity_pct, hi = config_.max_relative_humidity_pct;
        break;
      default:
        break;
    }
    if (!std::isfinite(field.value_si) || field.value_si < lo || field.value_si > hi) {
      report(errors, ErrorKind::out_of_range, msg_offset,
             fmt::format("PTU300: {} = {} {} outside [{}, {}] (SI units)", label, raw.value,
                         raw.unit, lo, hi));
      continue;
    }
    auto set = [&](std::optional<double>& slot, std::string_view main_label) {
      if (!slot || iequals(field.label, main_label)) slot = field.value_si;
    };
    if (q == Ptu300Quantity::pressure) set(f.pressure_pa, "P");
    if (q == Ptu300Quantity::temperature) set(f.temperature_degc, "T");
    if (q == Ptu300Quantity::relative_humidity) set(f.relative_humidity_pct, "RH");
    if (q == Ptu300Quantity::dew_point) set(f.dew_point_degc, "TD");
    f.fields.push_back(std::move(field));
  }
  if (!f.fields.empty()) emit(frames, std::move(f));
}

}  // namespace cal::drivers::codec
