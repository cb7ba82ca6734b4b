// The instruments of a configuration's devices (shared by daq run and daq serve).
#include "run_setup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstdio>

#include "cal/analysis/error.hpp"
#include "cal/drivers/instruments.hpp"
#include "cal/drivers/transport/hid.hpp"

namespace daq {

namespace d = cal::drivers;
namespace t = cal::drivers::transport;
using namespace std::chrono_literals;

namespace {
// "hid VID:PID" (hex, as lsusb prints them), or "hid /dev/hidrawN".
t::HidSettings hid_settings(const cal::daq::DeviceConfig& c, const std::string& rest) {
  if (rest.starts_with("/")) return {.path = rest};
  unsigned vid = 0, pid = 0;
  char extra = 0;
  if (std::sscanf(rest.c_str(), "%4x:%4x%c", &vid, &pid, &extra) != 2)
    throw cal::InputError(
        fmt::format("devices.{}.transport '{}': expected hid VID:PID (hex) or hid /dev/hidrawN",
                    c.id, c.transport));
  // TEMPer sticks expose a keyboard interface too; the sensor answers on interface 1.
  return {.vendor_id = static_cast<std::uint16_t>(vid),
          .product_id = static_cast<std::uint16_t>(pid),
          .interface_number = c.driver == "temper" ? 1 : -1};
}

}  // namespace

namespace {
// "tcp HOST:PORT" with a port 1 .. 65535.
t::TcpSettings tcp_settings(const cal::daq::DeviceConfig& c, const std::string& rest) {
  const auto colon = rest.rfind(':');
  unsigned port = 0;
  const char* first = colon == std::string::npos ? nullptr : rest.data() + colon + 1;
  const char* last = rest.data() + rest.size();
  if (colon == std::string::npos || colon == 0 || std::from_chars(first, last, port).ptr != last ||
      port < 1 || port > 65535)
    throw cal::InputError(
        fmt::format("devices.{}.transport '{}': expected tcp HOST:PORT (a port 1 .. 65535)", c.id,
                    c.transport));
  return {.host = rest.substr(0, colon), .port = static_cast<std::uint16_t>(port)};
}

t::SerialSettings serial_settings(const cal::daq::DeviceConfig& c, const std::string& rest) {
  const auto sp = rest.find(' ');
  if (sp == std::string::npos || sp == 0)
    throw cal::InputError(fmt::format(
        "devices.{}.transport '{}': expected serial DEVICE BAUD FRAME", c.id, c.transport));
  try {
    return t::parse_serial_settings(rest.substr(sp + 1), {.device = rest.substr(0, sp)});
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("devices.{}.transport: {}", c.id, e.what()));
  }
}

std::pair<std::string, std::string> split_transport(const cal::daq::DeviceConfig& c) {
  const auto space = c.transport.find(' ');
  return {c.transport.substr(0, space),
          space == std::string::npos ? "" : c.transport.substr(space + 1)};
}
}  // namespace

void check_transport(const cal::daq::DeviceConfig& c) {
  const auto [kind, rest] = split_transport(c);
  if (kind == "tcp") return void(tcp_settings(c, rest));
  if (kind == "serial") return void(serial_settings(c, rest));
  if (kind == "hid") return void(hid_settings(c, rest));
  throw cal::InputError(
      fmt::format("devices.{}: transport '{}' has no driver here yet", c.id, c.transport));
}

std::unique_ptr<t::Transport> make_transport(boost::asio::io_context& io,
                                             const cal::daq::DeviceConfig& c) {
  check_transport(c);
  const auto [kind, rest] = split_transport(c);
  if (kind == "tcp") return t::make_tcp(io, tcp_settings(c, rest));
  if (kind == "serial") return t::make_serial(io, serial_settings(c, rest));
  return t::make_hid(io, hid_settings(c, rest));
}

