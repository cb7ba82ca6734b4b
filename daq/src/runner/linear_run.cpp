// ISO 230-2 acquisition (see linear_run.hpp).
#include "linear_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <chrono>
#include <deque>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"
#include "cal/daq/capture_guard.hpp"
#include "cal/daq/env_stage.hpp"
#include "cal/daq/motion.hpp"
#include "cal/daq/trigger.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/storage/store.hpp"
#include "cal/storage/writer.hpp"
#include "iso230_2_output.hpp"
#include "kinds/kind.hpp"
#include "provenance.hpp"
#include "result_rows.hpp"
#include "roles.hpp"
#include "run_quality.hpp"
#include "runner.hpp"
#include "session_spec.hpp"

namespace daq {

using cal::drivers::Quantity;
using cal::drivers::Reading;
using cal::drivers::ReadingStatus;
using nlohmann::json;

namespace {
// A unit of the live state as the page writes it: deg as the degree sign (the terminal's "deg"
// is not in unit_html's table, whose words the reports' sentences share), um as µm.
std::string page_unit(std::string_view unit) {
  return unit == "deg" ? std::string("°") : ::daq::unit_html(unit);
}
}  // namespace

std::string to_json_text(const LiveState& s) {
  const std::string position_unit = page_unit(s.units.position);
  const std::string deviation_unit = page_unit(s.units.deviation);
  json j{{"schema", "caldaq.live.v1"},
         {"time_s", s.time_s},
         {"state", s.state},
         {"message", s.message},
         {"reading",
          {{"value", s.deviation_um},
           {"unit", deviation_unit},
           {"decimals", 2},
           {"position_mm", s.position_mm}}},
         {"fallback", s.fallback},
         // Every *_mm and *_um value's unit (a rotary axis's: degrees and arcsec), for the page.
         {"units", {{"position", position_unit}, {"deviation", deviation_unit}}}};
  // Until the first air sample the compensation is not known: no numbers rather than zeros.
  if (s.pressure_pa > 0) {
    j["air"] = {{"temperature_degc", s.air_temperature_degc},
                {"pressure_pa", s.pressure_pa},
                {"humidity_pct", s.humidity_pct},
                {"n", s.n}};
    j["material_degc"] = s.material_degc;
    j["factor_ppm"] = s.factor_ppm;
  }
  if (s.progress.next_position_mm) {
    j["target"] = {{"index", s.progress.target},
                   {"count", s.progress.targets},
                   {"nominal_mm", *s.progress.next_position_mm}};
    j["run"] = {
        {"number", s.progress.run},
        {"count", s.progress.runs},
        {"direction", s.progress.direction == cal::iso230_2::Direction::up ? "up" : "down"}};
  }
  j["captured"] = s.progress.captured;
  j["expected"] = s.progress.expected;
  j["valid"] = s.valid;
  j["motion"] = {{"state", s.motion}, {"stable_fraction", s.stable_fraction}};
  if (s.last_settling_s)
    j["motion"]["last_stop"] = {{"settling_s", *s.last_settling_s},
                                {"stable_s", s.last_stable_s.value_or(0.0)}};
  // The number the page shows: a deviation within a target's capture window, else the
  // position; none before the first laser reading.
  if (!s.has_reading)
    j["display"] = nullptr;
  else if (s.at_target_mm)
    j["display"] = {{"mode", "deviation"},
                    {"value", s.at_target_deviation_um},
                    {"unit", deviation_unit},
                    {"decimals", 2},
                    {"target_mm", *s.at_target_mm}};
  else
    j["display"] = {
        {"mode", "position"}, {"value", s.position_mm}, {"unit", position_unit}, {"decimals", 3}};
  j["stop"] = {{"number", s.stop_number}, {"count", s.stop_count}};
  json stops = json::array();
  for (const auto& x : s.stops)
    stops.push_back({{"number", x.number},
                     {"run", x.run},
                     {"direction", x.up ? "up" : "down"},
                     {"target", x.target},
                     {"nominal_mm", x.nominal_mm},
                     {"deviation_um", x.missed || x.pending ? json(nullptr) : json(x.deviation_um)},
                     {"pending", x.pending},
                     {"missed", x.missed},
                     {"skipped", x.skipped},
                     {"manual", x.manual},
                     {"while_moving", x.while_moving}});
  j["stops"] = std::move(stops);
  j["stop_value"] = {{"what", s.stop_value}, {"unit", ::daq::unit_html(s.stop_unit)}};
  j["paused"] = s.paused;
  return j.dump();
}

cal::iso230_2::Plan linear_plan(const cal::daq::LinearTestConfig& l) {
  return cal::iso230_2::make_plan({.first_mm = l.first_mm,
                                   .last_mm = l.last_mm,
                                   .interval_mm = l.interval_mm,
                                   .count = l.count,
                                   .random_fraction = l.random_fraction},
                                  {.cycle = cal::iso230_2::cycle_from_string(l.cycle),
                                   .bidirectional = l.bidirectional,
                                   .runs = l.runs,
                                   .overrun_mm = l.overrun_mm});
}

namespace {

json settings_json(const cal::daq::Config& c, const cal::iso230_2::Plan& plan, double datum_mm,
                   const std::string& context_json) {
  const auto& l = *c.linear;
  json context = context_json.empty() ? json(nullptr) : json::parse(context_json, nullptr, false);
  const auto& kind = kinds::kind(l.measure.kind);
  if (!context.is_object()) {
    auto roles = kinds::linear_run_roles(kind);
    // A laser's angular optics over a rotary indexer: its angles arrive through the angle
    // device, and the laser is not opened, but it is the reference the angles are traceable to
    // (its serial number and certificate, the air's index of its wavelength): listed.
    if (l.measure.kind == "rotary" && l.measure.reference == "laser") roles.emplace_back("laser");
    context = run_context(c, "linear", l.axis, roles);
  }
  json measure = measure_json(l.measure);
  measure["component"] = kind.component(l);
  measure["unit"] = kind.unit();
  return {
      {"measure", measure},
      {"machine_model",
       {{"topology", c.machine_topology},
        {"tool_offset_mm", c.machine_tool_offset_mm},
        {"table_offset_mm", c.machine_table_offset_mm}}},
      {"context", context},
      {"machine", c.machine_name},
      {"axis", l.axis},
      {"targets_mm", plan.targets_mm},
      {"cycle", l.cycle},
      {"runs", l.runs},
      {"bidirectional", l.bidirectional},
      {"feed_mm_per_min", l.feed_mm_per_min},
      {"dwell_s", l.dwell_s},
      {"datum_mm", datum_mm},
      {"standard", l.standard},
      {"environment",
       {{"equation", c.environment.equation},
        {"expansion_ppm_per_k", c.environment.expansion_ppm_per_k},
        {"stale_after_s", c.environment.stale_after_s},
        {"on_stale", c.environment.on_stale == cal::daq::StalePolicy::stop ? "stop" : "fallback"},
        {"co2_umol_per_mol", c.environment.co2_umol_per_mol},
        {"wavelength_nm", c.environment.wavelength_nm}}},
      {"trigger",
       {{"tolerance_um", c.trigger.tolerance_um},
        {"dwell_s", c.trigger.dwell_s},
        {"window_mm", c.trigger.window_mm}}}};
}

}  // namespace

MaterialSensors::MaterialSensors(std::size_t instruments,
                                 const std::vector<std::vector<std::uint8_t>>& channels) {
  for (std::size_t k = 0; k < instruments; ++k) {
    first_.push_back(count_);
    channels_.push_back(k < channels.size() ? channels[k] : std::vector<std::uint8_t>{});
    count_ += channels_.back().empty() ? 1 : static_cast<int>(channels_.back().size());
  }
}

int MaterialSensors::sensor(std::size_t k, std::uint8_t channel) const {
  if (k >= channels_.size()) return -1;
  const auto& c = channels_[k];
  if (c.empty()) return first_[k];
  const auto it = std::find(c.begin(), c.end(), channel);
  return it == c.end() ? -1 : first_[k] + static_cast<int>(it - c.begin());
}

struct LinearRun::Impl : Runner {
  LinearRunSetup setup;
  RunDevices devices;  // laser, air, material thermometers, position feed, probe
  cal::iso230_2::Plan plan;
  MaterialSensors materials;
  cal::daq::EnvStage env;
  cal::daq::StabilityTrigger trigger;
  std::optional<cal::daq::PositionTrigger> position_trigger;  // with a position feed
  cal::daq::Sequencer sequencer;
  const kinds::TestKind& kind;
  std::unique_ptr<kinds::SampleReader> reader;  // null for positioning
  // The kind's value, newest last: measured somewhere in [time_ns, latest_ns] (a polled
  // gauge: its request and its answer; cal::drivers::Reading::measured_within_ms).
  struct Sample {
    std::int64_t time_ns, latest_ns;
    double value;
  };
  std::deque<Sample> samples;
  std::vector<kinds::StopValue> values;  // at the captured stops
  // Stops captured before a sample of the kind's instrument measured after their window had
  // arrived (a polled gauge behind the laser; its samples carry the time of their request and
  // of their answer): when one arrives, they take the mean of the samples measured in the
  // window (requested from its start, the machine had arrived, never before; answered while
  // the machine still stood); with none in it, that first sample when it was requested and
  // answered while the machine still stood after the window, else the run ends saying so.
  struct Pending {
    std::size_t stop;
    cal::daq::Capture cap;
    cal::daq::Compensated comp;
  };
  std::vector<Pending> pending;
  cal::daq::MotionIndicator motion;
  // A capture by hand while the axis moves is refused unless pressed again (capture_guard.hpp).
  cal::daq::CaptureGuard guard;
  std::int64_t last_ns = 0;        // the newest laser, reference or feed reading's time
  std::vector<double> acceptable;  // sorted: the positions a stop could be at now
  LinearRunOutcome outcome;
  LiveState live;
  std::int64_t first_ns = -1;
  double last_raw_m = 0.0;  // the newest laser reading, for a capture made on a feed sample
  std::optional<std::size_t> last_taken;  // the stop the last capture was labelled as
  std::vector<bool> manual;               // by stop: captured by hand
  std::vector<bool> while_moving;         // by stop: captured by hand, forced while the axis moved
  bool forcing = false;                   // the capture by hand being labelled is a forced one
  std::string_view again_key =
      "Capture (C)";  // the key that forces it: the page's, the CLI's Enter
  // By stop, once stored: the value of a kind with a reader (its own; a rotary stop's deviation).
  std::vector<std::optional<double>> kind_values;
  // True for a kind whose stop value is its own instrument's (straightness, angular, roll), not
  // the deviation the sequencer computed from the position (positioning, rotary).
  bool own_value() const { return reader && !kind.stops_from_probe(); }

