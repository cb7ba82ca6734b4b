// Ballbar run (see circle_run.hpp).
#include "circle_run.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "cal/storage/store.hpp"
#include "cal/storage/writer.hpp"
#include "circle_output.hpp"

namespace daq {

using nlohmann::json;

struct CircleRun::Impl {
  boost::asio::io_context& io;
  CircleRunSetup setup;
  cal::daq::BallbarSegmenter segmenter;
  std::optional<cal::storage::Store> store;
  std::unique_ptr<cal::storage::BatchWriter> writer;
  CircleRunOutcome outcome;
  bool running = false, done = false;

  Impl(boost::asio::io_context& i, CircleRunSetup s)
      : io(i), setup(std::move(s)), segmenter(setup.program) {}

  void event(const std::string& e) {
    if (setup.on_event) setup.on_event(e);
  }

  void start() {
    store.emplace(setup.database);
    const auto& c = setup.config;
    std::int64_t machine = 0;
    if (auto m = store->machine_by_name(c.machine_name))
      machine = m->id;
    else
      machine = store->add_machine({.name = c.machine_name, .description = c.machine_description});
    const auto& p = setup.program;
    const json settings{{"radius_mm", p.radius_mm},
                        {"feed_mm_per_min", p.feed_mm_per_min},
                        {"sample_rate_hz", p.sample_rate_hz},
                        {"feed_in_mm", p.feed_in_mm},
                        {"dwell_s", p.dwell_s},
                        {"overshoot_deg", p.overshoot_deg},
                        {"start_deg", p.start_deg},
                        {"plane", setup.plane}};
    outcome.run_id = store->begin_run({.machine_id = machine,
                                       .campaign = c.campaign,
                                       .kind = "circle",
                                       .axis = setup.plane,
                                       .settings_json = settings.dump(),
                                       .capture_path = setup.capture_path,
                                       .software_version = setup.software_version});
    store->add_instrument({.run_id = outcome.run_id,
                           .device = 3,
                           .driver = "ballbar",
                           .transport = setup.ballbar->describe()});
    writer = std::make_unique<cal::storage::BatchWriter>(setup.database, outcome.run_id);
    running = true;
    setup.ballbar->start({.reading = [this](const cal::drivers::Reading& r) { on_reading(r); },
                          .state =
                              [this](cal::drivers::InstrumentState s, std::string_view why) {
                                if (s == cal::drivers::InstrumentState::closed && running)
                                  abort(fmt::format("ballbar closed: {}", why));
                              }});
    event(fmt::format("run {}: ballbar circle R {} mm at {} mm/min, waiting for the feed-in",
                      outcome.run_id, p.radius_mm, p.feed_mm_per_min));
  }

  void on_reading(const cal::drivers::Reading& r) {
    if (!running || r.quantity != cal::drivers::Quantity::length_m) return;
    ++outcome.readings;
    writer->push({.time_ns = r.time_ns,
                  .device = 3,
                  .quantity = static_cast<std::uint8_t>(r.quantity),
                  .status = static_cast<std::uint8_t>(r.status),
                  .value = r.value});
    const bool had = segmenter.feed_in_end().has_value();
    segmenter.add(r.value * 1e3);
    if (!had && segmenter.feed_in_end()) event("feed-in found: the circle starts after the dwell");
    if (segmenter.complete()) boost::asio::post(io, [this] { finish(); });
  }

  void finish() {
    if (done) return;
    running = false;
    writer->flush();
    try {
      const auto traces = segmenter.traces();
      outcome.result = cal::circle::analyse(
          {.radius_mm = setup.program.radius_mm, .feed_mm_per_min = setup.program.feed_mm_per_min},
          traces);
    } catch (const std::exception& e) {
      return abort(e.what());
    }
    store->add_result({.run_id = outcome.run_id,
                       .standard = "ISO 230-4:2005",
                       .json = circle_json(*outcome.result, setup.program.radius_mm, setup.plane,
                                           setup.program.feed_mm_per_min)
                                   .dump()});
    store->finish_run(outcome.run_id, cal::storage::RunStatus::complete);
    outcome.complete = true;
    end();
  }

  void abort(const std::string& reason) {
    if (done) return;
    running = false;
    outcome.reason = reason;
    if (writer) writer->flush();
    if (store) store->finish_run(outcome.run_id, cal::storage::RunStatus::aborted, reason);
    end();
  }

  void end() {
    done = true;
    setup.ballbar->stop();
    writer.reset();
  }
};

CircleRun::CircleRun(boost::asio::io_context& io, CircleRunSetup setup)
    : impl_(std::make_unique<Impl>(io, std::move(setup))) {}
CircleRun::~CircleRun() {
  if (!impl_->done && impl_->running) impl_->abort("stopped");
}
void CircleRun::start() { impl_->start(); }
void CircleRun::stop(const std::string& reason) { impl_->abort(reason); }
bool CircleRun::finished() const { return impl_->done; }
const CircleRunOutcome& CircleRun::outcome() const { return impl_->outcome; }

}  // namespace daq
