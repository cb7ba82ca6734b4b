// Five-axis ballbar run (see ballbar5x_run.hpp).
#include "ballbar5x_run.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "provenance.hpp"
#include "roles.hpp"
#include "runner.hpp"

namespace daq {

using nlohmann::json;
namespace kin = cal::kinematics;

std::vector<double> RotaryBallbarTiming::stop_starts_s(const std::vector<double>& angles) const {
  std::vector<double> out;
  double t = 0.0;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    if (k > 0) t += dwell_s + std::abs(angles[k] - angles[k - 1]) / rate_deg_per_s;
    out.push_back(t);
  }
  return out;
}

json timing_json(const RotaryBallbarTiming& t) {
  return {{"sample_rate_hz", t.sample_rate_hz},
          {"feed_in_mm", t.feed_in_mm},
          {"feed_in_s", t.feed_in_s},
          {"out_s", t.out_s},
          {"dwell_s", t.dwell_s},
          {"settle_s", t.settle_s},
          {"rate_deg_per_s", t.rate_deg_per_s}};
}

RotaryBallbarSegmenter::RotaryBallbarSegmenter(std::vector<kin::RotaryBallbarTest> tests,
                                               RotaryBallbarTiming timing)
    : tests_(std::move(tests)), t_(timing) {
  if (tests_.empty()) throw cal::InputError("five-axis ballbar run: no test");
  if (!(t_.sample_rate_hz > 0 && t_.dwell_s > 1.5 * t_.settle_s && t_.rate_deg_per_s > 0 &&
        t_.feed_in_mm > 0))
    throw cal::InputError("five-axis ballbar run: the program's timing is not usable");
  starts_ = t_.stop_starts_s(tests_.front().angles_deg);
  stops_.emplace_back();
}

// The feed-in as a circle run finds it (pipeline/ballbar.cpp): first out (more than half the
// feed-in), then within 0.2 mm of zero for 50 ms; the move's end is where that began. 0.2 mm,
// not the circle's 5 % of the feed-in: a five-axis test's first stop may read up to ~0.1 mm of
// location errors and bar offset.
void RotaryBallbarSegmenter::add(double v) {
  if (complete()) return;
  const std::size_t i = index_++;
  if (!feed_in_end_) {
    if (v > 0.5 * t_.feed_in_mm) saw_out_ = true, settle_count_ = 0;
    if (!saw_out_) return;
    if (std::abs(v) >= 0.2) {
      settle_count_ = 0;
      return;
    }
    if (++settle_count_ < static_cast<std::size_t>(0.05 * t_.sample_rate_hz) + 1) return;
    feed_in_end_ = i + 1 - settle_count_;
    sum_sq_.assign(starts_.size(), 0.0);
    stops_.back().assign(starts_.size(), {});
    for (std::size_t k = 0; k < starts_.size(); ++k)
      stops_.back()[k].angle_deg = tests_[test_].angles_deg[k];
    // The samples since the feed-in's end (the settling ones) are before any window.
    return;
  }
  const double s = static_cast<double>(i - *feed_in_end_) / t_.sample_rate_hz;
  auto& stops = stops_.back();
  for (std::size_t k = 0; k < starts_.size(); ++k) {
    if (s < starts_[k] + t_.settle_s || s >= starts_[k] + t_.dwell_s - 0.5 * t_.settle_s) continue;
    auto& st = stops[k];
    ++st.samples;
    st.reading_um += 1e3 * v;  // a sum until the test ends
    sum_sq_[k] += 1e6 * v * v;
  }
  if (s < starts_.back() + t_.dwell_s) return;
  for (std::size_t k = 0; k < stops.size(); ++k) {
    auto& st = stops[k];
    const auto n = static_cast<double>(st.samples);
    st.reading_um /= n;
    st.spread_um =
        st.samples > 1
            ? std::sqrt(std::max(0.0, (sum_sq_[k] - n * st.reading_um * st.reading_um) / (n - 1)))
            : 0.0;
  }
  ++test_;
  feed_in_end_.reset();
  saw_out_ = false;
  settle_count_ = 0;
  if (complete()) return;
  starts_ = t_.stop_starts_s(tests_[test_].angles_deg);
  stops_.emplace_back();
}

std::vector<std::vector<RotaryBallbarStop>> RotaryBallbarSegmenter::stops() const {
  if (!complete())
    throw cal::InputError(fmt::format(
        "five-axis ballbar run: test {} ({} of {}) {}", tests_[test_].name, test_ + 1,
        tests_.size(),
        feed_in_end_ ? "was not read to its last stop" : "never fed in (no feed-in move found)"));
  return stops_;
}

