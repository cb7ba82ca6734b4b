// SIMULATED IDS3010 (see twin.hpp): JSON-RPC 2.0, requests taken as whole JSON objects whether
// or not a line ending follows, answers ended with CR LF; results [error, values...],
// displacements in integer picometres.
#include "ids3010/twin.hpp"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "sim/twin_io.hpp"

namespace cal::drivers::sim {

using nlohmann::json;

struct IdsTwin::Impl : detail::TcpChannel {  // answers only: the channel's timer stays idle
  Impl(boost::asio::io_context& io, World& w, Clock c, IdsTwinConfig cfg)
      : TcpChannel(io, cfg.port), world(w), clock(std::move(c)), config(cfg) {}

  std::string mode(double now) const {
    if (measuring_since < 0) return aligning ? "optics alignment running" : "system idle";
    return now - measuring_since < config.starting_s ? "measurement starting"
                                                     : "measurement running";
  }

  // The device's answer to one request line.
  std::string answer(const std::string& line) {
    ++served;
    const json request = json::parse(line, nullptr, false);
    if (request.is_discarded() || !request.is_object() || !request.contains("method"))
      return json{{"jsonrpc", "2.0"},
                  {"error", {{"code", -32700}, {"message", "Parse error"}}},
                  {"id", nullptr}}
          .dump();
    const json id = request.value("id", json());
    const std::string method =
        request["method"].is_string() ? request["method"].get<std::string>() : "";
    const json params = request.value("params", json::array());
    const double now = clock();
    world.advance_to(now);
    json result = dispatch(method, params, now);
    if (result.is_null())
      return json{{"jsonrpc", "2.0"},
                  {"error", {{"code", -32601}, {"message", "Method not found"}}},
                  {"id", id}}
          .dump();
    return json{{"jsonrpc", "2.0"}, {"result", result}, {"id", id}}.dump();
  }

  // The machine state with the tool at the reflector of interferometer axis `a`: the axes plus
  // the error of that point (its nominal offset is constant and cancels against the datum).
  MachineState reflector_state(std::size_t a) const {
    MachineState state = world.state();
    if (const auto& r = config.reflector_mm[a]) {
      const auto e = world.machine().error_at(*r);
      for (std::size_t k = 0; k < 3; ++k)
        state.tool_mm[k] = state.axes_mm[k] + 1e-3 * e.translation_um[k];
    }
    return state;
  }

  std::int64_t displacement_pm(int axis) {
    const int machine_axis = config.machine_axis[static_cast<std::size_t>(axis)];
    if (machine_axis < 0) return 0;
    const double n = world.air().sample(world.time_s()).refractive_index;
    const auto a = static_cast<std::size_t>(axis);
    const double m = laser_reading_m(
        reflector_state(a), static_cast<kinematics::Axis>(machine_axis), config.datum_mm[a], n);
    return std::llround(m * 1e12);
  }

  std::int64_t axis_status(int axis, double now) const {
    if (measuring_since < 0 || now - measuring_since < config.starting_s)
      return error_not_measuring;
    return beam_lost[static_cast<std::size_t>(axis)] ? error_beam_lost : 0;
  }

