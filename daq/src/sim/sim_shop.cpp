// The simulated shop (see sim_shop.hpp).
#include "sim_shop.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <cmath>
#include <numbers>

#include "cal/analysis/error.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "ids3010/instrument.hpp"
#include "ids3010/twin.hpp"
#include "line_gauge/instrument.hpp"
#include "line_gauge/twin.hpp"
#include "linear_run.hpp"
#include "ptu300/instrument.hpp"
#include "ptu300/twin.hpp"
#include "roles.hpp"
#include "shdr/twin.hpp"

namespace daq {

namespace sim = cal::drivers::sim;

// The machine's scales expand with its temperature; the run normalises to 20 degC with the
// same coefficient, so the truth is the 20 degC error: E_XX, the pitch error at the driven
// position, and the lost motion (the axis stops b/2 short of the target whichever way it
// comes: below when approaching from below).
double ShopTruth::deviation_um(double x_mm, cal::iso230_2::Direction d) const {
  const double half = 0.5 * backlash_um * 1e-3 * (d == cal::iso230_2::Direction::up ? -1 : 1);
  const double driven = x_mm + half;
  return scale_um_per_m * driven * 1e-3 +
         cyclic_amplitude_um * std::sin(2 * std::numbers::pi * driven / cyclic_period_mm) +
         half * 1e3;
}

// The same lost motion and errors at the driven angle, in arcsec (1 deg = 3600").
double ShopTruth::Rotary::deviation_arcsec(double target_deg, cal::iso230_2::Direction d) const {
  const double half_deg =
      0.5 * backlash_arcsec / 3600.0 * (d == cal::iso230_2::Direction::up ? -1 : 1);
  const double driven_deg = target_deg + half_deg;
  return zero_arcsec + scale_arcsec_per_turn * driven_deg / 360.0 +
         cyclic_arcsec * std::sin(2 * std::numbers::pi * driven_deg / cyclic_period_deg) +
         half_deg * 3600.0;
}

cal::daq::LinearTestConfig simulated_rotary_test(int runs) {
  cal::daq::LinearTestConfig l;
  l.axis = "C";
  l.measure.kind = "rotary";
  l.first_mm = 0.0;  // deg
  l.last_mm = 360.0;
  l.interval_mm = 45.0;
  l.runs = runs;
  l.overrun_mm = 3.0;
  l.feed_mm_per_min = 1200.0;  // deg/min: 20 deg/s
  l.dwell_s = 3.0;
  l.measure.reference = "encoder";  // the SIMULATED rotary indexer's readout (docs/config.md)
  return l;
}

struct SimulatedShop::Impl {
  boost::asio::io_context& io;
  ShopTruth truth;
  double speed;
  // Simulated time follows the wall clock times `speed`, but between two readings of the
  // clock it advances by at most kMaxStep_s of simulated time: when the process is starved of
  // CPU (a loaded CI machine), the simulation pauses with it instead of running past the stops
  // while nothing reads the instruments. 0.05 s is below the shortest feature a run must see
  // (a 3 mm overrun excursion at 6000 mm/min lasts about 0.1 s), and a normal event loop reads
  // the clock far more often (every laser poll), so it binds only under starvation. Every
  // party reads this one clock.
  static constexpr double kMaxStep_s = 0.05;
  // The clock's state is declared before `clock` and the twins that hold it, so it is set
  // before any twin's constructor can read the time.
  mutable double sim_s = 0.0;
  mutable std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();
  // Simulated mode: the loop's VirtualTime is the shop's clock, and the speed only converts
  // the callers' margins (given in wall seconds at that speed) to simulated seconds.
  cal::drivers::VirtualTime* virtual_time;
  sim::Clock clock;
  sim::World world;
  sim::IdsTwin ids;
  sim::Ptu300Twin ptu;
  sim::GaugeTwin material;
  sim::GaugeTwin ballbar;
  sim::ShdrTwin position;
  cal::daq::LinearTestConfig test;
  sim::GaugeTwin indicator;  // SIMULATED: the straightness indicator of a straightness test
  sim::GaugeTwin level;      // SIMULATED: the differential electronic level of a roll test
  sim::GaugeTwin angle;      // SIMULATED: the angular reference of a rotary test