  Impl(boost::asio::io_context& i, LinearRunSetup s)
      : Runner(i, s.database, s.store_options),
        setup(std::move(s)),
        devices(setup.material.size()),
        plan(linear_plan(*setup.config.linear)),
        materials(setup.material.size(), setup.material_channels),
        env(setup.config.environment, materials.count()),
        trigger({.tolerance_um = setup.config.trigger.tolerance_um,
                 .dwell_s = setup.config.trigger.dwell_s,
                 .window_mm = setup.config.trigger.window_mm}),
        sequencer(plan, setup.config.trigger.window_mm,
                  kinds::kind(setup.config.linear->measure.kind).axis_units()),
        kind(kinds::kind(setup.config.linear->measure.kind)),
        motion({.tolerance_um = setup.config.trigger.tolerance_um,
                .dwell_s = setup.config.trigger.dwell_s,
                .window_mm = setup.config.trigger.window_mm}),
        guard({.tolerance_um = setup.config.trigger.tolerance_um}) {
    kind.validate(*setup.config.linear);
    reader = kind.reader(*setup.config.linear);
    live.units = kind.axis_units();
    live.stop_value = own_value() ? std::string(kind.name()) : "deviation";
    live.stop_unit = own_value() ? std::string(kind.unit()) : live.units.deviation;
    if (kind.stops_from_probe()) live.reference = "angular reference";  // rotary: no laser
    if (!kind.probe_role().empty() && !setup.probe)
      throw cal::InputError(fmt::format("a {} test needs a device with role = \"{}\"", kind.name(),
                                        kind.probe_role()));
    if (!setup.laser && !kind.stops_from_probe())
      throw cal::InputError(
          fmt::format("a {} test needs a device with role = \"laser\"", kind.name()));
    // A kind whose stops come from its own instrument (rotary) watches no feed of the linear axes.
    if (setup.position && !kind.stops_from_probe())
      position_trigger.emplace(
          cal::daq::PositionTriggerSettings{.tolerance_um = setup.config.trigger.tolerance_um,
                                            .dwell_s = setup.config.trigger.dwell_s,
                                            .feed_holds = setup.position_on_change});
  }

