// Attocube IDS3010 JSON-RPC codec. Method names and result layouts are those of attocube's
// public API (github.com/attocube-systems/IDS-APIs: python/displacement.py, system.py,
// ecu.py; matlab/IDS_displacement_getAxesDisplacement.m for the exact request line).
#include "ids3010/codec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <unordered_map>

#include "cal/analysis/error.hpp"
#include "cal/analysis/json_scan.hpp"

namespace cal::drivers::codec {
namespace {

// What result[1..] holds for each method.
enum class ResultKind {
  none,
  three_pm,
  one_pm,
  temperature_degc,
  pressure_hpa,
  humidity,
  index,
  flag,
  text
};

// Which interface a method belongs to: the displacement and system interfaces carry the
// generation (com.attocube.ids / com.attocube.sen), the ECU and the system service do not.
enum class Interface { generation, ecu, service };

struct MethodInfo {
  IdsMethod method;
  Interface interface;
  std::string_view name;  // after the interface's prefix
  std::size_t params;     // number of params the method takes
  ResultKind result;
};

constexpr MethodInfo kMethods[] = {
    {IdsMethod::get_axes_displacement, Interface::generation, "displacement.getAxesDisplacement", 0,
     ResultKind::three_pm},
    {IdsMethod::get_axis_displacement, Interface::generation, "displacement.getAxisDisplacement", 1,
     ResultKind::one_pm},
    {IdsMethod::get_absolute_positions, Interface::generation, "displacement.getAbsolutePositions",
     0, ResultKind::three_pm},
    {IdsMethod::get_measurement_enabled, Interface::generation,
     "displacement.getMeasurementEnabled", 0, ResultKind::flag},
    {IdsMethod::start_measurement, Interface::generation, "system.startMeasurement", 0,
     ResultKind::none},
    {IdsMethod::stop_measurement, Interface::generation, "system.stopMeasurement", 0,
     ResultKind::none},
    {IdsMethod::start_optics_alignment, Interface::generation, "system.startOpticsAlignment", 0,
     ResultKind::none},
    {IdsMethod::stop_optics_alignment, Interface::generation, "system.stopOpticsAlignment", 0,
     ResultKind::none},
    {IdsMethod::get_current_mode, Interface::generation, "system.getCurrentMode", 0,
     ResultKind::text},
    {IdsMethod::get_system_error, Interface::generation, "system.getSystemError", 0,
     ResultKind::none},
    {IdsMethod::reset_axes, Interface::generation, "system.resetAxes", 0, ResultKind::none},
    {IdsMethod::ecu_enable, Interface::ecu, "enable", 0, ResultKind::none},
    {IdsMethod::ecu_get_enabled, Interface::ecu, "getEnabled", 0, ResultKind::flag},
    {IdsMethod::ecu_get_connected, Interface::ecu, "getConnected", 0, ResultKind::flag},
    {IdsMethod::ecu_get_temperature, Interface::ecu, "getTemperatureInDegrees", 0,
     ResultKind::temperature_degc},
    {IdsMethod::ecu_get_pressure, Interface::ecu, "getPressureInHPa", 0, ResultKind::pressure_hpa},
    {IdsMethod::ecu_get_humidity, Interface::ecu, "getHumidityInPercent", 0, ResultKind::humidity},
    {IdsMethod::ecu_get_refractive_index, Interface::ecu, "getRefractiveIndex", 0,
     ResultKind::index},
    {IdsMethod::get_firmware_version, Interface::service, "getFirmwareVersion", 0,
     ResultKind::text},
    {IdsMethod::error_number_to_string, Interface::service, "errorNumberToString", 2,
     ResultKind::text},
};

const MethodInfo& info(IdsMethod m) {
  for (const auto& i : kMethods) {
    if (i.method == m) return i;
  }
  return kMethods[0];  // unreachable: every enumerator is in the table (tested)
}

std::string full_name(const MethodInfo& m, IdsApi api) {
  switch (m.interface) {
    case Interface::generation:
      return fmt::format("{}.{}", to_string(api), m.name);
    case Interface::ecu:
      return fmt::format("com.attocube.ecu.{}", m.name);
    case Interface::service:
      return fmt::format("com.attocube.system.{}", m.name);
  }
  return std::string(m.name);
}

// Exact factors: a reading is stored as the correctly rounded double of its value in SI
// (n pm is n / 10^12 m, one division of exact operands; "1013.27" hPa is strtod("1013.27e2")
// Pa), never n x 1e-12, which rounds twice and misses it for 14 % of picometre counts.
constexpr DecimalScale kMetresPerPicometre = kPicometresToMetres;
constexpr DecimalScale kPascalPerHectopascal = kHectopascalsToPascals;

bool has_control_bytes(std::string_view line) {
  for (char c : line) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 && u != '\t') return true;
  }
  return false;
}