  // A rotary test's axis on the first servo, in degrees (ShopTruth::Rotary): 1 um of it is
  // 1 millidegree = 3.6"; at 20 degC, so its "scale" does not expand.
  static sim::MachineConfig rotary_machine(const ShopTruth::Rotary& r) {
    constexpr double kArcsecPerUm = 3.6;
    sim::MachineConfig c;
    c.servo[0] = {.kv_per_s = 30.0,
                  .backlash_um = r.backlash_arcsec / kArcsecPerUm,
                  .cyclic_amplitude_um = r.cyclic_arcsec / kArcsecPerUm,
                  .cyclic_period_mm = r.cyclic_period_deg,
                  .noise_um = r.noise_arcsec / kArcsecPerUm};
    c.thermal = {.start_degc = 20.0, .expansion_ppm_per_k = 0.0};
    c.acceleration_mm_per_s2 = 2000.0;  // deg/s^2
    return c;
  }

  static sim::MachineConfig machine(const ShopTruth& t, const cal::daq::LinearTestConfig& l) {
    if (l.measure.kind == "rotary") return rotary_machine(t.rotary);
    sim::MachineConfig c;
    c.geometry.axes[cal::kinematics::X].ex_um =
        cal::kinematics::ErrorFunction::polynomial({0.0, t.scale_um_per_m * 1e-3});
    c.servo[0] = {.kv_per_s = 30.0,
                  .backlash_um = t.backlash_um,
                  .cyclic_amplitude_um = t.cyclic_amplitude_um,
                  .cyclic_period_mm = t.cyclic_period_mm,
                  .noise_um = t.noise_um};
    c.servo[1] = {.kv_per_s = t.kv_y_per_s,
                  .backlash_um = t.backlash_y_um,
                  .cyclic_amplitude_um = t.cyclic_y_amplitude_um,
                  .cyclic_period_mm = t.cyclic_y_period_mm,
                  .noise_um = t.noise_yz_um};
    c.servo[2] = {.kv_per_s = t.kv_z_per_s,
                  .backlash_um = t.backlash_z_um,
                  .cyclic_amplitude_um = t.cyclic_z_amplitude_um,
                  .cyclic_period_mm = t.cyclic_z_period_mm,
                  .noise_um = t.noise_yz_um};
    c.servo[0].kv_per_s = t.kv_x_per_s;
    c.servo[1].vibration_um = t.vibration_y_um;
    c.servo[1].vibration_hz = t.vibration_y_hz;
    // urad per m of X x 1e-3 = urad per mm, the polynomial's coefficient of X in mm (none set
    // when zero: a zero function is skipped by the kinematics).
    const auto slope = [](double urad_per_m) {
      return urad_per_m == 0.0
                 ? cal::kinematics::ErrorFunction{}
                 : cal::kinematics::ErrorFunction::polynomial({0.0, urad_per_m * 1e-3});
    };
    auto& x = c.geometry.axes[cal::kinematics::X];
    x.ea_urad = slope(t.roll_x_urad_per_m);
    x.eb_urad = slope(t.pitch_x_urad_per_m);
    x.ec_urad = slope(t.yaw_x_urad_per_m);
    c.geometry.squareness.c0y_urad = t.squareness_um_per_m;
    c.geometry.squareness.b0z_urad = t.b0z_urad;
    c.geometry.squareness.a0z_urad = t.a0z_urad;
    if (t.geometry) c.geometry = *t.geometry;
    c.thermal = {.start_degc = t.machine_degc, .expansion_ppm_per_k = t.expansion_ppm_per_k};
    c.acceleration_mm_per_s2 = 2000.0;
    // A probe (the straightness indicator against its straightedge, the roll's level) is set up
    // with the machine at the start of the line: the other axes at their stationary positions,
    // the test axis at the first target. Started at the origin, the machine first traversed to
    // the line (240 mm in Y on the volumetric shop at the test's feed) and the indicator, which
    // reads where the axes stand off their command, read that move's following error: a -2.7 mm
    // dip at the start of a straightness run's readings, where a real indicator is not yet on
    // its straightedge.
    if (l.measure.kind == "straightness" || l.measure.kind == "roll") {
      const auto& st = l.measure.stationary_mm;
      c.start_mm = {st[0], st[1], st[2]};
      c.start_mm[l.axis == "Y" ? 1 : l.axis == "Z" ? 2 : 0] = l.first_mm;
    }
    return c;
  }
  static sim::AirConfig air(const ShopTruth& t) {
    sim::AirConfig a;
    a.temperature_degc = {
        .start = t.air_start_degc, .per_hour = t.air_drift_k_per_h, .noise_rms = 0.005};
    a.pressure_pa = {
        .start = t.pressure_pa, .amplitude = 30.0, .period_s = 1800.0, .noise_rms = 2.0};
    a.humidity_pct = {.start = t.humidity_pct, .noise_rms = 0.2};
    return a;
  }