InstrumentSpec spec_of(const cal::daq::DeviceConfig& c, std::uint16_t device) {
  InstrumentSpec s{.device = device, .driver = c.driver, .role = c.role, .transport = c.transport};
  if (!c.axes.empty()) {
    s.ids_axes = {false, false, false};
    for (int a : c.axes) s.ids_axes[static_cast<std::size_t>(a)] = true;
  }
  s.gauge = {
      .request = c.request, .pattern = c.pattern, .unit = d::codec::gauge_unit_from_string(c.unit)};
  if (s.gauge.unit == d::codec::GaugeUnit::degc) s.gauge.min_si = -40, s.gauge.max_si = 150;
  s.temper_family = c.family;
  s.feed_key = c.key;
  s.feed_column = c.column;
  s.feed_unit = c.unit == "in" ? "in" : "mm";
  static constexpr std::string_view drivers[] = {"ids3010", "ptu300",     "gauge",
                                                 "temper",  "halsampler", "shdr"};
  if (std::find(std::begin(drivers), std::end(drivers), c.driver) == std::end(drivers))
    throw cal::InputError(
        fmt::format("devices.{}: driver '{}' is not available for runs yet", c.id, c.driver));
  return s;
}

const cal::daq::DeviceConfig& need(const cal::daq::Config& c, const char* role) {
  if (const auto* d = c.device_for(role)) return *d;
  throw cal::InputError(fmt::format("{}: no device with role = \"{}\"", c.source.string(), role));
}

std::chrono::microseconds scaled_poll(double poll_s, const RunOptions& o) {
  return std::chrono::microseconds(
      std::max<std::int64_t>(100, static_cast<std::int64_t>(poll_s * o.poll_scale * 1e6)));
}

const cal::daq::DeviceConfig& ballbar_device(const cal::daq::Config& c) {
  const auto& dc = need(c, "ballbar");
  if (dc.driver != "gauge")
    throw cal::InputError(fmt::format("{}: devices.{}: the ballbar needs driver = \"gauge\"",
                                      c.source.string(), dc.id));
  return dc;
}

d::InstrumentOptions instrument_options(const cal::daq::DeviceConfig& dc, const RunOptions& o,
                                        cal::replay::CaptureRecorder* recorder) {
  d::InstrumentOptions opt{.name = dc.id,
                           .backoff = {.max_attempts = o.give_up_after},
                           .clock = o.clock,
                           .recorder = recorder};
  if (dc.poll_s > 0) opt.poll_period = scaled_poll(dc.poll_s, o);
  return opt;
}

// The instruments of a linear run (laser, air, material sensors, optional position feed).
std::vector<InstrumentSpec> linear_specs(const cal::daq::Config& config) {
  if (!config.linear)
    throw cal::InputError(fmt::format("{}: no [test.linear]", config.source.string()));
  std::vector<InstrumentSpec> specs;
  std::uint16_t n = 0;
  // The position feed reports the test axis: its channel is the axis' index.
  const int axis = config.linear->axis == "Y" ? 1 : config.linear->axis == "Z" ? 2 : 0;
  for (const auto& dc : config.devices) {
    if (dc.role != "laser" && dc.role != "air" && dc.role != "material" && dc.role != "position")
      continue;
    specs.push_back(spec_of(dc, n++));
    specs.back().feed_axis = axis;
    if (specs.back().feed_key.empty()) specs.back().feed_key = config.linear->axis + "act";
  }
  need(config, "laser"), need(config, "air");
  return specs;
}

void add_linear_instruments(boost::asio::io_context& io, const cal::daq::Config& config,
                            const std::vector<InstrumentSpec>& specs, const RunOptions& o,
                            cal::replay::CaptureRecorder* recorder, LinearRunSetup& setup) {
  for (const auto& s : specs) {
    const auto& dc = *std::find_if(
        config.devices.begin(), config.devices.end(),
        [&](const auto& x) { return x.transport == s.transport && x.role == s.role; });
    auto opt = instrument_options(dc, o, recorder);
    if (dc.poll_s <= 0 && (s.driver == "ptu300" || s.driver == "temper" || s.role == "material"))
      opt.poll_period = scaled_poll(1.0, o);
    if (dc.poll_s <= 0 && s.driver == "shdr") opt.poll_period = 5000ms;  // "* PING" heartbeats
    auto inst = make_instrument(io, s, make_transport(io, dc), opt);
    if (o.wrap) inst = o.wrap(dc, std::move(inst));
    if (s.role == "laser")
      setup.laser = std::move(inst);
    else if (s.role == "air")
      setup.air = std::move(inst);
    else if (s.role == "position")
      setup.position = std::move(inst), setup.position_channel = s.feed_axis;
    else
      setup.material.push_back(std::move(inst));
  }
}

}  // namespace daq
