// Attocube IDS3010 JSON-RPC codec. Method names and result layouts are those of attocube's
// public API (github.com/attocube-systems/IDS-APIs: python/displacement.py, system.py,
// ecu.py; matlab/IDS_displacement_getAxesDisplacement.m for the exact request line).
#include "ids3010/codec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"

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

constexpr double kMetresPerPicometre = 1e-12;
constexpr double kPascalPerHectopascal = 100.0;

bool has_control_bytes(std::string_view line) {
  for (char c : line) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 && u != '\t') return true;
  }
  return false;
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
  pending_[id] = std::move(p);
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
  bool in_string = false, escaped = false;
  for (std::size_t i = open; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{') {
      ++depth;
    } else if (c == '}' && --depth == 0) {
      return i + 1;
    }
  }
  return std::string_view::npos;
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
      bytes,
      [&](std::string_view line, std::uint64_t) {
        const auto j = nlohmann::json::parse(line, nullptr, false);
        if (j.is_discarded() || !j.is_object() || !j.contains("id") || !j.contains("method"))
          return;
        if (!j["id"].is_number_integer() || !j["method"].is_string()) return;
        const auto name = j["method"].get<std::string>();
        for (const auto& m : kMethods)
          for (const IdsApi api : {IdsApi::ids, IdsApi::sen}) {
            if (full_name(m, api) != name) continue;
            const auto id = j["id"].get<std::int64_t>();
            Pending p{m.method, api, {}};
            if (const auto params = j.find("params"); params != j.end() && params->is_array())
              for (const auto& e : *params)
                if (e.is_number_integer()) p.params.push_back(e.get<std::int64_t>());
            remember(id, std::move(p));
            next_id_ = std::max(next_id_, id + 1);
            if (m.interface == Interface::generation) api_ = api;  // the session's generation
            break;
          }
      },
      [](std::uint64_t) {});
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

void IdsCodec::decode_line(std::string_view line, std::uint64_t offset,
                           std::vector<IdsResponse>& frames, std::vector<CodecError>& errors) {
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
  IdsResponse r;
  r.id = id_it->get<std::int64_t>();
  const auto pending = pending_.find(r.id);
  if (pending == pending_.end()) {
    report(errors, ErrorKind::malformed, offset,
           fmt::format("IDS: response id {} matches no pending request", r.id));
    return;
  }
  r.method = pending->second.method;
  r.api = pending->second.api;
  r.params = std::move(pending->second.params);
  pending_.erase(pending);

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
  if (res == j.end() || !res->is_array() || res->empty() || !(*res)[0].is_number_integer()) {
    report(errors, ErrorKind::malformed, offset,
           fmt::format("IDS: response id {} has no result array with an error code", r.id));
    return;
  }
  r.error_code = (*res)[0].get<std::int64_t>();
  const ResultKind kind = info(r.method).result;
  const std::size_t needed = kind == ResultKind::none ? 0 : kind == ResultKind::three_pm ? 3 : 1;
  // With a non-zero code the device may leave the values out; that is its answer, not ours
  // to reject.
  if (res->size() < needed + 1) {
    if (r.error_code == 0) {
      report(errors, ErrorKind::malformed, offset,
             fmt::format("IDS: {} result has {} values, {} expected", method_name(r.method, r.api),
                         res->size() - 1, needed));
      return;
    }
    emit(frames, std::move(r));
    return;
  }
  auto number = [&](std::size_t i, std::string_view what, double scale, double lo,
                    double hi) -> std::optional<double> {
    const auto& v = (*res)[i];
    if (!v.is_number()) {
      report(errors, ErrorKind::malformed, offset,
             fmt::format("IDS: {} is not a number: {}", what, v.dump()));
      return std::nullopt;
    }
    const double x = v.get<double>() * scale;
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
        r.displacement_m[a] = number(a + 1, fmt::format("axis {} displacement (m)", a),
                                     kMetresPerPicometre, -dmax, dmax);
      }
      break;
    case ResultKind::one_pm:
      r.displacement_m[0] = number(1, "displacement (m)", kMetresPerPicometre, -dmax, dmax);
      break;
    case ResultKind::temperature_degc:
      r.temperature_degc = number(1, "ECU temperature (degC)", 1.0, limits_.min_temperature_degc,
                                  limits_.max_temperature_degc);
      break;
    case ResultKind::pressure_hpa:
      r.pressure_pa = number(1, "ECU pressure (Pa)", kPascalPerHectopascal, limits_.min_pressure_pa,
                             limits_.max_pressure_pa);
      break;
    case ResultKind::humidity:
      r.humidity_pct_rh = number(1, "ECU humidity (%RH)", 1.0, limits_.min_humidity_pct_rh,
                                 limits_.max_humidity_pct_rh);
      break;
    case ResultKind::index:
      r.refractive_index = number(1, "ECU refractive index", 1.0, limits_.min_refractive_index,
                                  limits_.max_refractive_index);
      break;
    case ResultKind::flag:
      if ((*res)[1].is_boolean()) {
        r.flag = (*res)[1].get<bool>();
      } else {
        report(errors, ErrorKind::malformed, offset, "IDS: flag result is not a boolean");
      }
      break;
    case ResultKind::text:
      if ((*res)[1].is_string()) {
        r.text = (*res)[1].get<std::string>();
        if (r.method == IdsMethod::get_current_mode) r.mode = r.text;
      } else {
        report(errors, ErrorKind::malformed, offset, "IDS: text result is not a string");
      }
      break;
  }
  emit(frames, std::move(r));
}

}  // namespace cal::drivers::codec