  // The laser of a test: axis 0 reads the test axis; at the probe offset when one is set (or
  // for another kind than positioning), an angular test's beams at probe +- separation / 2.
  static sim::IdsTwinConfig laser(const cal::daq::LinearTestConfig& l) {
    sim::IdsTwinConfig c;
    const int axis = l.axis == "Y" ? 1 : l.axis == "Z" ? 2 : 0;
    c.machine_axis = {axis, -1, -1};
    const auto& m = l.measure;
    const sim::Vec3 probe{m.probe_offset_mm[0], m.probe_offset_mm[1], m.probe_offset_mm[2]};
    if (m.kind != "positioning" || probe != sim::Vec3{}) c.reflector_mm[0] = probe;
    if (m.kind == "angular")
      for (std::size_t b = 0; b < 2; ++b) {
        const auto a = static_cast<std::size_t>(m.beams[b]);
        sim::Vec3 r = probe;
        for (std::size_t k = 0; k < 3; ++k) r[k] += (b == 0 ? 0.5 : -0.5) * m.separation_mm[k];
        c.machine_axis[a] = axis;
        c.reflector_mm[a] = r;
      }
    return c;
  }

  Impl(boost::asio::io_context& ctx, ShopTruth t, double s, const cal::daq::LinearTestConfig& l)
      : io(ctx),
        truth(t),
        speed(s),
        virtual_time(cal::drivers::VirtualTime::of(ctx)),
        clock([this] { return now(); }),
        world(machine(t, l), air(t)),
        ids(ctx, world, clock, laser(l)),
        ptu(ctx, world, clock),
        material(ctx, world, clock,
                 polled(3, [](const sim::World& w) { return w.state().machine_temperature_degc; })),
        ballbar(ctx, world, clock,
                {.pivot_mm = t.pivot_mm,
                 .zero_length_mm = t.ballbar_mm,
                 .sample_rate_hz = t.ballbar_rate_hz,
                 .continuous = false}),
        position(ctx, world, clock),
        test(l),
        // The indicator reads the probe point's deviation from the nominal line it is commanded
        // on: where the axes stand off the command across the travel (a control's compensation
        // moves them) plus the geometric error there; in mm, to 10 nm digits.
        indicator(ctx, world, clock,
                  polled_probe(t, s, ctx, 5,
                               [this](const sim::World& w) {
                                 const auto& st = w.state();
                                 return st.axes_mm[dir()] - st.commanded_mm[dir()] +
                                        probe_error().translation_um[dir()] * 1e-3;
                               })),
        // The level reads the rotation about the test axis, in urad to 1 nrad digits.
        level(ctx, world, clock,
              polled_probe(
                  t, s, ctx, 3,
                  [this](const sim::World&) { return probe_error().rotation_urad[axis()]; })),
        angle(ctx, world, clock,
              polled(3, [this](const sim::World& w) { return reference_arcsec(w); })) {}

  // A twin answering "?" with value(world) to `decimals` digits (arcsec: 0.001" digits).
  static sim::GaugeTwinConfig polled(int decimals, std::function<double(const sim::World&)> value) {
    return {.continuous = false, .request = "?", .decimals = decimals, .value = std::move(value)};
  }
  // A probe of the linear tests (indicator, level): polled as above, answering after the
  // probes' delay and, when the truth says so, measuring at the answer instead of the request.
  static sim::GaugeTwinConfig polled_probe(const ShopTruth& shop_truth, double shop_speed,
                                           boost::asio::io_context& loop, int decimals,
                                           std::function<double(const sim::World&)> value) {
    auto c = polled(decimals, std::move(value));
    c.answer_delay = answer_delay(shop_truth, shop_speed, loop);
    c.measure_on_answer = shop_truth.probe_measures_on_answer;
    return c;
  }