  // The triggers watch every position the sequencer could accept now (see acceptable_mm):
  // after a missed stop they must still see the following ones.
  void expect_next() {
    const auto positions = sequencer.acceptable_mm();
    acceptable = positions;
    if (positions.empty()) {
      trigger.expect(std::nullopt);
      if (position_trigger) position_trigger->expect(std::nullopt);
      return;
    }
    trigger.expect_any(positions);
    if (position_trigger) position_trigger->expect_any(positions);
  }

  void event(const std::string& text) {
    live.message = text;
    if (setup.on_event) setup.on_event(text);
  }

  void start() {
    open_store();
    const auto& c = setup.config;
    outcome.run_id = store->begin_run(
        {.machine_id = machine_id(c),
         .campaign = c.campaign,
         .kind = std::string(kind.run_kind()),
         .axis = c.linear->axis,
         .settings_json = settings_json(c, plan, setup.datum_mm, setup.context_json).dump(),
         .capture_path = setup.capture_path,
         .software_version = setup.software_version});
    auto add = [&](int device, const cal::drivers::Instrument& i, std::string_view role) {
      const auto origin = setup.origins.find(std::string(role));
      store->add_instrument(
          {.run_id = outcome.run_id,
           .device = device,
           .driver = std::string(role),
           .transport = i.describe(),
           .origin = origin == setup.origins.end() ? "" : origin->second.kind,
           .origin_detail = origin == setup.origins.end() ? "" : origin->second.detail});
    };
    for_each_instrument([&](cal::drivers::Instrument& i, Role role, std::size_t k) {
      add(devices.device(role, k), i, role == Role::probe ? kind.probe_role() : name(role));
    });
    outcome.component = kind.component(*setup.config.linear);
    open_writer(outcome.run_id);
    running = true;
    live.state = "waiting";
    expect_next();
    if (setup.laser) start_instrument(*setup.laser, devices.device(Role::laser));
    start_instrument(*setup.air, devices.device(Role::air));
    for (std::size_t k = 0; k < setup.material.size(); ++k)
      start_instrument(*setup.material[k], devices.device(Role::material, k));
    if (setup.position) {
      start_instrument(*setup.position, devices.device(Role::position));
      event("stops are recognised from the machine position feed (" + setup.position->describe() +
            ")");
    }
    if (setup.probe) start_instrument(*setup.probe, devices.device(Role::probe));
    if (reader) event(fmt::format("measuring {} ({})", outcome.component, kind.name()));
    event(fmt::format("run {}: {} targets x {} runs, {} stops expected", outcome.run_id,
                      plan.targets_mm.size(), c.linear->runs, sequencer.stops().size()));
    tick();
  }

  void start_instrument(cal::drivers::Instrument& inst, std::uint16_t device) {
    inst.start(
        {.reading = [this, device](const Reading& r) { on_reading(r, device); },
         .state =
             [this, &inst](cal::drivers::InstrumentState s, std::string_view why) {
               if (s == cal::drivers::InstrumentState::closed && running)
                 abort(fmt::format("{} closed: {}", inst.describe(), why));
               else if (s == cal::drivers::InstrumentState::reconnecting)
                 event(fmt::format("{}: reconnecting ({})", inst.describe(), why));
             },
         .gap =
             [this, &inst](const cal::drivers::Gap& g) {
               event(fmt::format("{}: no data for {:.2f} s ({})", inst.describe(),
                                 static_cast<double>(g.end_ns - g.start_ns) * 1e-9, g.reason));
             },
         .codec_error =
             codec_errors_as_events(inst.describe(), [this](const std::string& e) { event(e); }),
         .message =
             [this, &inst](const cal::drivers::DeviceMessage& m) {
               event(fmt::format("{}: {}{}: {}", inst.describe(), to_string(m.severity),
                                 m.code ? fmt::format(" {}", m.code) : "", m.text));
             }});
  }

