// The instruments of a configuration's devices (shared by daq run, daq serve and daq replay).
// Every device is built through the registry: nothing here names a device.
#include "run_setup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "kinds/kind.hpp"

namespace daq {

namespace d = cal::drivers;
namespace t = cal::drivers::transport;

namespace {

// The readings a role needs from its device (one of them suffices).
std::vector<d::Quantity> needed(std::string_view role) {
  using Q = d::Quantity;
  if (role == "laser") return {Q::displacement_m};
  if (role == "air") return {Q::air_temperature_degc, Q::air_pressure_pa};
  if (role == "material") return {Q::material_temperature_degc};
  if (role == "ballbar") return {Q::length_m};
  if (role == "position") return {Q::machine_position_m};
  if (role == "indicator") return {Q::length_m};  // a straightness run's transducer
  if (role == "level") return {Q::angle_rad};     // a roll run's electronic level
  if (role == "angle") return {Q::angle_rad};     // a rotary run's angular reference
  return {};
}

// The drivers whose readings can fill the role, for the message: with their default options, or
// with another choice of one of them ("gauge with unit = \"arcsec\"": with its default unit, mm,
// no driver read angles, and the message of an angular reference or a level named none).
std::string drivers_for(std::string_view role) {
  std::vector<std::string> names;
  const auto want = needed(role);
  const auto gives = [&](const d::DeviceDriver& drv, const d::Options& options) {
    try {
      const auto q = drv.quantities(options, {std::string(role), 0});
      return std::any_of(want.begin(), want.end(), [&](d::Quantity w) {
        return std::find(q.begin(), q.end(), w) != q.end();
      });
    } catch (const cal::InputError&) {  // a combination of options the driver refuses
      return false;
    }
  };
  for (const auto* drv : d::device_drivers()) {
    if (gives(*drv, d::Options(drv->options()))) {
      names.emplace_back(drv->name());
      continue;
    }
    std::vector<std::string> with;
    for (const auto& spec : drv->options())
      for (const auto& choice : spec.choices) {
        d::Options other(drv->options());
        other.set(spec.name, choice);
        if (gives(*drv, other)) with.push_back(fmt::format("{} = \"{}\"", spec.name, choice));
      }
    if (!with.empty())
      names.push_back(fmt::format("{} with {}", drv->name(), fmt::join(with, " or ")));
  }
  return names.empty() ? std::string("none") : fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace

std::unique_ptr<t::Transport> make_transport(boost::asio::io_context& io,
                                             const cal::daq::DeviceConfig& c) {
  try {
    return t::make_transport(io, c.transport, d::driver(c.driver).hid_interface());
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("devices.{}.transport {}", c.id, e.what()));
  }
}

InstrumentSpec spec_of(const cal::daq::DeviceConfig& c, std::uint16_t device, int test_axis) {
  const auto& drv = d::driver(c.driver);
  InstrumentSpec s{.device = device,
                   .driver = c.driver,
                   .role = c.role,
                   .transport = c.transport,
                   .options = c.options,
                   .test_axis = test_axis,
                   .serial_number = c.serial_number,
                   .certificate = c.certificate,
                   .calibration_due = c.calibration_due,
                   .origin = c.origin};
  const auto want = needed(c.role);
  const auto have = drv.quantities(s.options, s.context());
  if (!want.empty() && std::none_of(want.begin(), want.end(), [&](d::Quantity w) {
        return std::find(have.begin(), have.end(), w) != have.end();
      }))
    throw cal::InputError(fmt::format(
        "devices.{}: driver '{}' (as configured) gives no {} readings, which role \"{}\" needs "
        "(drivers that do: {})",
        c.id, c.driver, d::to_string(want.front()), c.role, drivers_for(c.role)));
  return s;
}

const cal::daq::DeviceConfig& need(const cal::daq::Config& c, const char* role) {
  if (const auto* dc = c.device_for(role)) return *dc;
  throw cal::InputError(fmt::format("{}: no device with role = \"{}\"", c.source.string(), role));
}

const cal::daq::DeviceConfig& ballbar_device(const cal::daq::Config& c) {
  const auto& dc = need(c, "ballbar");
  spec_of(dc, 0);  // its driver must give lengths
  return dc;
}

std::chrono::microseconds scaled_poll(std::chrono::microseconds period, const RunOptions& o) {
  return std::chrono::microseconds(std::max<std::int64_t>(
      100, static_cast<std::int64_t>(static_cast<double>(period.count()) * o.poll_scale)));
}

d::InstrumentOptions instrument_options(const cal::daq::DeviceConfig& dc, const InstrumentSpec& s,
                                        const RunOptions& o,
                                        cal::replay::CaptureRecorder* recorder) {
  d::InstrumentOptions opt{.name = dc.id,
                           .backoff = {.max_attempts = o.give_up_after},
                           .clock = o.clock,
                           .recorder = recorder};
  opt.poll_period = scaled_poll(
      dc.poll_s > 0 ? std::chrono::microseconds(static_cast<std::int64_t>(dc.poll_s * 1e6))
                    : d::driver(s.driver).default_poll(s.options, s.context()),
      o);
  return opt;
}

namespace {

const cal::daq::DeviceConfig& device_of(const cal::daq::Config& config, const InstrumentSpec& s) {
  return *std::find_if(config.devices.begin(), config.devices.end(), [&](const auto& x) {
    return x.transport == s.transport && x.role == s.role;
  });
}

// What the check saw of one device.
struct Checked {
  const cal::daq::DeviceConfig* device = nullptr;
  std::unique_ptr<d::Instrument> instrument;
  bool may_be_silent = false;
  bool opened = false, spoke = false, closed = false;
  std::string why;  // the last state's reason (the transport's error text)
  bool done() const { return spoke || closed || (may_be_silent && opened); }
};

}  // namespace

void check_devices(const cal::daq::Config& config, const std::vector<InstrumentSpec>& specs,
                   std::chrono::duration<double> within,
                   const std::function<void(const std::string&)>& print) {
  boost::asio::io_context io;
  std::vector<Checked> checked(specs.size());
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const auto& s = specs[k];
    auto& c = checked[k];
    c.device = &device_of(config, s);
    c.may_be_silent = d::driver(s.driver).may_be_silent(s.options);
    auto options = instrument_options(*c.device, s, RunOptions{.give_up_after = 1}, nullptr);
    c.instrument = make_instrument(io, s, make_transport(io, *c.device), std::move(options));
    c.instrument->start({.reading = [&c](const d::Reading&) { c.spoke = true; },
                         .state =
                             [&c](d::InstrumentState st, std::string_view why) {
                               if (st == d::InstrumentState::configuring) c.opened = true;
                               if (st == d::InstrumentState::closed) c.closed = true;
                               if (!why.empty()) c.why = std::string(why);
                             },
                         // What the device says in its own words (e.g. the IDS3010's number
                         // and errorNumberToString text), warnings told apart from errors.
                         .message =
                             [&c, &print](const d::DeviceMessage& m) {
                               print(fmt::format("  devices.{} ({}): {}{}: {}", c.device->id,
                                                 c.device->transport, d::to_string(m.severity),
                                                 m.code ? fmt::format(" {}", m.code) : "", m.text));
                             }});
  }
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::nanoseconds>(within);
  while (std::chrono::steady_clock::now() < deadline &&
         !std::all_of(checked.begin(), checked.end(), [](const Checked& c) { return c.done(); }))
    io.run_for(std::chrono::milliseconds(20));
  std::vector<std::string> failed;
  for (auto& c : checked) {
    const std::string who = fmt::format("devices.{} ({})", c.device->id, c.device->transport);
    std::string state;
    if (c.spoke) {
      state = "speaks";
    } else if (c.may_be_silent && c.opened && !c.closed) {
      state = "open (it may be silent until it streams)";
    } else {
      // A closed instrument gave up after its one attempt: the reason is what follows.
      if (const auto at = c.why.find("attempts: "); c.closed && at != std::string::npos)
        c.why = c.why.substr(at + 10);
      state = c.closed   ? fmt::format("failed: {}", c.why)
              : c.opened ? fmt::format("opened but said nothing within {:.0f} s", within.count())
                         : fmt::format("did not open within {:.0f} s{}", within.count(),
                                       c.why.empty() ? "" : ": " + c.why);
      failed.push_back(who + ": " + state);
    }
    print(fmt::format("  {}: {}", who, state));
    c.instrument->stop();
  }
  io.poll();
  if (!failed.empty())
    throw cal::InputError(fmt::format("device check: {}", fmt::join(failed, "; ")));
}

// The instruments of a linear run (laser, air, material sensors, optional position feed).
std::vector<InstrumentSpec> linear_specs(const cal::daq::Config& config) {
  if (!config.linear)
    throw cal::InputError(fmt::format("{}: no [test.linear]", config.source.string()));
  std::vector<InstrumentSpec> specs;
  std::uint16_t n = 0;
  const int axis = config.linear->axis == "Y" ? 1 : config.linear->axis == "Z" ? 2 : 0;
  const auto& kind = kinds::kind(config.linear->measure.kind);
  try {
    kind.validate(*config.linear);
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: {}", config.source.string(), e.what()));
  }
  const std::string probe(kind.probe_role());
  // The roles it opens (a rotary run: no laser nor position feed), as its context lists them.
  const auto roles = kinds::linear_run_roles(kind);
  for (const auto& dc : config.devices)
    if (std::find(roles.begin(), roles.end(), dc.role) != roles.end())
      specs.push_back(spec_of(dc, n++, axis));
  if (!kind.stops_from_probe()) need(config, "laser");
  need(config, "air");
  if (!probe.empty()) need(config, probe.c_str());
  // An angular run reads two more laser axes: the laser must read them.
  if (const auto beams = kind.laser_channels(*config.linear); !beams.empty()) {
    const auto& laser = *std::find_if(specs.begin(), specs.end(),
                                      [](const InstrumentSpec& s) { return s.role == "laser"; });
    const auto have = d::driver(laser.driver).channels(laser.options, laser.context());
    for (const int b : beams)
      if (std::find(have.begin(), have.end(), b) == have.end())
        throw cal::InputError(fmt::format(
            "{}: test.linear.beams: the laser (driver '{}') does not read axis {}: add it to its "
            "axes",
            config.source.string(), laser.driver, b));
  }
  return specs;
}

InstrumentOrigin origin_of(const std::string& configured, const std::string& replay_capture) {
  const std::string what = configured.empty() ? "a device whose origin the capture does not record"
                           : configured == "simulated" ? "a twin of the built-in simulated shop"
                                                       : "a " + configured + " device";
  if (!replay_capture.empty())
    return {"replay", fmt::format("capture {}, recorded from {}", replay_capture, what)};
  return {configured, configured == "simulated" ? what : ""};
}

void place_linear_instrument(const InstrumentSpec& s, std::unique_ptr<d::Instrument> inst,
                             LinearRunSetup& setup) {
  setup.origins[s.role] = origin_of(s.origin, setup.replay ? setup.capture_path : "");
  const auto& drv = d::driver(s.driver);
  const auto channels = drv.channels(s.options, s.context());
  const int first = channels.empty() ? 0 : channels.front();
  if (s.role == "laser") {
    setup.laser = std::move(inst);
    setup.laser_channel = first;
  } else if (s.role == "air") {
    setup.air = std::move(inst);
  } else if (s.role == "indicator" || s.role == "level" || s.role == "angle") {
    setup.probe = std::move(inst);
  } else if (s.role == "position") {
    setup.position = std::move(inst);
    setup.position_channel = first;
    setup.position_on_change = drv.sends_on_change();
  } else {
    setup.material.push_back(std::move(inst));
    setup.material_channels.resize(setup.material.size() - 1);
    setup.material_channels.push_back(channels);  // each channel its own material sensor
  }
}

void add_linear_instruments(boost::asio::io_context& io, const cal::daq::Config& config,
                            const std::vector<InstrumentSpec>& specs, const RunOptions& o,
                            cal::replay::CaptureRecorder* recorder, LinearRunSetup& setup) {
  for (const auto& s : specs) {
    const auto& dc = device_of(config, s);
    auto inst =
        make_instrument(io, s, make_transport(io, dc), instrument_options(dc, s, o, recorder));
    if (o.wrap) inst = o.wrap(dc, std::move(inst));
    place_linear_instrument(s, std::move(inst), setup);
  }
}

}  // namespace daq