// Every request name of kMethods in both generations, built once: replay recognises a recorded
// request by comparing its method with these (the order is that of kMethods, ids before sen).
struct KnownRequest {
  std::string name;
  const MethodInfo* method;
  IdsApi api;
};

const KnownRequest* find_request(std::string_view name) {
  static const std::vector<KnownRequest> table = [] {
    std::vector<KnownRequest> t;
    for (const auto& m : kMethods)
      for (const IdsApi api : {IdsApi::ids, IdsApi::sen})
        if (api == IdsApi::ids || m.interface == Interface::generation)
          t.push_back({full_name(m, api), &m, api});
    return t;
  }();
  // Looked up by hash: replay asks once per recorded request, and a linear search compared
  // the name with most of the table's 32 (emplace keeps the first of equal names, as it did).
  static const std::unordered_map<std::string_view, const KnownRequest*> by_name = [] {
    std::unordered_map<std::string_view, const KnownRequest*> m;
    for (const auto& k : table) m.emplace(k.name, &k);
    return m;
  }();
  // A session repeats one request (getAxesDisplacement, 10,000 a second): the last name found
  // is compared first, which spares the hash of its 50 characters.
  thread_local const KnownRequest* last = nullptr;
  if (last != nullptr && last->name == name) return last;
  const auto it = by_name.find(name);
  if (it == by_name.end()) return nullptr;
  return last = it->second;
}

// The one-pass reader of the lines caldaq and the device write: a JSON object whose members
// are strings of printable ASCII without escapes, numbers, or arrays of numbers, no key twice.
// Anything else (escapes, nesting, booleans, null, numbers needing more than an int64 or that
// from_chars will not round, a BOM) is not taken, and the line goes to the full JSON parser:
// what the fast path takes, the parser reads to the same values, so its result is the parser's.
struct FlatNumber {
  bool integer = false;  // no fraction or exponent and at most 18 digits (exact in int64)
  std::int64_t i = 0;
  double d = 0;           // as nlohmann's get<double>() gives it (strtod and from_chars both round)
  std::string_view text;  // the number as written (valid while its line is)
};

struct FlatValue {
  enum class Type { string, number, array } type = Type::string;
  std::string_view text;             // a string's characters
  FlatNumber number;                 // a number
  std::size_t first = 0, count = 0;  // an array's elements in FlatObject::elements
};

struct FlatObject {
  static constexpr std::size_t max_members = 6, max_elements = 8;
  std::array<std::string_view, max_members> keys{};
  std::array<FlatValue, max_members> values{};
  std::size_t members = 0;
  std::array<FlatNumber, max_elements> elements{};
  std::size_t element_count = 0;

  const FlatValue* find(std::string_view key) const {
    for (std::size_t m = 0; m < members; ++m)
      if (keys[m] == key) return &values[m];
    return nullptr;
  }
  std::span<const FlatNumber> elements_of(const FlatValue& array) const {
    return std::span(elements).subspan(array.first, array.count);
  }
};