  void on_reading(Reading r, std::uint16_t device) {
    if (!running) return;
    r.device = device;
    ++outcome.readings;
    if (!store_reading({.time_ns = r.time_ns,
                        .device = r.device,
                        .channel = r.channel,
                        .quantity = static_cast<std::uint8_t>(r.quantity),
                        .status = static_cast<std::uint8_t>(r.status),
                        .value = r.value}))
      return;
    if (setup.on_reading) setup.on_reading(r);
    if (first_ns < 0) {
      first_ns = r.time_ns;
      set_time_origin(outcome.run_id, r.time_ns);
    }
    if (reader && devices.is(Role::probe, device) && r.status == ReadingStatus::ok &&
        (r.quantity == Quantity::length_m || r.quantity == Quantity::angle_rad))
      return add_sample(kinds::Source::probe, r);
    // A sample the device flagged (out of range, no signal) is stored, never an air or
    // material value: its value may be anything (a sensor's error code, a clipped reading).
    if (r.status != ReadingStatus::ok && r.quantity != Quantity::displacement_m &&
        r.quantity != Quantity::machine_position_m)
      return;
    switch (r.quantity) {
      case Quantity::air_temperature_degc:
        return env.add_air(r.time_ns, cal::daq::AirQuantity::temperature_degc, r.value);
      case Quantity::air_pressure_pa:
        return env.add_air(r.time_ns, cal::daq::AirQuantity::pressure_pa, r.value);
      case Quantity::air_humidity_pct:  // not of a material thermometer: a TEMPerX on the table
        if (!devices.is(Role::laser, device) && !devices.is(Role::air, device))
          return;  // measures the humidity there, not in the beam
        return env.add_air(r.time_ns, cal::daq::AirQuantity::humidity_pct, r.value);
      case Quantity::material_temperature_degc:
      case Quantity::length_m:  // a line thermometer reports through the gauge codec
        if (const auto k = devices.index(Role::material, device))
          if (const int sensor = materials.sensor(*k, r.channel); sensor >= 0)
            env.add_material(r.time_ns, sensor, r.value);
        return;
      case Quantity::displacement_m:
        if (!devices.is(Role::laser, device)) return;
        if (r.channel == setup.laser_channel) return on_laser(r);
        if (reader && r.status == ReadingStatus::ok) {
          Reading c = r;
          c.value = env.compensated_length_m(r.time_ns, r.value);
          add_sample(kinds::Source::laser, c);
        }
        return;
      case Quantity::machine_position_m:
        if (position_trigger && devices.is(Role::position, device) &&
            r.channel == setup.position_channel) {
          if (r.status == ReadingStatus::ok) guard.add_feed(r.time_ns, r.value * 1e3);
          last_ns = std::max(last_ns, r.time_ns);
          // A feed without a position (SHDR UNAVAILABLE) ends the stillness it held.
          if (auto cap = position_trigger->add_position(
                  r.time_ns, r.status == ReadingStatus::ok
                                 ? r.value * 1e3
                                 : std::numeric_limits<double>::quiet_NaN()))
            on_capture(*cap, env.compensate(r.time_ns, last_raw_m));
        }
        return;
      default:
        return;
    }
  }

  // A sample of the kind's value; the newest few minutes are kept for the stops' windows.
  void add_sample(kinds::Source source, const Reading& r) {
    if (const auto v = reader->add(source, r.channel, r.time_ns, r.value)) {
      const Sample s{r.time_ns, r.time_ns + std::int64_t{r.measured_within_ms} * 1'000'000, *v};
      samples.push_back(s);
      while (samples.size() > 1'000'000) samples.pop_front();  // bounded, whatever the rate
      resolve_pending(s);
      if (source == kinds::Source::probe && kind.stops_from_probe() && !done)
        on_reference(r.time_ns, *v / kArcsecPerDeg);
    }
  }

  static constexpr double kArcsecPerDeg = 3600.0;

  // A reading of the angular reference of a kind whose stops it gives (rotary): its continuous
  // angle in degrees is the position the trigger and the sequencer watch, as the laser's length
  // in mm is for a linear axis (the trigger's tolerance_um reads as millidegrees, window_mm as
  // degrees). Not compensated for air or material, an angle is not a length: the air's
  // staleness does not stop it (the air is recorded only).
  void on_reference(std::int64_t time_ns, double angle_deg) {
    live.time_s = static_cast<double>(time_ns - first_ns) * 1e-9;
    live.position_mm = angle_deg;
    if (const auto next = sequencer.next_expected_mm())
      live.deviation_um = sequencer.units().deviation_of(angle_deg, *next);
    live.state = "measuring";
    show_motion(time_ns, angle_deg, true);
    guard.add_reading(time_ns, angle_deg, true);
    last_ns = std::max(last_ns, time_ns);
    // The stop's value is the kind's (the window mean of the reference); raw 1 m, a factor 1.
    if (auto cap = trigger.add(time_ns, angle_deg, true)) {
      auto c = env.compensate(time_ns, 1.0);
      c.length_m = c.raw_m;
      on_capture(*cap, c);
    }
  }

  // Until when the machine surely still stands at a captured stop: it stands the program's
  // dwell, and the trigger captured after its own dwell of it.
  std::int64_t standing_until_ns(const cal::daq::Capture& cap) const {
    const double trigger_s = setup.config.trigger.dwell_s;
    return cap.end_ns + static_cast<std::int64_t>(
                            1e9 * std::min(trigger_s, setup.config.linear->dwell_s - trigger_s));
  }

  void resolve_pending(const Sample& sample) {
    if (pending.empty()) return;
    auto waiting = std::move(pending);
    pending.clear();
    for (const auto& p : waiting) {
      if (sample.time_ns <= p.cap.end_ns) {  // in the window (kept in `samples`), or measured
        pending.push_back(p);                // before the machine had arrived: not this stop's
      } else if (const auto v = window_mean(p.cap)) {  // every sample of the window is in
        store_stop(p.stop, p.cap, p.comp, *v);
      } else if (sample.latest_ns <= standing_until_ns(p.cap)) {  // none in the window: the
        store_stop(p.stop, p.cap, p.comp, sample.value);          // machine still stood
      } else {
        return abort(no_reading_at(p.stop));
      }
    }
    if (!done && pending.empty() && sequencer.complete()) finish();
  }

