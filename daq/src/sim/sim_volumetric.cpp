// The simulated volumetric campaign (see sim_volumetric.hpp).
#include "sim_volumetric.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/error.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "ids3010/instrument.hpp"
#include "kinds/kind.hpp"
#include "line_gauge/instrument.hpp"
#include "linear_run.hpp"
#include "ptu300/instrument.hpp"
#include "roles.hpp"

namespace daq {

namespace kin = cal::kinematics;

namespace {

constexpr int kTargets = 6;
constexpr double kProbeZMm = -100.0;  // the probe, reflectors and level 100 mm below the spindle
// At targets of the other axes: the angles there are measured, not interpolated between targets.
constexpr std::array<double, 3> kStationaryMm{200.0, 240.0, 180.0};

// Amplitude (um or urad) and the shape a1 s + a2 s^2 + a3 s^3 over s = q / travel.
struct Shape {
  double amplitude, a1, a2, a3;
};
// In kin::Component order: E_XX E_YX E_ZX E_AX E_BX E_CX, E_XY ... E_CY, E_XZ ... E_CZ.
constexpr std::array<Shape, 18> kShapes{{
    {6.0, 1.0, 0.5, -0.6},
    {4.0, 0.0, 1.0, -0.5},
    {3.0, 0.2, -1.0, 0.8},
    {12.0, 1.0, -0.5, 0.0},
    {15.0, 0.5, 0.5, -0.3},
    {-10.0, 1.0, -1.2, 0.4},
    {3.0, 0.1, 1.2, -0.9},
    {-5.0, 1.0, 0.3, -0.2},
    {2.5, 0.3, -0.7, 1.0},
    {9.0, 1.0, 0.0, -0.6},
    {-8.0, 0.4, 0.8, -0.5},
    {11.0, 0.7, -0.3, 0.2},
    {2.0, 0.5, 1.0, -1.0},
    {-3.0, 0.0, 1.0, 0.2},
    {7.0, 1.0, -0.4, 0.3},
    {6.0, 1.0, -0.8, 0.5},
    {-7.0, 0.2, 0.9, -0.4},
    {5.0, 1.0, 0.5, -0.8},
}};

std::vector<double> targets_of(const cal::daq::LinearTestConfig& l) {
  return linear_plan(l).targets_mm;
}

cal::daq::LinearTestConfig base_test(std::size_t axis) {
  cal::daq::LinearTestConfig l;
  l.axis = std::string(1, "XYZ"[axis]);
  l.first_mm = 0.0;
  l.last_mm = kSimTravelMm[axis];
  l.count = kTargets;
  l.runs = 1;
  l.bidirectional = true;
  l.overrun_mm = 3.0;
  l.feed_mm_per_min = 6000.0;
  l.dwell_s = 4.0;  // a gauge answering late still finds the machine standing
  l.measure.stationary_mm = kStationaryMm;
  l.measure.probe_offset_mm = {0.0, 0.0, kProbeZMm};
  return l;
}

}  // namespace

kin::Machine volumetric_geometry(kin::Topology t) {
  kin::Machine m;
  m.topology = t;
  for (kin::Component c : kin::all_components()) {
    const auto i = static_cast<std::size_t>(c);
    const auto axis = i / 6;
    const double L = kSimTravelMm[axis];
    const auto& s = kShapes[i];
    std::array<double, 4> p{0.0, s.amplitude * s.a1 / L, s.amplitude * s.a2 / (L * L),
                            s.amplitude * s.a3 / (L * L * L)};
    const bool straightness = i % 6 < 3 && i % 6 != axis;
    if (straightness) {
      // The least-squares line over the targets removed: ISO 230-1 reference lines.
      const auto q = targets_of(base_test(axis));
      double sq = 0, sv = 0, sqq = 0, sqv = 0;
      for (const double x : q) {
        const double v = p[0] + x * (p[1] + x * (p[2] + x * p[3]));
        sq += x, sv += v, sqq += x * x, sqv += x * v;
      }
      const double n = static_cast<double>(q.size());
      const double b = (n * sqv - sq * sv) / (n * sqq - sq * sq);
      const double a = (sv - b * sq) / n;
      p[0] -= a, p[1] -= b;
    }
    kin::component(m, c) = kin::ErrorFunction::polynomial(p);
  }
  m.squareness = {.c0y_urad = 15.0, .b0z_urad = -10.0, .a0z_urad = 8.0};
  return m;
}

ShopTruth volumetric_truth(kin::Topology t, double noise_um) {
  ShopTruth truth;
  truth.scale_um_per_m = 0.0;
  truth.cyclic_amplitude_um = 0.0;
  truth.backlash_um = 0.0;
  truth.noise_um = noise_um;
  truth.machine_degc = 20.0;
  truth.squareness_um_per_m = 0.0;
  truth.geometry = volumetric_geometry(t);
  return truth;
}

cal::daq::model::Model volumetric_truth_model(kin::Topology t) {
  cal::daq::model::Model m;
  m.name = fmt::format("SIMULATED truth ({})", kin::to_string(t));
  m.machine = volumetric_geometry(t);
  m.travel_mm = {{{0.0, kSimTravelMm[0]}, {0.0, kSimTravelMm[1]}, {0.0, kSimTravelMm[2]}}};
  const std::string injected = R"({"origin": "simulated", "what": "injected"})";
  for (auto& c : m.components) c = {.given = true, .source = {injected}};
  for (auto& s : m.squareness) s.given = true, s.source = {injected};
  m.provenance = {
      "{\"origin\": \"SIMULATED\", \"what\": \"the errors injected into the SIMULATED shop's "
      "volumetric machine (daq/src/sim/sim_volumetric.cpp)\"}"};
  return m;
}

std::vector<cal::daq::LinearTestConfig> volumetric_tests() {
  std::vector<cal::daq::LinearTestConfig> out;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    // Pitch and yaw: beams 100 mm apart along the third axis.
    for (std::size_t k = 0; k < 3; ++k) {
      if (k == axis) continue;
      auto l = base_test(axis);
      l.measure.kind = "angular";
      l.measure.direction = std::string(1, "ABC"[k]);
      l.measure.separation_mm[3 - axis - k] = 100.0;
      out.push_back(l);
    }
    auto roll = base_test(axis);
    roll.measure.kind = "roll";
    out.push_back(roll);
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    auto pos = base_test(axis);
    pos.runs = 2;  // ISO 230-2 evaluates at least 2 runs per direction
    out.push_back(pos);
    for (std::size_t d = 0; d < 3; ++d) {
      if (d == axis) continue;
      auto l = base_test(axis);
      l.measure.kind = "straightness";
      l.measure.direction = std::string(1, "XYZ"[d]);
      l.measure.square = true;  // read against a square's edge: the plane's squareness pair
      out.push_back(l);
    }
  }
  return out;
}