  json dispatch(const std::string& method, const json& params, double now) {
    const std::string ids = std::string(codec::to_string(config.api)) + ".",
                      ecu = "com.attocube.ecu.", service = "com.attocube.system.";
    if (method == service + "getFirmwareVersion")
      return json::array(
          {0, config.api == codec::IdsApi::sen ? "1.9.1 (simulated)" : "1.8.2 (simulated)"});
    if (method == service + "errorNumberToString") {
      const std::int64_t n =
          params.size() == 2 && params[1].is_number_integer() ? params[1].get<std::int64_t>() : -1;
      if (n == error_not_measuring) return json::array({0, "measurement not running (simulated)"});
      if (n == error_beam_lost) return json::array({0, "signal lost on an axis (simulated)"});
      if (n == error_ecu_disabled) return json::array({0, "ECU interface not enabled (simulated)"});
      if (n == error_start_refused) return json::array({0, "laser not ready (simulated)"});
      if (n == error_ecu_refused) return json::array({0, "ECU interface refused (simulated)"});
      return json::array({0, "unknown error (simulated)"});
    }
    if (method == ids + "displacement.getAxesDisplacement" ||
        method == ids + "displacement.getAbsolutePositions") {
      std::int64_t code = 0;
      for (int a = 0; a < 3; ++a)
        if (config.machine_axis[static_cast<std::size_t>(a)] >= 0 && code == 0)
          code = axis_status(a, now);
      return json::array({code, displacement_pm(0), displacement_pm(1), displacement_pm(2)});
    }
    if (method == ids + "displacement.getAxisDisplacement") {
      const int axis =
          params.size() == 1 && params[0].is_number_integer() ? params[0].get<int>() : -1;
      if (axis < 0 || axis > 2) return json::array({-1});
      return json::array({axis_status(axis, now), displacement_pm(axis)});
    }
    if (method == ids + "displacement.getMeasurementEnabled")
      return json::array({0, measuring_since >= 0});
    if (method == ids + "system.startMeasurement") {
      if (config.refuse_start) return json::array({error_start_refused});
      if (measuring_since < 0) measuring_since = now;
      aligning = false;
      return json::array({0});
    }
    if (method == ids + "system.stopMeasurement") {
      measuring_since = -1;
      return json::array({0});
    }
    if (method == ids + "system.startOpticsAlignment") {
      measuring_since = -1;
      aligning = true;
      return json::array({0});
    }
    if (method == ids + "system.stopOpticsAlignment") {
      aligning = false;
      return json::array({0});
    }
    if (method == ids + "system.getCurrentMode") return json::array({0, mode(now)});
    if (method == ids + "system.getSystemError") return json::array({0});
    if (method == ids + "system.resetAxes") {
      for (std::size_t a = 0; a < 3; ++a)
        if (config.machine_axis[a] >= 0)
          config.datum_mm[a] =
              reflector_state(a).tool_mm[static_cast<std::size_t>(config.machine_axis[a])];
      return json::array({0});
    }
    if (method == ecu + "enable") {
      if (config.refuse_ecu_enable) return json::array({error_ecu_refused});
      ecu_enabled = true;
      return json::array({0});
    }
    if (method == ecu + "getEnabled") return json::array({0, ecu_enabled});
    if (method == ecu + "getConnected") return json::array({0, config.ecu_connected});
    // The ECU reports only once its interface is enabled (attocube's ecu.py: "Checking if the
    // ECU is connected can only be done on an enabled ECU interface").
    if (method.starts_with(ecu) && !ecu_enabled) return json::array({error_ecu_disabled});
    const AirSample air = world.air().sample(now);
    if (method == ecu + "getTemperatureInDegrees") return json::array({0, air.temperature_degc});
    if (method == ecu + "getPressureInHPa") return json::array({0, air.pressure_pa / 100.0});
    if (method == ecu + "getHumidityInPercent") return json::array({0, air.humidity_pct});
    if (method == ecu + "getRefractiveIndex") return json::array({0, air.refractive_index});
    return json();  // unknown: JSON-RPC "Method not found"
  }

  World& world;
  Clock clock;
  IdsTwinConfig config;
  std::array<bool, 3> beam_lost{};
  double measuring_since = -1.0;
  bool aligning = false;
  bool ecu_enabled = false;
  std::uint64_t served = 0;
};

IdsTwin::IdsTwin(boost::asio::io_context& io, World& world, Clock clock, IdsTwinConfig config)
    : IdsTwin(std::make_shared<Impl>(io, world, std::move(clock), config)) {}
namespace {
// A request is a whole JSON object, terminated or not: attocube's ACS.py (IDS-APIs) and the
// EPICS driver nmarks99/attocubeIDS write it with no terminator, the MATLAB wrappers' writeline
// with LF. Text that is not an object is a request when its line ends (answered "Parse error").
std::size_t request_end(std::string_view buffered) {
  const std::size_t first = buffered.find_first_not_of(" \t\r\n");
  if (first == buffered.npos) return 0;
  if (buffered[first] != '{') {
    const std::size_t eol = buffered.find('\n', first);
    return eol == buffered.npos ? 0 : eol + 1;
  }
  const std::size_t end = codec::json_object_end(buffered, first);
  return end == buffered.npos ? 0 : end;
}
}  // namespace

IdsTwin::IdsTwin(std::shared_ptr<Impl> impl) : TcpTwin(impl), impl_(std::move(impl)) {
  impl_->server->set_framing(request_end);
  impl_->server->start([impl = impl_.get(), server = impl_->server.get()](
                           const detail::LineServer::ClientPtr& client, const std::string& line) {
    // The device ends its answers with CR LF (ACS.py reads them with newline='\r\n').
    server->send(client, impl->answer(line) + "\r\n");
  });
}
void IdsTwin::set_beam_lost(int axis, bool lost) {
  impl_->beam_lost.at(static_cast<std::size_t>(axis)) = lost;
}
void IdsTwin::set_optics(const std::array<int, 3>& machine_axis,
                         const std::array<std::optional<Vec3>, 3>& reflector_mm) {
  impl_->config.machine_axis = machine_axis;
  impl_->config.reflector_mm = reflector_mm;
}
std::uint64_t IdsTwin::requests_served() const { return impl_->served; }

}  // namespace cal::drivers::sim