  std::string no_reading_at(std::size_t stop) const {
    const auto& s = sequencer.stops()[stop];
    const std::string role =
        kind.probe_role().empty() ? "laser's beam pair" : std::string(kind.probe_role());
    std::string text = fmt::format(
        "no {} reading measured while the machine stood at {:.3f} mm "
        "(run {}): is the {} reading?",
        kind.name(), s.position_mm, s.run, role);
    if (const auto a = probe_latency(); a && a->answers > 0)
      text += fmt::format(
          " Its answers came up to {:.0f} ms after their requests (median {:.0f} ms); a value "
          "answered after the machine has left cannot be told from the next target's",
          static_cast<double>(a->max_ns) / 1e6, static_cast<double>(a->median_ns) / 1e6);
    return text;
  }

  // The kind's value at a stop: the mean of its samples measured within the stop's window
  // (requested in it, answered while the machine still stood).
  std::optional<double> window_mean(const cal::daq::Capture& cap) const {
    const std::int64_t until = standing_until_ns(cap);
    double sum = 0;
    std::size_t n = 0;
    for (const auto& s : samples)
      if (s.time_ns >= cap.start_ns && s.time_ns <= cap.end_ns && s.latest_ns <= until)
        sum += s.value, ++n;
    if (n == 0) return std::nullopt;
    return sum / static_cast<double>(n);
  }
  // ... once every sample measured in the window is in: when one measured after it has arrived
  // (a source's samples arrive in the order they were measured); else nullopt (pending).
  std::optional<double> stop_value(const cal::daq::Capture& cap) const {
    if (samples.empty() || samples.back().time_ns <= cap.end_ns) return std::nullopt;
    return window_mean(cap);
  }
  // Samples older than every window still to be valued are not needed any more.
  void trim_samples(std::int64_t from_ns) {
    for (const auto& p : pending) from_ns = std::min(from_ns, p.cap.start_ns);
    while (!samples.empty() && samples.front().time_ns < from_ns) samples.pop_front();
  }

  void on_laser(const Reading& r) {
    const auto health = env.check(r.time_ns);
    for (const auto& m : health.messages) event(m);
    if (health.must_stop) return abort(live.message);
    const auto c = env.compensate(r.time_ns, r.value);
    const double position_mm = setup.datum_mm + c.length_m * 1e3;
    live.time_s = static_cast<double>(r.time_ns - first_ns) * 1e-9;
    live.position_mm = position_mm;
    live.air_temperature_degc = c.air_temperature_degc;
    live.pressure_pa = c.pressure_pa;
    live.humidity_pct = c.humidity_pct;
    live.n = c.n;
    live.material_degc = c.material_degc;
    live.factor_ppm = c.factor_ppm;
    live.fallback = c.fallback_air || c.fallback_material;
    if (const auto next = sequencer.next_expected_mm())
      live.deviation_um = (position_mm - *next) * 1e3;
    live.state = "measuring";
    const bool valid = r.status == ReadingStatus::ok;
    last_raw_m = r.value;
    show_motion(r.time_ns, position_mm, valid);
    guard.add_reading(r.time_ns, position_mm, valid);
    last_ns = std::max(last_ns, r.time_ns);
    if (position_trigger) {
      if (auto cap = position_trigger->add_reading(r.time_ns, position_mm, valid))
        on_capture(*cap, c);
    } else if (auto cap = trigger.add(r.time_ns, position_mm, valid)) {
      on_capture(*cap, c);
    }
  }

  // The page's indicator and number (motion.hpp): the deviation from the target whose window
  // holds the position, else the position.
  void show_motion(std::int64_t time_ns, double position_mm, bool valid) {
    motion.add(time_ns, position_mm, valid, acceptable);
    live.has_reading = true;
    live.valid = valid;
    live.motion = std::string(cal::daq::to_string(motion.motion()));
    live.stable_fraction = motion.stable_fraction();
    live.at_target_mm = motion.target_mm();
    if (live.at_target_mm)
      live.at_target_deviation_um = sequencer.units().deviation_of(position_mm, *live.at_target_mm);
  }

  void on_capture(const cal::daq::Capture& cap, const cal::daq::Compensated& c) {
    for (const auto& e : sequencer.on_capture(cap)) {
      using Kind = cal::daq::SequenceEvent::Kind;
      // A kind with a reader says its stop's value when stored (store_stop): the sequencer's
      // text holds the trigger's mean, which is not what the stop stores (the laser's
      // positioning deviation; a rotary stop's trigger mean, up to 0.25" from the window mean
      // of its reference that is stored and evaluated).
      if (!(reader && e.kind == Kind::captured)) event(e.message);
      if (e.kind == Kind::captured || e.kind == Kind::out_of_order) {
        last_taken = e.stop;
        manual.resize(sequencer.stops().size());
        manual[e.stop] = cap.manual;
        while_moving.resize(sequencer.stops().size());
        while_moving[e.stop] = cap.manual && forcing;
        {
          const auto& s = sequencer.stops()[e.stop];
          motion.captured(cap.mean_mm, s.position_mm, cap.end_ns);
          if (const auto t = motion.last_stop())
            live.last_settling_s = t->settling_s, live.last_stable_s = t->stable_s;
        }
        double value = sequencer.stops()[e.stop].deviation_um;
        if (reader) {
          const auto v = stop_value(cap);
          if (!v) {
            pending.push_back({e.stop, cap, c});
            trim_samples(cap.start_ns);
            continue;
          }
          value = *v;
          trim_samples(cap.start_ns);
        }
        if (!store_stop(e.stop, cap, c, value)) return;
      }
    }
    expect_next();
    if (sequencer.complete() && pending.empty()) finish();
  }