cal::daq::LinearTestConfig volumetric_test(std::string_view component) {
  for (const auto& l : volumetric_tests())
    if (kinds::kind(l.measure.kind).component(l) == component) return l;
  throw cal::InputError(fmt::format(
      "component '{}': the simulated campaign measures the 18 of ISO 230-1, E_XX ... E_CZ "
      "(squareness comes from the straightness pairs)",
      component));
}

std::function<kin::Vec3(const kin::Vec3&)> control_loads(
    std::string_view format, std::span<const std::string> files, bool inverted,
    const std::map<std::string, int>& axis_numbers) {
  std::vector<cal::comptable::CompFile> named;
  for (const auto& t : files) named.push_back({"", t});
  return control_loads(format, named, inverted, axis_numbers);
}

std::function<kin::Vec3(const kin::Vec3&)> control_loads(
    std::string_view format, std::span<const cal::comptable::CompFile> files, bool inverted,
    const std::map<std::string, int>& axis_numbers) {
  const auto applied = cal::comptable::read_cross_applied(format, files, axis_numbers, inverted);
  return [applied](const kin::Vec3& p) { return cal::comptable::cross_correction_um(applied, p); };
}

LinearRunOutcome acquire_simulated(const SimulatedAcquisition& a,
                                   const cal::daq::LinearTestConfig& test) {
  namespace d = cal::drivers;
  namespace t = cal::drivers::transport;
  boost::asio::io_context io;
  // speed 0: simulated time that jumps from event to event (cal/drivers/loop_time.hpp), as
  // fast as the CPU allows and the same readings on a loaded machine; loop seconds are then
  // simulated seconds.
  if (a.speed == 0) cal::drivers::VirtualTime::install(io);
  const double pace = a.speed > 0 ? a.speed : 1.0;
  SimulatedShop shop(io, a.truth, pace, test);
  if (a.compensation) shop.set_compensation(a.compensation);
  cal::daq::Config c;
  c.machine_name = a.machine;
  c.machine_description = "SIMULATED machine with all 21 geometric errors injected";
  c.campaign = "volumetric (simulated)";
  if (a.truth.geometry)
    c.machine_topology = std::string(kin::to_string(a.truth.geometry->topology));
  c.environment.stale_after_s = 60.0;
  c.trigger = {.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5};
  c.linear = test;
  const auto clock = shop.clock_ns();
  const auto poll = [&](double sim_s) {
    return std::chrono::microseconds(static_cast<std::int64_t>(sim_s / pace * 1e6));
  };
  LinearRunSetup setup;
  setup.config = c;
  for (const char* role : {"laser", "air", "material", "indicator", "level", "angle"})
    setup.origins[role] = {"simulated", "a twin of the built-in simulated shop (volumetric)"};
  setup.database = a.database;
  setup.store_options = a.store_options;
  const bool rotary = test.measure.kind == "rotary";  // its angular reference, no laser
  ShopInstruments instruments{.laser_poll_s = a.laser_poll_s, .laser = !rotary};
  if (test.measure.kind == "angular")
    for (const int b : test.measure.beams)
      instruments.laser_axes[static_cast<std::size_t>(b)] = true;
  shop.connect_linear(setup, instruments);
  // A probe injected to answer late (ShopTruth::probe_answer_delay_s) is silent that much
  // longer at first: not a lost connection.
  const auto probe_silence = std::chrono::milliseconds(
      3000 + static_cast<std::int64_t>(a.truth.probe_answer_delay_s / pace * 1e3));
  // The test's own instrument: a gauge twin of the shop, polled on the shop's clock.
  const auto gauge = [&](const std::string& device, double poll_s, d::codec::GaugeUnit unit,
                         double range_si) {
    return d::make_gauge(
        io, t::make_serial(io, {.device = device}),
        {.poll_period = poll(poll_s), .silence_timeout = probe_silence, .clock = clock},
        {.request = "?\r", .unit = unit, .min_si = -range_si, .max_si = range_si});
  };
  if (test.measure.kind == "straightness")
    setup.probe = gauge(shop.indicator_device(), 0.1, d::codec::GaugeUnit::mm, 0.01);
  if (test.measure.kind == "roll")
    setup.probe = gauge(shop.level_device(), 0.1, d::codec::GaugeUnit::urad, 0.01);
  if (rotary)  // polled as often as the laser would be: it alone sees the stops
    setup.probe = gauge(shop.angle_device(), a.laser_poll_s, d::codec::GaugeUnit::arcsec, 10.0);
  StartupReadings read(setup.material.size(), !rotary);
  setup.on_reading = [&read](const d::Reading& r) { read.add(r); };
  if (std::getenv("CALDAQ_SIM_EVENTS"))  // debugging aid: the run's events on stderr
    setup.on_event = [](const std::string& e) { std::fprintf(stderr, "  event: %s\n", e.c_str()); };
  LinearRun run(io, std::move(setup));
  run.start();
  if (!shop.wait_until([&] { return read.all(); }, 30.0))
    throw cal::InputError("simulated acquisition: the instruments did not start reading");
  shop.run_linear(run.plan(), test.feed_mm_per_min, test.dwell_s);
  shop.run_program([&] { return run.finished(); }, 30.0);
  if (!run.finished()) run.stop("the simulated program ended before the run");
  return run.outcome();
}

}  // namespace daq