json ballbar5x_result(const kin::FiveAxisMachine& control,
                      const std::vector<kin::RotaryBallbarTest>& tests,
                      const std::vector<std::vector<RotaryBallbarStop>>& stops) {
  std::map<kin::RotaryLetter, std::vector<std::size_t>> by_axis;
  for (std::size_t n = 0; n < tests.size(); ++n) by_axis[tests[n].axis].push_back(n);
  json axes = json::array();
  for (const auto& [letter, which] : by_axis) {
    std::vector<kin::RotaryBallbarRun> runs;
    for (std::size_t n : which) {
      kin::RotaryBallbarRun r{tests[n], {}};
      for (const auto& s : stops.at(n)) r.reading_um.push_back(s.reading_um);
      runs.push_back(std::move(r));
    }
    const auto f = kin::fit_rotary_ballbar(control, letter, runs);
    const auto names = kin::location_error_names(letter);
    // The control's own values, in the fit's order (what a correction put into it).
    std::array<double, 4> held{};
    for (const auto& r : control.rotary) {
      if (r.letter != letter) continue;
      std::size_t m = 0;
      for (std::size_t i = 0; i < 3; ++i) {
        if (i == kin::direction_index(letter)) continue;
        held.at(m) = r.location_position_um.at(i);
        held.at(m + 2) = r.location_orientation_urad.at(i);
        ++m;
      }
    }
    json loc = json::object();
    for (std::size_t k = 0; k < 4; ++k)
      loc[names.at(k)] = {{"value", f.value.at(k)},
                          {"uncertainty", f.uncertainty.at(k)},
                          {"control", held.at(k)},
                          {"left", f.value.at(k) - held.at(k)},
                          {"unit", k < 2 ? "um" : "urad"}};
    json rows = json::array();
    for (std::size_t m = 0; m < which.size(); ++m) {
      const auto& t = tests[which[m]];
      json st = json::array();
      for (std::size_t k = 0; k < t.angles_deg.size(); ++k) {
        const auto& s = stops.at(which[m]).at(k);
        st.push_back({{"angle_deg", s.angle_deg},
                      {"reading_um", s.reading_um},
                      {"spread_um", s.spread_um},
                      {"samples", s.samples},
                      {"residual_um", f.residual_um.at(m).at(k)}});
      }
      rows.push_back({{"test", t.name},
                      {"setup", kin::to_string(t.setup)},
                      {"ball_mm", t.table_ball_mm},
                      {"length_mm", t.length_mm},
                      {"offset_um", f.offset_um.at(m)},
                      {"offset_u_um", f.offset_u_um.at(m)},
                      {"stops", st}});
    }
    axes.push_back({{"axis", kin::to_string(letter)},
                    {"names", names},  // the location errors' order (ISO 230-1's)
                    {"location", loc},
                    {"rms_um", f.rms_um},
                    {"sigma_um", f.sigma_um},
                    {"dof", f.dof},
                    {"tests", rows}});
  }
  return {{"schema", "caldaq.ballbar5x.v1"}, {"axes", axes}};
}

std::vector<FittedLocation> fitted_locations(const json& result) {
  std::vector<FittedLocation> out;
  for (const auto& a : result.at("axes"))
    for (const auto& name : a.at("names")) {
      const auto& v = a.at("location").at(name.get<std::string>());
      out.push_back({name.get<std::string>(), v.at("value").get<double>(),
                     v.at("uncertainty").get<double>(), v.at("left").get<double>()});
    }
  return out;
}

struct RotaryBallbarRun::Impl : Runner {
  RotaryBallbarRunSetup setup;
  RotaryBallbarSegmenter segmenter;
  RotaryBallbarRunOutcome outcome;
  const std::uint16_t ballbar_device = RunDevices().device(Role::ballbar);
  std::size_t told_test = 0;

  Impl(boost::asio::io_context& i, RotaryBallbarRunSetup s)
      : Runner(i, s.database, {}), setup(std::move(s)), segmenter(setup.tests, setup.timing) {}

  void event(const std::string& e) {
    if (setup.on_event) setup.on_event(e);
  }