// A JSON number (RFC 8259 section 6) at s[i]: -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?;
// i is moved past it.
bool scan_number(std::string_view s, std::size_t& i, FlatNumber& n) {
  const auto digit = [&] { return i < s.size() && s[i] >= '0' && s[i] <= '9'; };
  const std::size_t start = i;
  if (i < s.size() && s[i] == '-') ++i;
  const std::size_t int_start = i;
  if (!digit()) return false;
  if (s[i++] != '0')
    while (digit()) ++i;
  const std::size_t int_digits = i - int_start;
  bool fraction_or_exponent = false;
  if (i < s.size() && s[i] == '.') {
    ++i;
    if (!digit()) return false;
    while (digit()) ++i;
    fraction_or_exponent = true;
  }
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    if (!digit()) return false;
    while (digit()) ++i;
    fraction_or_exponent = true;
  }
  const char* first = s.data() + start;
  const char* last = s.data() + i;
  n.text = s.substr(start, i - start);
  if (!fraction_or_exponent) {
    if (int_digits > 18) return false;  // the parser's uint64 or double: left to it
    n.integer = true;
    std::from_chars(first, last, n.i);  // cannot fail: at most 18 digits
    n.d = static_cast<double>(n.i);
    return true;
  }
  n.integer = false;
  const auto [end, ec] = std::from_chars(first, last, n.d);
  return ec == std::errc{} && end == last;  // out of range: the parser decides
}

class FlatScanner {
 public:
  explicit FlatScanner(std::string_view s) : s_(s) {}

  // True if the whole of s is such an object (with JSON white space around and inside).
  bool object(FlatObject& o) {
    if (!eat('{')) return false;
    if (eat('}')) return at_end();
    do {
      if (o.members == FlatObject::max_members) return false;
      std::string_view key;
      if (!peek('"') || !string(key) || o.find(key) != nullptr || !eat(':')) return false;
      FlatValue& v = o.values[o.members];
      if (!value(o, v)) return false;
      o.keys[o.members++] = key;
    } while (eat(','));
    return eat('}') && at_end();
  }

 private:
  void space() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r'))
      ++i_;
  }
  bool peek(char c) {
    space();
    return i_ < s_.size() && s_[i_] == c;
  }
  bool eat(char c) {
    if (!peek(c)) return false;
    ++i_;
    return true;
  }
  bool at_end() {
    space();
    return i_ == s_.size();
  }

  bool value(FlatObject& o, FlatValue& v) {
    if (peek('"')) {
      v.type = FlatValue::Type::string;
      return string(v.text);
    }
    if (eat('[')) {
      v.type = FlatValue::Type::array;
      v.first = o.element_count;
      if (!eat(']')) {
        do {
          if (o.element_count == FlatObject::max_elements) return false;
          if (!number(o.elements[o.element_count++])) return false;
        } while (eat(','));
        if (!eat(']')) return false;
      }
      v.count = o.element_count - v.first;
      return true;
    }
    v.type = FlatValue::Type::number;
    return number(v.number);
  }

  // At the opening quote: printable ASCII up to the closing one, no escapes.
  bool string(std::string_view& out) {
    const std::size_t start = ++i_;
    while (i_ < s_.size() && s_[i_] != '"') {
      const auto u = static_cast<unsigned char>(s_[i_]);
      if (u < 0x20 || u > 0x7e || u == '\\') return false;
      ++i_;
    }
    if (i_ == s_.size()) return false;
    out = s_.substr(start, i_++ - start);
    return true;
  }

  bool number(FlatNumber& n) {
    space();
    return scan_number(s_, i_, n);
  }

  std::string_view s_;
  std::size_t i_ = 0;
};

// An integer as the scanner takes it without a fraction or exponent: -?(0|[1-9][0-9]*), at
// most 18 digits (exact in int64). At s[i]; i is moved past it.
bool plain_integer(std::string_view s, std::size_t& i, std::int64_t& out) {
  const std::size_t start = i;
  if (i < s.size() && s[i] == '-') ++i;
  const std::size_t digits = i;
  if (i == s.size() || s[i] < '0' || s[i] > '9') return false;
  if (s[i++] != '0')
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
  if (i - digits > 18) return false;
  std::from_chars(s.data() + start, s.data() + i, out);  // cannot fail: at most 18 digits
  return true;
}