  // Stores a captured stop with the kind's value; false when the store failed (run aborted).
  bool store_stop(std::size_t stop, const cal::daq::Capture& cap, const cal::daq::Compensated& c,
                  double window_mean) {
    const auto& s = sequencer.stops()[stop];
    const double value = kind.stop_value(s.position_mm, window_mean);
    if (reader) {  // the live table and the event show the value stored, not the trigger's
      kind_values.resize(sequencer.stops().size());
      kind_values[stop] = value;
      if (own_value())
        event(fmt::format("{}: {} {} {}", sequencer.describe(s), kind.name(),
                          signed_number_text(value), kind.unit()));
      else  // rotary: the sequencer's words, with the stored deviation
        event(fmt::format("{}: {} {}", sequencer.describe(s), signed_number_text(value),
                          sequencer.units().deviation));
    }
    values.push_back({.position_mm = s.position_mm,
                      .target_index = s.target_index - 1,
                      .run = s.run,
                      .direction = s.direction == cal::iso230_2::Direction::up ? '+' : '-',
                      .value = value});
    const cal::storage::CapturedTarget t{
        .run_id = outcome.run_id,
        .target_index = s.target_index - 1,
        .run_number = s.run,
        .direction = s.direction == cal::iso230_2::Direction::up ? '+' : '-',
        .nominal_mm = s.position_mm,
        .time_ns = cap.end_ns,
        // A rotary stop's raw value is its reference's angle in SI (rad), as its readings are.
        .raw_m = kind.stops_from_probe()
                     ? cap.mean_mm * std::numbers::pi / 180.0
                     : (cap.mean_mm - setup.datum_mm) * 1e-3 / (c.length_m / c.raw_m),
        .deviation_um = value,  // the kind's value (um, urad; arcsec: settings.measure.unit)
        .refractive_index = c.n,
        .material_temperature_degc = c.material_degc};
    try {
      store->add_targets(std::span(&t, 1));
    } catch (const std::exception& err) {
      abort(fmt::format("storage failed: {}", err.what()));
      return false;
    }
    return true;
  }

  // The end of the plan. A run is complete only when every planned stop was captured; one
  // with missed stops is stored incomplete with them listed, and evaluated from what it has.
  void finish() {
    running = false;
    report_probe_latency();
    try {
      writer->flush();
      outcome.missed = missed_stops();
      store->set_missed_stops(outcome.run_id, outcome.missed);
      check_quality();
      outcome.status = outcome.missed.empty() ? cal::storage::RunStatus::complete
                                              : cal::storage::RunStatus::incomplete;
      if (!outcome.missed.empty())
        outcome.reason = fmt::format("{} of {} planned stops missed", outcome.missed.size(),
                                     sequencer.stops().size());
      const auto& l = *setup.config.linear;
      if (reader) return finish_profile(l);
      const auto standard = cal::iso230_2::standard_from_string(l.standard);
      try {
        outcome.evaluation = cal::iso230_2::evaluate(sequencer.measurements(), standard);
      } catch (const std::exception& e) {
        return not_evaluated(e.what());
      }
      json prov = result_provenance();
      prov["standard"] = l.standard;
      prov["sensor_offsets"] = to_json(SensorOffsets{});
      store->add_result({.run_id = outcome.run_id,
                         .standard = std::string(outcome.evaluation->standard.title),
                         .json = to_json(*outcome.evaluation).dump(),
                         .provenance_json = prov.dump()});
      store->finish_run(outcome.run_id, outcome.status, outcome.reason);
    } catch (const cal::storage::StoreError& e) {  // a full disk: the run ends as aborted
      outcome.evaluation.reset();
      return abort(fmt::format("storage failed: {}", e.what()));
    }
    outcome.complete = true;
    live.state = outcome.missed.empty() ? "complete" : "incomplete";
    end();
  }

  // The missed stops stored as they are now; false when the store failed (the run aborted).
  bool store_missed() {
    try {
      store->set_missed_stops(outcome.run_id, missed_stops());
    } catch (const std::exception& e) {
      abort(fmt::format("storage failed: {}", e.what()));
      return false;
    }
    return true;
  }

  // The stops passed without a capture so far (skipped ones included), as the store keeps them.
  std::vector<cal::storage::MissedStop> missed_stops() const {
    std::vector<cal::storage::MissedStop> out;
    for (const auto i : sequencer.missed()) {
      const auto& s = sequencer.stops()[i];
      out.push_back({.run_id = outcome.run_id,
                     .run_number = s.run,
                     .direction = s.direction == cal::iso230_2::Direction::up ? '+' : '-',
                     .target_index = s.target_index - 1,
                     .nominal_mm = s.position_mm});
    }
    return out;
  }

  // The stops against the run's own repeatability (run_quality.hpp): stored with the run and
  // said, each suspect stop by name.
  void check_quality() {
    outcome.quality = assess_stops(store->targets(outcome.run_id), kind.unit());
    store->set_quality(outcome.run_id, outcome.quality);
    event(fmt::format("stop quality: {}", quality_text(outcome.quality)));
    for (const auto& s : outcome.quality.suspects) event("SUSPECT stop: " + s.reason);
  }

  // A polled probe's answers: how late they came after their requests (each value carries its
  // request's time), stated in the run's events and its results' provenance.
  std::optional<cal::drivers::AnswerLatency> probe_latency() const {
    return setup.probe ? setup.probe->answer_latency() : std::nullopt;
  }
  void report_probe_latency() {
    if (const auto a = probe_latency(); a && a->answers > 0)
      event(fmt::format(
          "{}: answers {:.1f} ms after their request (median), at most {:.1f} ms, over {} "
          "answers; each value is taken at its request's time{}",
          setup.probe->describe(), static_cast<double>(a->median_ns) * 1e-6,
          static_cast<double>(a->max_ns) * 1e-6, a->answers,
          a->unmatched ? fmt::format(" ({} answers without a request: at arrival)", a->unmatched)
                       : ""));
  }

  // What every stored result of the run says of how it was obtained (provenance.hpp).
  json result_provenance() const {
    json prov = provenance(setup.replay ? "replayed" : "acquired", setup.software_version);
    prov["coefficients"] = compensation_json(setup.config.environment);
    if (const auto a = probe_latency())
      prov["probe_answer_latency"] = {{"answers", a->answers},
                                      {"unmatched", a->unmatched},
                                      {"median_ms", static_cast<double>(a->median_ns) * 1e-6},
                                      {"max_ms", static_cast<double>(a->max_ns) * 1e-6},
                                      {"stamped", "request"}};
    if (setup.replay) {
      prov["capture"] = setup.capture_path;
      prov["replay_of_run"] = setup.replay_of_run ? json(*setup.replay_of_run) : json(nullptr);
    }
    return prov;
  }