  void start() {
    open_store();
    json settings{{"tests", json::array()}, {"timing", timing_json(setup.timing)}};
    for (const auto& t : setup.tests)
      settings["tests"].push_back({{"test", t.name},
                                   {"axis", kin::to_string(t.axis)},
                                   {"setup", kin::to_string(t.setup)},
                                   {"ball_mm", t.table_ball_mm},
                                   {"length_mm", t.length_mm},
                                   {"angles_deg", t.angles_deg}});
    if (!setup.extra_settings_json.empty()) settings.update(json::parse(setup.extra_settings_json));
    std::string axes;
    for (const auto& t : setup.tests)
      if (axes.find(kin::to_string(t.axis)) == std::string::npos) axes += kin::to_string(t.axis);
    const std::string opened[] = {"ballbar"};
    settings["context"] = run_context(setup.config, "ballbar5x", axes, opened);
    if (json& tol = settings["context"]["tolerances"];
        tol.is_object() && !setup.tolerances_file.empty())
      tol["source"] = fmt::format("{} in {} (--tolerances)", tol.value("source", std::string()),
                                  setup.tolerances_file);
    outcome.run_id = store->begin_run({.machine_id = machine_id(setup.config),
                                       .campaign = setup.config.campaign,
                                       .kind = "ballbar5x",
                                       .axis = axes,
                                       .settings_json = settings.dump(),
                                       .software_version = setup.software_version});
    store->add_instrument({.run_id = outcome.run_id,
                           .device = ballbar_device,
                           .driver = std::string(name(Role::ballbar)),
                           .transport = setup.ballbar->describe(),
                           .origin = setup.ballbar_origin.kind,
                           .origin_detail = setup.ballbar_origin.detail});
    open_writer(outcome.run_id);
    running = true;
    event(fmt::format("run {}: five-axis ballbar, {} tests; waiting for the feed-in of {}",
                      outcome.run_id, setup.tests.size(), setup.tests.front().name));
    setup.ballbar->start(
        {.reading = [this](const cal::drivers::Reading& r) { on_reading(r); },
         .state =
             [this](cal::drivers::InstrumentState s, std::string_view why) {
               if (s == cal::drivers::InstrumentState::closed && running)
                 abort(fmt::format("ballbar closed: {}", why));
             },
         .codec_error = codec_errors_as_events(setup.ballbar->describe(),
                                               [this](const std::string& e) { event(e); })});
    tick();
  }

  void on_reading(const cal::drivers::Reading& r) {
    if (!running || r.quantity != cal::drivers::Quantity::length_m) return;
    if (outcome.readings == 0) set_time_origin(outcome.run_id, r.time_ns);
    ++outcome.readings;
    if (!store_reading({.time_ns = r.time_ns,
                        .device = ballbar_device,
                        .quantity = static_cast<std::uint8_t>(r.quantity),
                        .status = static_cast<std::uint8_t>(r.status),
                        .value = r.value}))
      return;
    const bool was = segmenter.measuring();
    segmenter.add(r.value * 1e3);
    if (!was && segmenter.measuring())
      event(fmt::format("test {}: feed-in found, reading its {} stops",
                        setup.tests[segmenter.current_test()].name,
                        setup.tests[segmenter.current_test()].angles_deg.size()));
    if (segmenter.current_test() != told_test) {
      event(fmt::format("test {} read", setup.tests[told_test].name));
      told_test = segmenter.current_test();
    }
    if (segmenter.complete()) boost::asio::post(io, [this] { finish(); });
  }

  void finish() {
    if (done || !running) return;
    running = false;
    try {
      writer->flush();
    } catch (const std::exception& e) {
      return abort(fmt::format("storage failed: {}", e.what()));
    }
    json doc;
    try {
      doc = ballbar5x_result(setup.control, setup.tests, segmenter.stops());
    } catch (const std::exception& e) {
      return abort(e.what());
    }
    try {
      store->add_result({.run_id = outcome.run_id,
                         .standard = "location errors (five-axis ballbar)",
                         .json = doc.dump(),
                         .provenance_json = provenance("acquired", setup.software_version).dump()});
      store->finish_run(outcome.run_id, cal::storage::RunStatus::complete);
    } catch (const std::exception& e) {
      return abort(fmt::format("storage failed: {}", e.what()));
    }
    outcome.result_json = doc.dump();
    outcome.complete = true;
    end();
  }

  std::int64_t current_run() const override { return outcome.run_id; }
  void aborting(const std::string& reason) override { outcome.reason = reason; }
  void aborted(const std::string& reason) override { outcome.reason = reason; }
  void stop_instruments() override { setup.ballbar->stop(); }
};

RotaryBallbarRun::RotaryBallbarRun(boost::asio::io_context& io, RotaryBallbarRunSetup setup)
    : impl_(std::make_unique<Impl>(io, std::move(setup))) {}
RotaryBallbarRun::~RotaryBallbarRun() { impl_->stop_if_running(); }
void RotaryBallbarRun::start() { impl_->start(); }
void RotaryBallbarRun::stop(const std::string& reason) { impl_->abort(reason); }
bool RotaryBallbarRun::finished() const { return impl_->done; }
const RotaryBallbarRunOutcome& RotaryBallbarRun::outcome() const { return impl_->outcome; }

}  // namespace daq