// JSON white space after the object (a line's own terminator is not in it; a CR may be).
std::string_view without_trailing_space(std::string_view line) {
  while (!line.empty() &&
         (line.back() == ' ' || line.back() == '\t' || line.back() == '\n' || line.back() == '\r'))
    line.remove_suffix(1);
  return line;
}

// The literal's length known where it is compared (a template on the array): the compiler
// compares a few words in place, where a string_view compare called memcmp for every member
// of every replayed line (6 % of an IDS3010 replay, issue 32).
template <std::size_t N>
bool take(std::string_view s, std::size_t& i, const char (&literal)[N]) {
  constexpr std::size_t n = N - 1;  // without the terminating NUL
  if (i > s.size() || s.size() - i < n || std::memcmp(s.data() + i, literal, n) != 0) return false;
  i += n;
  return true;
}

// The request line encode() writes, byte for byte:
//   {"jsonrpc":"2.0","method":"NAME","params":[P,...],"id":N,"api":2}
// NAME printable ASCII without '"' or '\', the params and N integers as plain_integer takes
// them, JSON white space only after the closing brace. What this takes, FlatScanner reads to
// the same id, method and integer params; anything else returns false (and goes the general
// way). Replay learns every recorded request, so this is one compare per byte, no scan of
// keys.
struct EncodedRequest {
  std::int64_t id = 0;
  std::string_view method;
  std::vector<std::int64_t> params;
};
bool match_encoded_request(std::string_view line, EncodedRequest& r) {
  line = without_trailing_space(line);
  std::size_t i = 0;
  if (!take(line, i, R"({"jsonrpc":"2.0","method":")")) return false;
  const std::size_t name = i;
  while (i < line.size() && line[i] != '"') {
    const auto u = static_cast<unsigned char>(line[i]);
    if (u < 0x20 || u > 0x7e || u == '\\') return false;
    ++i;
  }
  r.method = line.substr(name, i - name);
  if (!take(line, i, R"(","params":[)")) return false;
  if (!take(line, i, "]")) {
    do {
      std::int64_t p = 0;
      if (r.params.size() == 8 || !plain_integer(line, i, p)) return false;  // the scanner's 8
      r.params.push_back(p);
    } while (take(line, i, ","));
    if (!take(line, i, "]")) return false;
  }
  return take(line, i, R"(,"id":)") && plain_integer(line, i, r.id) &&
         take(line, i, R"(,"api":2})") && i == line.size();
}

// An answer as the device (and the twin) writes it, byte for byte, members in one of the two
// orders seen: {"id":N,"jsonrpc":"2.0","result":[X,...]} or {"jsonrpc":"2.0","result":[X,...],
// "id":N}, N as plain_integer takes it, the X JSON numbers without white space (at most
// FlatObject's 8), JSON white space only after the closing brace. What this takes,
// FlatScanner reads to the same id and numbers; anything else returns false.
struct EncodedAnswer {
  std::int64_t id = 0;
  std::array<FlatNumber, FlatObject::max_elements> numbers{};
  std::size_t count = 0;
  std::span<const FlatNumber> result() const { return std::span(numbers).first(count); }
};
bool match_result_array(std::string_view line, std::size_t& i, EncodedAnswer& a) {
  if (!take(line, i, R"("result":[)")) return false;
  if (take(line, i, "]")) return true;
  do {
    if (a.count == a.numbers.size() || !scan_number(line, i, a.numbers[a.count++])) return false;
  } while (take(line, i, ","));
  return take(line, i, "]");
}
bool match_encoded_answer(std::string_view line, EncodedAnswer& a) {
  line = without_trailing_space(line);
  std::size_t i = 0;
  if (take(line, i, R"({"id":)"))
    return plain_integer(line, i, a.id) && take(line, i, R"(,"jsonrpc":"2.0",)") &&
           match_result_array(line, i, a) && take(line, i, "}") && i == line.size();
  return take(line, i, R"({"jsonrpc":"2.0",)") && match_result_array(line, i, a) &&
         take(line, i, R"(,"id":)") && plain_integer(line, i, a.id) && take(line, i, "}") &&
         i == line.size();
}

}  // namespace

std::string_view to_string(IdsApi api) {
  return api == IdsApi::sen ? "com.attocube.sen" : "com.attocube.ids";
}

std::string method_name(IdsMethod method, IdsApi api) { return full_name(info(method), api); }

bool returns_warning(IdsMethod method) {
  return info(method).result == ResultKind::three_pm || info(method).result == ResultKind::one_pm;
}

void IdsCodec::remember(std::int64_t id, Pending p) {
  // The node of the last answered request is used again: a map node allocated and freed per
  // request was the largest part of the malloc calls of a replay (issue 32). The same as
  // pending_[id] = p: a request of an id already pending replaces it.
  if (spare_.empty()) {
    pending_[id] = std::move(p);
  } else {
    spare_.key() = id;
    spare_.mapped() = std::move(p);
    auto placed = pending_.insert(std::move(spare_));
    if (!placed.inserted) {
      placed.position->second = std::move(placed.node.mapped());
      spare_ = std::move(placed.node);
    }
  }
  if (pending_.size() > max_pending) pending_.erase(pending_.begin());
}

IdsCodec::IdsCodec(IdsLimits limits, std::size_t max_line_bytes)
    : limits_(limits), splitter_(max_line_bytes) {}

std::string IdsCodec::encode(IdsMethod method, std::span<const IdsParam> params) {
  const MethodInfo& mi = info(method);
  if (params.size() != mi.params) {
    throw InputError(fmt::format("IDS request {}: {} params given, {} expected",
                                 full_name(mi, api_), params.size(), mi.params));
  }
  const std::string name = full_name(mi, api_);
  nlohmann::ordered_json j;
  j["jsonrpc"] = "2.0";
  j["method"] = name;
  j["params"] = nlohmann::ordered_json::array();
  for (const auto& p : params) {
    std::visit([&](auto v) { j["params"].push_back(v); }, p);
  }
  if (method == IdsMethod::get_axis_displacement) {
    const auto* axis = std::get_if<std::int64_t>(&params[0]);
    if (axis == nullptr || *axis < 0 || *axis > 2) {
      throw InputError(fmt::format("IDS request {}: axis {} given, an integer 0..2 expected", name,
                                   j["params"][0].dump()));
    }
  }
  const std::int64_t id = next_id_++;
  j["id"] = id;
  j["api"] = 2;  // as in attocube's own wrappers (matlab/IDS_*.m)
  Pending p{method, api_, {}};
  for (const auto& param : params)
    if (const auto* i = std::get_if<std::int64_t>(&param)) p.params.push_back(*i);
  remember(id, std::move(p));
  return j.dump() + "\n";
}

std::size_t json_object_end(std::string_view text, std::size_t open) {
  int depth = 0;
  const auto close = cal::text::find_outside_json_strings(text, open, [&](char c) {
    if (c == '{') ++depth;
    return c == '}' && --depth == 0;
  });
  return close == std::string_view::npos ? close : close + 1;
}

std::vector<std::string_view> json_objects(std::string_view text) {
  std::vector<std::string_view> out;
  constexpr std::string_view blank = " \t\r\n";
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t open = text.find('{', at);
    // Stray text before the next object (from its first non-blank character) is a piece too.
    const std::size_t stray = text.find_first_not_of(blank, at);
    if (stray < open) out.push_back(text.substr(stray, open == text.npos ? open : open - stray));
    if (open == text.npos) break;
    const std::size_t end = json_object_end(text, open);
    out.push_back(text.substr(open, end == text.npos ? end : end - open));
    at = end;
  }
  return out;
}

void IdsCodec::note_requests(std::span<const std::byte> bytes) {
  sent_splitter_.feed(
      bytes, [&](std::string_view line, std::uint64_t) { note_request(line); },
      [](std::uint64_t) {});
}

void IdsCodec::note_request(std::string_view line) {
  // The request lines encode() writes are matched byte for byte; other flat objects are taken
  // in one pass; others (attocube's client puts spaces and "api" before "id") go through the
  // JSON parser, with the same result.
  if (EncodedRequest r; match_encoded_request(line, r))
    return learn(r.id, r.method, std::move(r.params));
  if (FlatObject o; FlatScanner(line).object(o)) {
    const FlatValue* id = o.find("id");
    const FlatValue* method = o.find("method");
    if (id == nullptr || method == nullptr || id->type != FlatValue::Type::number ||
        !id->number.integer || method->type != FlatValue::Type::string)
      return;
    std::vector<std::int64_t> params;
    if (const FlatValue* p = o.find("params"); p != nullptr && p->type == FlatValue::Type::array)
      for (const FlatNumber& e : o.elements_of(*p))
        if (e.integer) params.push_back(e.i);
    return learn(id->number.i, method->text, std::move(params));
  }
  const auto j = nlohmann::json::parse(line, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("id") || !j.contains("method")) return;
  if (!j["id"].is_number_integer() || !j["method"].is_string()) return;
  std::vector<std::int64_t> params;
  if (const auto p = j.find("params"); p != j.end() && p->is_array())
    for (const auto& e : *p)
      if (e.is_number_integer()) params.push_back(e.get<std::int64_t>());
  learn(j["id"].get<std::int64_t>(), j["method"].get_ref<const std::string&>(), std::move(params));
}

void IdsCodec::learn(std::int64_t id, std::string_view method, std::vector<std::int64_t> params) {
  const KnownRequest* known = find_request(method);
  if (known == nullptr) return;  // not a request of ours: ignored
  remember(id, Pending{known->method->method, known->api, std::move(params)});
  next_id_ = std::max(next_id_, id + 1);
  if (known->method->interface == Interface::generation) api_ = known->api;  // the session's
}

void IdsCodec::do_feed(std::span<const std::byte> bytes, std::vector<IdsResponse>& frames,
                       std::vector<CodecError>& errors) {
  splitter_.feed(
      bytes,
      [&](std::string_view line, std::uint64_t offset) {
        decode_line(line, offset, frames, errors);
      },
      [&](std::uint64_t offset) {
        report(errors, ErrorKind::overlong_line, offset, "IDS: line longer than the buffer");
      });
}

// result[] of an answer, read by the fast path (numbers only) or by the JSON parser.
class IdsCodec::ResultView {
 public:
  explicit ResultView(const nlohmann::json& array) : json_(&array) {}
  explicit ResultView(std::span<const FlatNumber> numbers) : numbers_(numbers) {}

  std::size_t size() const { return json_ != nullptr ? json_->size() : numbers_.size(); }
  bool is_integer(std::size_t i) const {
    return json_ != nullptr ? (*json_)[i].is_number_integer() : numbers_[i].integer;
  }
  std::int64_t integer(std::size_t i) const {
    return json_ != nullptr ? (*json_)[i].get<std::int64_t>() : numbers_[i].i;
  }
  bool is_number(std::size_t i) const { return json_ == nullptr || (*json_)[i].is_number(); }
  double number(std::size_t i) const {
    return json_ != nullptr ? (*json_)[i].get<double>() : numbers_[i].d;
  }
  // number(i) x scale, correctly rounded: an integer count divided by the exact power of ten,
  // a fraction from its text with the exponent moved. The JSON parser keeps no text: its
  // double's shortest decimal stands for it (the same value for a number written with at most
  // 15 significant digits, as the device writes them).
  double scaled(std::size_t i, DecimalScale scale) const {
    if (json_ != nullptr) {
      const auto& v = (*json_)[i];
      if (v.is_number_integer() &&
          !(v.is_number_unsigned() &&
            v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX)))
        return scaled_count(v.get<std::int64_t>(), scale);
      return scaled_double(v.get<double>(), scale);
    }
    const FlatNumber& n = numbers_[i];
    if (n.integer) return scaled_count(n.i, scale);
    if (const auto v = parse_number_scaled(n.text, scale)) return *v;
    return scaled_double(n.d, scale);  // beyond the double's range: what the product gives
  }
  bool is_boolean(std::size_t i) const { return json_ != nullptr && (*json_)[i].is_boolean(); }
  bool boolean(std::size_t i) const { return (*json_)[i].get<bool>(); }
  bool is_string(std::size_t i) const { return json_ != nullptr && (*json_)[i].is_string(); }
  std::string string(std::size_t i) const { return (*json_)[i].get<std::string>(); }
  std::string dump(std::size_t i) const { return json_ != nullptr ? (*json_)[i].dump() : ""; }

 private:
  const nlohmann::json* json_ = nullptr;
  std::span<const FlatNumber> numbers_;
};