  // Too little was captured to evaluate: the run is stored as it is, and says why.
  void not_evaluated(const std::string& why) {
    outcome.status = cal::storage::RunStatus::incomplete;
    outcome.reason += (outcome.reason.empty() ? "" : "; ") + std::string("not evaluated: ") + why;
    store->finish_run(outcome.run_id, outcome.status, outcome.reason);
    live.state = "incomplete";
    end();
  }

  // The end of a run of another kind than positioning: its profile is its result.
  void finish_profile(const cal::daq::LinearTestConfig& l) {
    try {
      auto e = kind.evaluate(values, l);
      json prov = result_provenance();
      prov["measure"] = kind.name();
      store->add_result({.run_id = outcome.run_id,
                         .standard = e.title,
                         .json = e.json.dump(),
                         .provenance_json = prov.dump()});
      outcome.profile = std::move(e.json);
    } catch (const cal::InputError& e) {
      return not_evaluated(e.what());
    }
    store->finish_run(outcome.run_id, outcome.status, outcome.reason);
    outcome.complete = true;
    live.state = outcome.missed.empty() ? "complete" : "incomplete";
    end();
  }

  // --- the operator's control (issue 29) ---------------------------------------------------

  ControlOutcome control(Control c, std::string_view source) {
    if (!running) return {false, "the run has ended"};
    ControlOutcome out;
    std::optional<std::size_t> stop;
    switch (c) {
      case Control::capture:
        out = capture_by_hand(stop);
        break;
      case Control::skip:
        out = skip(stop);
        break;
      case Control::retry:
        out = retry(stop);
        break;
      case Control::pause:
      case Control::resume:
        out = pause(c == Control::pause);
        break;
    }
    if (!out.applied) return out;
    record(c, source, stop, out.message);
    event(out.message);
    if (running && sequencer.complete() && pending.empty()) finish();
    return out;
  }

  // The current window, whatever its spread, labelled by the sequencer as an automatic capture
  // is; a capture it does not take (no target there) changes nothing. While the trigger sees
  // the axis moving (capture_guard.hpp) it is refused, unless pressed again within 3 s: then
  // taken and marked as taken while moving (the stop table, the run's record, the report).
  ControlOutcome capture_by_hand(std::optional<std::size_t>& stop) {
    const auto verdict = guard.press(last_ns, motion.motion());
    if (!verdict.take)
      return {.applied = false,
              .message = guard.refusal(verdict.moving, again_key),
              .force_within_s = guard.force_within_s()};
    auto cap = position_trigger ? position_trigger->capture_now() : trigger.capture_now();
    if (!cap)
      return {false, "nothing to capture: no laser reading since the last capture or the start"};
    // on_capture uses only the ratio length / raw, a pure factor (refraction and material
    // temperature): any non-zero raw length gives it, 0 would give 0 / 0.
    const auto comp = env.compensate(cap->end_ns, 0.1);
    last_taken.reset();
    forcing = verdict.while_moving;  // read by on_capture for this capture only
    on_capture(*cap, comp);
    forcing = false;
    if (!last_taken) {
      rearm();  // the automatic trigger watches this stop again
      return {false, fmt::format("not captured: {}", live.message)};
    }
    stop = last_taken;
    const auto& s = sequencer.stops()[*stop];
    const auto& u = sequencer.units();
    const auto value =
        fmt::format("{}: {} {}", describe(s),
                    signed_number_text(u.deviation_of(cap->mean_mm, s.position_mm)), u.deviation);
    if (verdict.while_moving)
      return {true, fmt::format("captured by hand WHILE MOVING ({}), forced by a second press: {}",
                                verdict.moving, value)};
    return {true, fmt::format("captured by hand: {}", value)};
  }

  ControlOutcome skip(std::optional<std::size_t>& stop) {
    stop = sequencer.skip();
    if (!stop) return {false, "no target left to skip: the plan is complete"};
    expect_next();
    // Stored at once among the missed stops, so a run stopped or killed later still lists it.
    if (!store_missed()) return {false, "storage failed: the run was aborted"};
    return {true, fmt::format("skipped by the operator: {}", describe(sequencer.stops()[*stop]))};
  }

  // The last stop passed is expected again: its value (if captured) is dropped from the run and
  // the trigger measures it after a fresh dwell (or a capture by hand takes it).
  ControlOutcome retry(std::optional<std::size_t>& stop) {
    const auto before = sequencer.next_index() > 0
                            ? std::optional(sequencer.stops()[sequencer.next_index() - 1])
                            : std::nullopt;
    stop = sequencer.reopen_last();
    if (!stop || !before) return {false, "no stop passed yet: nothing to measure again"};
    std::string dropped = before->skipped ? " (it was skipped)" : " (it was missed)";
    if (before->captured) {
      dropped = fmt::format(" (the value {} {} discarded)",
                            signed_number_text(before->deviation_um), sequencer.units().deviation);
      if (!forget_stop(*before)) return {false, "storage failed: the run was aborted"};
    }
    if (*stop < manual.size()) manual[*stop] = false;
    if (*stop < while_moving.size()) while_moving[*stop] = false;
    if ((before->missed || before->skipped) && !store_missed())
      return {false, "storage failed: the run was aborted"};
    rearm();
    expect_next();
    return {true, fmt::format("measuring again: {}{}", describe(*before), dropped)};
  }

  ControlOutcome pause(bool on) {
    if (live.paused == on)
      return {false, on ? "the run is already paused" : "the run is not paused"};
    live.paused = on;
    trigger.hold(on);
    if (position_trigger) position_trigger->hold(on);
    return {true, on ? "paused: no automatic capture until resumed (capture by hand still works)"
                     : "resumed: stops are captured again"};
  }