  // The angular reference's reading: the axis's angle with its scale error, zeroed
  // zero_arcsec off, modulo a turn as an indexer's readout gives it.
  double reference_arcsec(const sim::World& w) const {
    constexpr double kTurnArcsec = 1296000.0;
    const auto& r = truth.rotary;
    const double a = w.state().axes_mm[0] * 3600.0 * (1.0 + r.scale_arcsec_per_turn / kTurnArcsec) +
                     r.zero_arcsec;
    return a - kTurnArcsec * std::floor(a / kTurnArcsec);
  }

  // The probes' answer delay on the loop's time: simulated, or the wall clock at the speed.
  static std::chrono::nanoseconds answer_delay(const ShopTruth& shop_truth, double shop_speed,
                                               boost::asio::io_context& loop) {
    const double loop_s = cal::drivers::VirtualTime::of(loop) || shop_speed <= 0
                              ? shop_truth.probe_answer_delay_s
                              : shop_truth.probe_answer_delay_s / shop_speed;
    return std::chrono::nanoseconds(static_cast<std::int64_t>(loop_s * 1e9));
  }

  std::size_t axis() const { return test.axis == "Y" ? 1 : test.axis == "Z" ? 2 : 0; }
  std::size_t dir() const {
    const auto& d = test.measure.direction;
    return d == "Y" ? 1 : d == "Z" ? 2 : 0;
  }
  cal::kinematics::VolumetricError probe_error() {
    const auto& p = test.measure.probe_offset_mm;
    return world.machine().error_at({p[0], p[1], p[2]});
  }