void IdsCodec::decode_line(std::string_view line, std::uint64_t offset,
                           std::vector<IdsResponse>& frames, std::vector<CodecError>& errors) {
  // The answers the device writes ({"jsonrpc":"2.0","result":[0,...],"id":n}, members in any
  // order) in one pass; everything else through the JSON parser. A line the fast path takes
  // has no control bytes (its strings are printable, its white space cannot be in a line).
  // The two byte layouts the device writes are matched without a scan of keys first.
  if (EncodedAnswer a; match_encoded_answer(line, a)) {
    if (auto r = take_pending(a.id, offset, errors))
      decode_result(std::move(*r), ResultView(a.result()), offset, frames, errors);
    return;
  }
  if (FlatObject o; FlatScanner(line).object(o)) {
    const FlatValue* id = o.find("id");
    const FlatValue* res = o.find("result");
    if (id != nullptr && id->type == FlatValue::Type::number && id->number.integer &&
        res != nullptr && res->type == FlatValue::Type::array) {
      if (auto r = take_pending(id->number.i, offset, errors))
        decode_result(std::move(*r), ResultView(o.elements_of(*res)), offset, frames, errors);
      return;
    }
  }
  if (has_control_bytes(line)) {
    report(errors, ErrorKind::garbage, offset, "IDS: control bytes in a JSON line");
    return;
  }
  const auto j = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    report(errors, ErrorKind::malformed, offset, "IDS: not a JSON object");
    return;
  }
  const auto id_it = j.find("id");
  if (id_it == j.end() || !id_it->is_number_integer()) {
    report(errors, ErrorKind::malformed, offset, "IDS: response without an integer id");
    return;
  }
  auto pending = take_pending(id_it->get<std::int64_t>(), offset, errors);
  if (!pending) return;
  IdsResponse& r = *pending;

  // A JSON-RPC 2.0 error object (jsonrpc.org/specification, 5.1) instead of a result.
  if (const auto e = j.find("error"); e != j.end() && e->is_object()) {
    const auto code = e->find("code");
    r.error_code = code != e->end() && code->is_number_integer() ? code->get<std::int64_t>() : -1;
    r.rpc_error = true;
    const auto msg = e->find("message");
    if (msg != e->end() && msg->is_string()) r.error_message = msg->get<std::string>();
    emit(frames, std::move(r));
    return;
  }
  const auto res = j.find("result");
  if (res == j.end() || !res->is_array()) {
    report_no_result(r.id, offset, errors);
    return;
  }
  decode_result(std::move(r), ResultView(*res), offset, frames, errors);
}