  void rearm() {
    trigger.rearm();
    if (position_trigger) position_trigger->rearm();
  }

  std::string describe(const cal::daq::ExpectedStop& s) const { return sequencer.describe(s); }

  // A stop's value out of the run: the kind's values, a value still waiting for its probe, and
  // the stored target. False when the store failed (the run is then aborted).
  bool forget_stop(const cal::daq::ExpectedStop& s) {
    const char dir = s.direction == cal::iso230_2::Direction::up ? '+' : '-';
    std::erase_if(values, [&](const kinds::StopValue& v) {
      return v.run == s.run && v.direction == dir && v.target_index == s.target_index - 1;
    });
    std::erase_if(pending, [&](const Pending& p) {
      const auto& q = sequencer.stops()[p.stop];
      return q.run == s.run && q.direction == s.direction && q.target_index == s.target_index;
    });
    try {
      auto kept = store->targets(outcome.run_id);
      std::erase_if(kept, [&](const cal::storage::CapturedTarget& t) {
        return t.run_number == s.run && t.direction == dir && t.target_index == s.target_index - 1;
      });
      store->replace_targets(outcome.run_id, kept);
    } catch (const std::exception& e) {
      abort(fmt::format("storage failed: {}", e.what()));
      return false;
    }
    return true;
  }

  // The action in the run's record, with the stop it acted on, as it happens.
  void record(Control c, std::string_view source, std::optional<std::size_t> stop,
              const std::string& detail) {
    cal::storage::OperatorAction a{.run_id = outcome.run_id,
                                   .action = std::string(to_string(c)),
                                   .source = std::string(source),
                                   .operator_name = setup.config.operator_name,
                                   .detail = detail};
    if (stop) {
      const auto& s = sequencer.stops()[*stop];
      a.stop = cal::storage::MissedStop{
          .run_id = outcome.run_id,
          .run_number = s.run,
          .direction = s.direction == cal::iso230_2::Direction::up ? '+' : '-',
          .target_index = s.target_index - 1,
          .nominal_mm = s.position_mm};
    }
    try {
      store->add_operator_action(a);
    } catch (const std::exception& e) {
      abort(fmt::format("storage failed: {}", e.what()));
    }
  }

  // Runner's hooks: how a linear run records its abort and stops its instruments.
  std::int64_t current_run() const override { return outcome.run_id; }
  void aborting(const std::string& reason) override {
    outcome.reason = reason;
    outcome.status = cal::storage::RunStatus::aborted;
    live.state = "aborted";
    live.message = reason;
  }
  void aborted(const std::string& reason) override { outcome.reason = reason; }
  void stop_instruments() override {
    for_each_instrument([](cal::drivers::Instrument& i, Role, std::size_t) { i.stop(); });
  }
  void on_tick() override { publish(); }
  void on_end() override { publish(); }

  // Each instrument of the run with its role and its index in the role, in device order.
  template <typename F>
  void for_each_instrument(F&& f) {
    if (setup.laser) f(*setup.laser, Role::laser, 0);
    f(*setup.air, Role::air, 0);
    for (std::size_t k = 0; k < setup.material.size(); ++k)
      f(*setup.material[k], Role::material, k);
    if (setup.position) f(*setup.position, Role::position, 0);
    if (setup.probe) f(*setup.probe, Role::probe, 0);
  }

  void publish() {
    if (!setup.on_live) return;
    live.progress = sequencer.progress();
    const auto& stops = sequencer.stops();
    live.stop_count = stops.size();
    live.stop_number = sequencer.next_index() + 1;
    live.stops.clear();
    for (std::size_t i = 0; i < stops.size(); ++i) {
      const auto& s = stops[i];
      if (!s.captured && !s.missed) continue;
      live.stops.push_back(
          {.number = i + 1,
           .run = s.run,
           .target = s.target_index,
           .up = s.direction == cal::iso230_2::Direction::up,
           .nominal_mm = s.position_mm,
           .deviation_um =
               i < kind_values.size() && kind_values[i] ? *kind_values[i] : s.deviation_um,
           .missed = s.missed && !s.captured,
           .skipped = s.skipped,
           .manual = s.captured && i < manual.size() && manual[i],
           .while_moving = s.captured && i < while_moving.size() && while_moving[i],
           .pending = s.captured && reader && !(i < kind_values.size() && kind_values[i])});
    }
    setup.on_live(live);
  }
};

LinearRun::LinearRun(boost::asio::io_context& io, LinearRunSetup setup)
    : impl_(std::make_unique<Impl>(io, std::move(setup))) {}
LinearRun::~LinearRun() { impl_->stop_if_running(); }
void LinearRun::start() { impl_->start(); }
void LinearRun::stop(const std::string& reason) { impl_->abort(reason); }
void LinearRun::manual_capture() {
  impl_->again_key = "Enter";  // daq run's keyboard: Enter is its capture
  const auto out = impl_->control(Control::capture, "keyboard (daq run)");
  if (!out.applied) impl_->event(out.message);
}
ControlOutcome LinearRun::control(Control c, std::string_view source) {
  return impl_->control(c, source);
}

std::string_view to_string(Control c) {
  using enum Control;
  static constexpr cal::EnumName<Control> kNames[] = {
      {capture, "capture"}, {skip, "skip"}, {retry, "retry"}, {pause, "pause"}, {resume, "resume"}};
  static_assert(cal::names_every_value(kNames));
  return cal::name_of(kNames, c);
}
void LinearRun::publish_live() {
  if (!impl_->done) impl_->publish();
}
bool LinearRun::finished() const { return impl_->done; }
const LinearRunOutcome& LinearRun::outcome() const { return impl_->outcome; }
const cal::iso230_2::Plan& LinearRun::plan() const { return impl_->plan; }

}  // namespace daq