  double now() const {
    if (virtual_time) return virtual_time->now_s();
    const auto wall = std::chrono::steady_clock::now();
    sim_s += std::min(speed * std::chrono::duration<double>(wall - last).count(), kMaxStep_s);
    last = wall;
    return sim_s;
  }
};

SimulatedShop::SimulatedShop(boost::asio::io_context& io, ShopTruth truth, double speed,
                             const cal::daq::LinearTestConfig& test)
    : impl_(std::make_unique<Impl>(io, std::move(truth), speed, test)) {}
SimulatedShop::~SimulatedShop() = default;

const ShopTruth& SimulatedShop::truth() const { return impl_->truth; }
double SimulatedShop::now_s() const { return impl_->now(); }
cal::drivers::Clock SimulatedShop::clock_ns() const {
  if (auto* vt = impl_->virtual_time) return [vt] { return vt->now_ns(); };
  return [impl = impl_.get()] { return static_cast<std::int64_t>(impl->now() * 1e9); };
}
void SimulatedShop::connect_linear(LinearRunSetup& setup, const ShopInstruments& o) const {
  namespace d = cal::drivers;
  namespace t = cal::drivers::transport;
  auto& io = impl_->io;
  const RunDevices devices(o.material ? 1 : 0);
  const auto options = [&](Role role, double poll_s) {
    return d::InstrumentOptions{.device = devices.device(role),
                                .poll_period = std::chrono::microseconds(static_cast<std::int64_t>(
                                    poll_s / impl_->speed * 1e6)),  // wall time at the speed
                                .clock = clock_ns(),
                                .recorder = o.recorder};
  };
  if (o.laser)
    setup.laser = d::make_ids3010(io, t::make_tcp(io, {.host = "127.0.0.1", .port = laser_port()}),
                                  options(Role::laser, o.laser_poll_s), {.axes = o.laser_axes});
  setup.air = d::make_ptu300(
      io, t::make_serial(io, t::parse_serial_settings("4800 7E1", {.device = air_device()})),
      options(Role::air, 1.0));
  if (o.material)
    setup.material.push_back(d::make_gauge(
        io, t::make_serial(io, {.device = material_device()}), options(Role::material, 1.0),
        {.request = "?\r", .unit = d::codec::GaugeUnit::degc, .min_si = -40, .max_si = 150}));
}

bool SimulatedShop::simulated_time() const { return impl_->virtual_time != nullptr; }
std::uint16_t SimulatedShop::laser_port() const { return impl_->ids.port(); }
const std::string& SimulatedShop::air_device() const { return impl_->ptu.device_path(); }
const std::string& SimulatedShop::material_device() const { return impl_->material.device_path(); }
const std::string& SimulatedShop::ballbar_device() const { return impl_->ballbar.device_path(); }
std::uint16_t SimulatedShop::position_port() const { return impl_->position.port(); }
const std::string& SimulatedShop::indicator_device() const {
  return impl_->indicator.device_path();
}
const std::string& SimulatedShop::level_device() const { return impl_->level.device_path(); }
const std::string& SimulatedShop::angle_device() const { return impl_->angle.device_path(); }
void SimulatedShop::set_compensation(
    std::function<cal::kinematics::Vec3(const cal::kinematics::Vec3&)> f) {
  impl_->world.machine().set_compensation(std::move(f));
}

void SimulatedShop::set_test(const cal::daq::LinearTestConfig& test) {
  impl_->test = test;
  const auto optics = Impl::laser(test);
  impl_->ids.set_optics(optics.machine_axis, optics.reflector_mm);
}

std::string SimulatedShop::devices_toml(double laser_poll_s, bool position_feed,
                                        bool serial_numbers, bool every_probe) const {
  // Serial numbers as a real set-up has them for its report (daq serve --simulate).
  const auto serial = [&](std::string_view number) {
    return serial_numbers ? fmt::format("serial_number = \"{}\"\n", number) : std::string{};
  };
  std::string position;
  if (position_feed)
    position = fmt::format(
        "[devices.position]      # the control's commanded position\n"
        "driver = \"shdr\"\ntransport = \"{}\"\nkey = \"Xcom\"\nrole = \"position\"\n"
        "origin = \"simulated\"\n\n",
        impl_->position.transport());
  // The instruments of the shop's test besides the laser (kinds/kind.hpp), SIMULATED.
  const auto& m = impl_->test.measure;
  std::string probe, axes;
  if (m.kind == "angular")
    axes = fmt::format("axes = [0, {}, {}]  # 0: position; the angular beams a, b\n", m.beams[0],
                       m.beams[1]);
  // The probe of a straightness or roll test: a gauge twin on a pseudo-terminal.
  const auto gauge = [&](std::string_view role, std::string_view what, const std::string& path,
                         std::string_view unit_and_range) {
    return fmt::format(
        "[devices.{0}]{1:<{2}}# SIMULATED {3}\n"
        "driver = \"gauge\"\ntransport = \"serial {4} 9600 8N1\"\nrequest = \"?\\r\"\n"
        "{5}role = \"{0}\"\npoll_s = {6}\norigin = \"simulated\"\n\n",
        role, "", 14 - role.size(), what, path, unit_and_range, 4 * laser_poll_s);
  };
  if (m.kind == "straightness" || every_probe)
    probe = gauge("indicator", "straightness indicator against a straightedge",
                  impl_->indicator.device_path(), "unit = \"mm\"\nmin_si = -0.01\nmax_si = 0.01\n");
  if (m.kind == "roll" || every_probe)
    probe += gauge("level", "electronic level against a reference level",
                   impl_->level.device_path(), "unit = \"urad\"\n");
  if (m.kind == "rotary")  // polled as often as the laser: it alone sees the stops
    probe = fmt::format(
        "[devices.angle]         # SIMULATED angular reference (rotary indexer's readout)\n"
        "driver = \"gauge\"\ntransport = \"serial {} 9600 8N1\"\nrequest = \"?\\r\"\n"
        "unit = \"arcsec\"\nmin_si = -7  # rad: a turn either way\nmax_si = 7\nrole = "
        "\"angle\"\npoll_s = {}\norigin = \"simulated\"\n\n",
        impl_->angle.device_path(), laser_poll_s);
  return fmt::format(
      R"TOML([devices.laser]
driver = "ids3010"
transport = "{laser}"
role = "laser"
origin = "simulated"
poll_s = {laser_poll}
{axes}{laser_sn}
[devices.air]
driver = "ptu300"
transport = "{air}"
role = "air"
origin = "simulated"
{air_sn}
[devices.material]
driver = "gauge"
transport = "serial {material} 9600 8N1"
request = "?\r"
unit = "degC"
role = "material"
origin = "simulated"
{material_sn}
{position}{probe}[devices.ballbar]
driver = "gauge"
transport = "{ballbar}"
unit = "mm"
min_si = -0.1           # the bar's travel: +/- 100 mm about its zero length
max_si = 0.1
role = "ballbar"
origin = "simulated"
{ballbar_sn})TOML",
      fmt::arg("laser_sn", serial("SIM-IDS-0001")), fmt::arg("air_sn", serial("SIM-PTU-0001")),
      fmt::arg("material_sn", serial("SIM-TH-0001")), fmt::arg("ballbar_sn", serial("SIM-BB-0001")),
      fmt::arg("laser", impl_->ids.transport()), fmt::arg("laser_poll", laser_poll_s),
      fmt::arg("air", impl_->ptu.transport()), fmt::arg("material", impl_->material.device_path()),
      fmt::arg("position", position), fmt::arg("ballbar", impl_->ballbar.transport()),
      fmt::arg("axes", axes), fmt::arg("probe", probe));
}