std::optional<IdsResponse> IdsCodec::take_pending(std::int64_t id, std::uint64_t offset,
                                                  std::vector<CodecError>& errors) {
  const auto pending = pending_.find(id);
  if (pending == pending_.end()) {
    report(errors, ErrorKind::malformed, offset,
           fmt::format("IDS: response id {} matches no pending request", id));
    return std::nullopt;
  }
  IdsResponse r;
  r.id = id;
  r.method = pending->second.method;
  r.api = pending->second.api;
  r.params = std::move(pending->second.params);
  spare_ = pending_.extract(pending);  // its node kept for the next request (remember)
  return r;
}

void IdsCodec::report_no_result(std::int64_t id, std::uint64_t offset,
                                std::vector<CodecError>& errors) {
  report(errors, ErrorKind::malformed, offset,
         fmt::format("IDS: response id {} has no result array with an error code", id));
}

void IdsCodec::decode_result(IdsResponse r, const ResultView& res, std::uint64_t offset,
                             std::vector<IdsResponse>& frames, std::vector<CodecError>& errors) {
  if (res.size() == 0 || !res.is_integer(0)) return report_no_result(r.id, offset, errors);
  r.error_code = res.integer(0);
  const ResultKind kind = info(r.method).result;
  const std::size_t needed = kind == ResultKind::none ? 0 : kind == ResultKind::three_pm ? 3 : 1;
  // With a non-zero code the device may leave the values out; that is its answer, not ours
  // to reject.
  if (res.size() < needed + 1) {
    if (r.error_code == 0) {
      report(errors, ErrorKind::malformed, offset,
             fmt::format("IDS: {} result has {} values, {} expected", method_name(r.method, r.api),
                         res.size() - 1, needed));
      return;
    }
    emit(frames, std::move(r));
    return;
  }
  auto number = [&](std::size_t i, std::string_view what, DecimalScale scale, double lo,
                    double hi) -> std::optional<double> {
    if (!res.is_number(i)) {
      report(errors, ErrorKind::malformed, offset,
             fmt::format("IDS: {} is not a number: {}", what, res.dump(i)));
      return std::nullopt;
    }
    const double x = scale == kUnitScale ? res.number(i) : res.scaled(i, scale);
    if (!std::isfinite(x) || x < lo || x > hi) {
      report(errors, ErrorKind::out_of_range, offset,
             fmt::format("IDS: {} = {} outside [{}, {}]", what, x, lo, hi));
      return std::nullopt;
    }
    return x;
  };
  const double dmax = limits_.max_abs_displacement_m;
  switch (kind) {
    case ResultKind::none:
      break;
    case ResultKind::three_pm:
      for (std::size_t a = 0; a < 3; ++a) {
        // Named without formatting: this runs for every reading.
        static constexpr std::string_view kWhat[] = {
            "axis 0 displacement (m)", "axis 1 displacement (m)", "axis 2 displacement (m)"};
        r.displacement_m[a] = number(a + 1, kWhat[a], kMetresPerPicometre, -dmax, dmax);
      }
      break;
    case ResultKind::one_pm:
      r.displacement_m[0] = number(1, "displacement (m)", kMetresPerPicometre, -dmax, dmax);
      break;
    case ResultKind::temperature_degc:
      r.temperature_degc = number(1, "ECU temperature (degC)", kUnitScale,
                                  limits_.min_temperature_degc, limits_.max_temperature_degc);
      break;
    case ResultKind::pressure_hpa:
      r.pressure_pa = number(1, "ECU pressure (Pa)", kPascalPerHectopascal, limits_.min_pressure_pa,
                             limits_.max_pressure_pa);
      break;
    case ResultKind::humidity:
      r.humidity_pct_rh = number(1, "ECU humidity (%RH)", kUnitScale, limits_.min_humidity_pct_rh,
                                 limits_.max_humidity_pct_rh);
      break;
    case ResultKind::index:
      r.refractive_index = number(1, "ECU refractive index", kUnitScale,
                                  limits_.min_refractive_index, limits_.max_refractive_index);
      break;
    case ResultKind::flag:
      if (res.is_boolean(1)) {
        r.flag = res.boolean(1);
      } else {
        report(errors, ErrorKind::malformed, offset, "IDS: flag result is not a boolean");
      }
      break;
    case ResultKind::text:
      if (res.is_string(1)) {
        r.text = res.string(1);
        if (r.method == IdsMethod::get_current_mode) r.mode = r.text;
      } else {
        report(errors, ErrorKind::malformed, offset, "IDS: text result is not a string");
      }
      break;
  }
  emit(frames, std::move(r));
}

}  // namespace cal::drivers::codec