void SimulatedShop::run_linear(const cal::iso230_2::Plan& plan, double feed, double dwell_s) {
  std::vector<sim::Move> program;
  const auto& st = impl_->test.measure.stationary_mm;
  const std::size_t axis = impl_->axis();
  for (const auto& m : plan.moves) {
    sim::Vec3 p{st[0], st[1], st[2]};
    p[axis] = m.position_mm;
    program.push_back(sim::Move::linear(p, feed));
    if (m.kind == cal::iso230_2::MoveKind::measure) program.push_back(sim::Move::dwell(dwell_s));
  }
  impl_->world.advance_to(now_s());
  impl_->world.machine().load(program);
}

void SimulatedShop::run_circle(const cal::daq::BallbarProgram& p) {
  const auto& c = impl_->truth.pivot_mm;
  const double feed = p.feed_mm_per_min, sweep = 360.0 + 2 * p.overshoot_deg;
  const sim::Vec3 centre{c[0], c[1], c[2]};
  const std::vector<sim::Move> program{
      sim::Move::linear({c[0] + p.radius_mm + p.feed_in_mm, c[1], c[2]}, 3000.0),
      sim::Move::dwell(0.5),
      sim::Move::linear({c[0] + p.radius_mm, c[1], c[2]}, feed),
      sim::Move::dwell(p.dwell_s),
      sim::Move::arc(false, centre, sim::Plane::xy, sweep, feed),
      sim::Move::dwell(p.dwell_s),
      sim::Move::arc(true, centre, sim::Plane::xy, sweep, feed),
      sim::Move::linear({c[0] + p.radius_mm + p.feed_in_mm, c[1], c[2]}, feed)};
  impl_->world.advance_to(now_s());
  impl_->world.machine().load(program);
  impl_->ballbar.set_streaming(true);  // the bar is mounted now
}

ShopTruth ShopTruth::three_planes() {
  ShopTruth t;
  t.b0z_urad = 15.0;    // alpha_ZX = -15 um/m
  t.a0z_urad = -10.0;   // alpha_YZ = -10 um/m
  t.kv_z_per_s = 29.4;  // Z lags X by 1/29.4 - 1/30 s = 0.680 ms, Z lags Y by 0.343 ms
  t.backlash_y_um = 3.0, t.backlash_z_um = 2.0;
  t.cyclic_y_amplitude_um = 0.8, t.cyclic_z_amplitude_um = 0.6;
  t.noise_yz_um = t.noise_um;
  return t;
}

ShopTruth ShopTruth::served() {
  ShopTruth t = three_planes();
  t.roll_x_urad_per_m = 40.0;
  t.pitch_x_urad_per_m = 40.0;
  t.yaw_x_urad_per_m = -20.0;
  t.vibration_y_um = 0.6;
  t.vibration_y_hz = 23.7;
  return t;
}

void SimulatedShop::run_circle_set(std::span<const cal::daq::BallbarSetTest> tests) {
  if (tests.empty()) throw cal::InputError("simulated ballbar set: no test");
  const auto& c = impl_->truth.pivot_mm;
  const sim::Vec3 centre{c[0], c[1], c[2]};
  const auto sim_plane = [](cal::daq::Plane p) {
    return p == cal::daq::Plane::zx   ? sim::Plane::zx
           : p == cal::daq::Plane::yz ? sim::Plane::yz
                                      : sim::Plane::xy;
  };
  // caldaq's angle in the plane: from its first axis towards the second (ZX: Z first).
  const auto point = [&](cal::daq::Plane p, double deg, double r) {
    const double a = deg * std::numbers::pi / 180, u = r * std::cos(a), v = r * std::sin(a);
    if (p == cal::daq::Plane::zx) return sim::Vec3{c[0] + v, c[1], c[2] + u};
    if (p == cal::daq::Plane::yz) return sim::Vec3{c[0], c[1] + u, c[2] + v};
    return sim::Vec3{c[0] + u, c[1] + v, c[2]};
  };
  std::vector<sim::Move> program;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const auto& [p, b] = tests[i];
    const double out = b.radius_mm + b.feed_in_mm, feed = b.feed_mm_per_min;
    if (i == 0) {
      program.push_back(sim::Move::linear(point(p, b.start_deg, out), 3000.0));
      program.push_back(sim::Move::dwell(0.5));
    } else {
      const auto& prev = tests[i - 1];
      if (std::abs(prev.program.radius_mm + prev.program.feed_in_mm - out) > 1e-9)
        throw cal::InputError("simulated ballbar set: one radius and feed-in only");
      for (const auto& a :
           cal::daq::ballbar_transition(prev.plane, prev.program.start_deg, p, b.start_deg))
        if (std::abs(a.sweep_deg) > 1e-9)
          program.push_back(sim::Move::arc(a.sweep_deg < 0, centre, sim_plane(a.plane),
                                           std::abs(a.sweep_deg), feed));
    }
    const double sweep = b.arc_deg + 2 * b.overshoot_deg;
    program.push_back(sim::Move::linear(point(p, b.start_deg, b.radius_mm), feed));  // feed-in
    program.push_back(sim::Move::dwell(b.dwell_s));
    program.push_back(sim::Move::arc(false, centre, sim_plane(p), sweep, feed));
    program.push_back(sim::Move::dwell(b.dwell_s));
    program.push_back(sim::Move::arc(true, centre, sim_plane(p), sweep, feed));
    program.push_back(sim::Move::linear(point(p, b.start_deg, out), feed));  // feed-out
  }
  impl_->world.advance_to(now_s());
  impl_->world.machine().load(program);
  impl_->ballbar.set_streaming(true);
}

double SimulatedShop::program_end_s() const { return impl_->world.machine().program_duration_s(); }

bool SimulatedShop::run_program(const std::function<bool()>& done, double margin_wall_s,
                                const std::function<void()>& each) {
  const double end_s = program_end_s() + margin_wall_s * impl_->speed;
  if (auto* vt = impl_->virtual_time) {
    // Slices of 0.1 s of simulated time, so that `each` runs as often as it would live.
    const auto end_ns = static_cast<std::int64_t>(end_s * 1e9);
    while (!done() && vt->now_ns() < end_ns) {
      const std::int64_t slice_end = std::min(end_ns, vt->now_ns() + 100'000'000);
      const bool finished = vt->run_until(done, slice_end);
      if (each) each();
      if (!finished && vt->now_ns() < slice_end) break;  // nothing can happen any more
    }
    return done();
  }
  // A last resort against a stalled clock: an hour of wall time.
  const auto hard = std::chrono::steady_clock::now() + std::chrono::hours(1);
  while (!done() && now_s() < end_s && std::chrono::steady_clock::now() < hard) {
    impl_->io.run_for(std::chrono::milliseconds(20));
    if (each) each();
  }
  return done();
}

bool SimulatedShop::wait_until(const std::function<bool()>& ready, double wall_s) {
  if (auto* vt = impl_->virtual_time)  // wall_s at the shop's speed, in simulated time
    return vt->run_for(
        std::chrono::nanoseconds(static_cast<std::int64_t>(wall_s * impl_->speed * 1e9)), ready);
  const auto limit = std::chrono::steady_clock::now() + std::chrono::duration<double>(wall_s);
  while (!ready() && std::chrono::steady_clock::now() < limit)
    impl_->io.run_for(std::chrono::milliseconds(5));
  return ready();
}

std::vector<cal::iso230_2::Measurement> SimulatedShop::true_measurements(
    const cal::iso230_2::Plan& p) const {
  std::vector<cal::iso230_2::Measurement> out;
  for (const auto& m : p.moves)
    if (m.kind == cal::iso230_2::MoveKind::measure)
      out.push_back({m.position_mm, m.run, m.direction,
                     impl_->truth.deviation_um(m.position_mm, m.direction)});
  return out;
}

namespace {

std::string linear_toml(const ShopConfigOptions& o) {
  return fmt::format(
      "[test.linear]\naxis = \"X\"\nfirst_mm = 0\nlast_mm = {}\ninterval_mm = 50\n"
      "random_fraction = 0.2\nruns = {}\noverrun_mm = 3\nfeed_mm_per_min = 6000\ndwell_s = 3\n",
      50 * (o.targets - 1), o.runs);
}

// simulated_rotary_test() as the configuration says it (docs/iso230-2.md, "Rotary axes").
std::string rotary_toml(int runs) {
  const auto l = simulated_rotary_test(runs);
  return fmt::format(
      "[test.linear]           # a rotary axis: the lengths below are degrees\n"
      "axis = \"{}\"\nmeasure = \"rotary\"\nfirst_mm = {}\nlast_mm = {}\ninterval_mm = {}\n"
      "runs = {}\noverrun_mm = {}\nfeed_mm_per_min = {}\ndwell_s = {}\nreference = \"{}\"\n",
      l.axis, l.first_mm, l.last_mm, l.interval_mm.value_or(45.0), l.runs, l.overrun_mm,
      l.feed_mm_per_min, l.dwell_s, l.measure.reference);
}

}  // namespace

std::string simulated_shop_config(const SimulatedShop& shop, const ShopConfigOptions& o) {
  const auto& t = shop.truth();
  const double wall = o.in_process ? 1.0 : 1.0 / o.speed;  // simulated s -> the reader's s
  const std::string header =
      o.in_process
          ? fmt::format(
                "# The devices of the built-in SIMULATED shop of `daq serve --simulate` (running\n"
                "# {}x faster than real time; every time here is simulated time). Valid while\n"
                "# that process runs.\n",
                o.speed)
          : fmt::format(
                "# Written by `daq sim`: the devices of the built-in SIMULATED shop (running {}x\n"
                "# faster than real time). Valid while that process runs.\n",
                o.speed);
  return header + fmt::format(
                      R"TOML(campaign = "simulated"

[machine]
name = "SIMULATED VMC"
description = "built-in simulated 3-axis machine with injected errors ({who})"
topology = "FXYZ"

{devices}
[environment]
equation = "ciddor"
expansion_ppm_per_k = {alpha}
{stale}
[trigger]
tolerance_um = 1
dwell_s = {trigger_dwell}
window_mm = 0.5

{linear}
[test.circle]
{circle_tests}radius_mm = {radius}
sample_rate_hz = {ballbar_rate}
overshoot_deg = 45
centre_mm = [{cx}, {cy}, {cz}]

# The machine's specification (as in `daq demo`): the injected backlash (4 um) and servo
# mismatch exceed it, the rest is within.
[tolerances.X]
E_um = 10
R_um = 6
B_um = 3
A_um = 12
M_um = 8

[tolerances.XY]
G_um = 10
[tolerances.XY.diagnostics]
squareness = 30
backlash_X = 3

# The set's other planes (YZ, ZX), judged by the same specification of G and squareness.
[tolerances.YZ]
G_um = 10
[tolerances.YZ.diagnostics]
squareness = 30

[tolerances.ZX]
G_um = 10
[tolerances.ZX.diagnostics]
squareness = 30
)TOML",
                      fmt::arg("who", o.in_process ? "daq serve --simulate" : "daq sim"),
                      // In process the instruments read the shop's clock: every time is
                      // simulated time; the poll periods of the drivers' defaults too.
                      // In process (daq serve) both probes: its tests may be of any kind.
                      fmt::arg("devices", shop.devices_toml(0.05 * wall, o.position_feed,
                                                            /*serial_numbers=*/true,
                                                            /*every_probe=*/o.in_process)),
                      fmt::arg("alpha", t.expansion_ppm_per_k),
                      fmt::arg("linear", o.rotary ? rotary_toml(o.runs) : linear_toml(o)),
                      // Simulated seconds: at a high speed the wall-clock timers' jitter is
                      // magnified, as in daq demo.
                      fmt::arg("stale", o.in_process ? "stale_after_s = 30\n" : ""),
                      fmt::arg("trigger_dwell", 1.5 * wall), fmt::arg("radius", t.ballbar_mm),
                      fmt::arg("ballbar_rate", t.ballbar_rate_hz), fmt::arg("cx", t.pivot_mm[0]),
                      fmt::arg("cy", t.pivot_mm[1]), fmt::arg("cz", t.pivot_mm[2]),
                      // One full circle in XY, or the standard set: XY 360 deg, ZX and YZ 220
                      // deg over the top, each at a slow and a fast feed (docs/circle.md).
                      fmt::arg("circle_tests",
                               o.circle_set ? "planes = [\"XY\", \"ZX\", \"YZ\"]\n"
                                              "feeds_mm_per_min = [1000, 3000]\n"
                                            : fmt::format("plane = \"XY\"\nfeed_mm_per_min = {}\n",
                                                          o.circle_feed_mm_per_min)));
}

}  // namespace daq
