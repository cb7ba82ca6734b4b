// The real instruments (transport + codec + state machine) against the simulated twins:
// values in SI equal the simulated truth, the states follow the device, and a dropped
// connection is reconnected with the gap reported.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <cmath>
#include <map>
#include <vector>

#include "ids3010/instrument.hpp"
#include "ids3010/twin.hpp"
#include "line_gauge/instrument.hpp"
#include "line_gauge/twin.hpp"
#include "ptu300/instrument.hpp"
#include "ptu300/twin.hpp"
#include "shdr/instrument.hpp"
#include "shdr/twin.hpp"

namespace {

namespace sim = cal::drivers::sim;
namespace t = cal::drivers::transport;
namespace d = cal::drivers;
using namespace std::chrono_literals;

template <class Pred>
bool run_until(boost::asio::io_context& io, Pred done, std::chrono::milliseconds limit = 4s) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!done() && std::chrono::steady_clock::now() < deadline) {
    io.run_for(5ms);
    io.restart();
  }
  return done();
}

struct Recorder {
  std::vector<d::Reading> readings;
  std::vector<d::InstrumentState> states;
  std::vector<std::string> reasons;
  std::vector<d::Gap> gaps;
  std::size_t codec_errors = 0;
  d::InstrumentEvents events() {
    return {.reading = [this](const d::Reading& r) { readings.push_back(r); },
            .state =
                [this](d::InstrumentState s, std::string_view why) {
                  states.push_back(s);
                  reasons.emplace_back(why);
                },
            .gap = [this](const d::Gap& g) { gaps.push_back(g); },
            .codec_error = [this](const auto&) { ++codec_errors; }};
  }
  std::size_t count(d::Quantity q, d::ReadingStatus s = d::ReadingStatus::ok) const {
    return static_cast<std::size_t>(
        std::count_if(readings.begin(), readings.end(),
                      [&](const auto& r) { return r.quantity == q && r.status == s; }));
  }
  const d::Reading* last(d::Quantity q) const {
    for (auto it = readings.rbegin(); it != readings.rend(); ++it)
      if (it->quantity == q) return &*it;
    return nullptr;
  }
};

sim::World parked_at_100mm() {
  sim::MachineConfig c;
  c.start_mm = {100, 0, 0};
  return sim::World(c, sim::AirConfig{});
}

TEST(Ids3010Instrument, StreamsTheRawDisplacementAndTheEcuAir) {
  boost::asio::io_context io;
  double now_s = 1.0;
  sim::World world = parked_at_100mm();
  sim::IdsTwin twin(io, world, [&] { return now_s; });
  auto ids = d::make_ids3010(io, t::make_tcp(io, {.host = "127.0.0.1", .port = twin.port()}),
                             {.device = 3, .name = "laser", .poll_period = 2ms});
  Recorder rec;
  ids->start(rec.events());
  // The twin reports "measurement starting" for 0.2 s of its time after startMeasurement:
  // with its clock held, no displacement may be emitted yet.
  run_until(
      io, [] { return false; }, 100ms);
  EXPECT_EQ(rec.count(d::Quantity::displacement_m), 0u);
  EXPECT_EQ(ids->state(), d::InstrumentState::configuring);
  now_s = 2.0;
  ASSERT_TRUE(run_until(io, [&] { return rec.count(d::Quantity::displacement_m) >= 20; }));
  EXPECT_EQ(ids->state(), d::InstrumentState::streaming);
  // n x 100 mm with n = 1.000271374 (Edlen at 20 degC, 101325 Pa, 50 %RH; Ciddor within 1e-8).
  const auto* x = rec.last(d::Quantity::displacement_m);
  EXPECT_EQ(x->device, 3);
  EXPECT_EQ(x->channel, 0);
  EXPECT_NEAR(x->value, 0.1000271374, 1e-9);
  ASSERT_TRUE(run_until(io, [&] { return rec.last(d::Quantity::refractive_index) != nullptr; }));
  EXPECT_NEAR(rec.last(d::Quantity::air_pressure_pa)->value, 101325.0, 1e-6);
  EXPECT_NEAR(rec.last(d::Quantity::air_temperature_degc)->value, 20.0, 1e-9);
  EXPECT_NEAR(rec.last(d::Quantity::refractive_index)->value, 1.000271374, 1e-8);
  EXPECT_EQ(rec.codec_errors, 0u);

  // Beam blocked: readings keep coming, flagged, and the state says so.
  twin.set_beam_lost(0, true);
  ASSERT_TRUE(run_until(io, [&] { return ids->state() == d::InstrumentState::signal_lost; }));
  EXPECT_GE(rec.count(d::Quantity::displacement_m, d::ReadingStatus::signal_lost), 1u);
  twin.set_beam_lost(0, false);
  ASSERT_TRUE(run_until(io, [&] { return ids->state() == d::InstrumentState::streaming; }));

  // Cable pulled: reconnect with backoff; the gap is reported when readings resume.
  twin.drop_connections();
  ASSERT_TRUE(run_until(io, [&] { return !rec.gaps.empty(); }));
  EXPECT_GT(rec.gaps[0].end_ns, rec.gaps[0].start_ns);
  EXPECT_NE(rec.gaps[0].reason.find("tcp 127.0.0.1"), std::string::npos) << rec.gaps[0].reason;
  EXPECT_NE(std::find(rec.states.begin(), rec.states.end(), d::InstrumentState::reconnecting),
            rec.states.end());
  ASSERT_TRUE(run_until(io, [&] { return ids->state() == d::InstrumentState::streaming; }));
  ids->stop();
  EXPECT_EQ(ids->state(), d::InstrumentState::closed);
}

TEST(Ptu300Instrument, PollsAt4800SevenEvenOneAndGivesUpOnAVanishedPort) {
  boost::asio::io_context io;
  double now_s = 0.0;
  sim::World world = parked_at_100mm();
  auto twin = std::make_unique<sim::Ptu300Twin>(io, world, [&] { return now_s; });
  auto ptu = d::make_ptu300(
      io, t::make_serial(io, t::parse_serial_settings("4800 7E1", {.device = twin->device_path()})),
      {.name = "PTU300",
       .backoff = {.initial = 10ms, .max = 20ms, .max_attempts = 3},
       .poll_period = 20ms});
  Recorder rec;
  ptu->start(rec.events());
  ASSERT_TRUE(run_until(io, [&] { return rec.count(d::Quantity::air_humidity_pct) >= 3; }));
  // The twin prints P in hPa with 2 decimals, T with 2, RH with 1: 1013.25 hPa = 101325 Pa.
  EXPECT_DOUBLE_EQ(rec.last(d::Quantity::air_pressure_pa)->value, 101325.0);
  EXPECT_DOUBLE_EQ(rec.last(d::Quantity::air_temperature_degc)->value, 20.0);
  EXPECT_DOUBLE_EQ(rec.last(d::Quantity::air_humidity_pct)->value, 50.0);
  EXPECT_EQ(ptu->state(), d::InstrumentState::streaming);

  // Unplugged for good: the pty disappears, three attempts fail, the instrument closes and
  // reports the gap with the first error.
  twin.reset();
  ASSERT_TRUE(run_until(io, [&] { return ptu->state() == d::InstrumentState::closed; }));
  ASSERT_EQ(rec.gaps.size(), 1u);
  EXPECT_NE(rec.reasons.back().find("gave up after 3 attempts"), std::string::npos)
      << rec.reasons.back();
}

TEST(GaugeInstrument, StreamsTheBallbarAndPollsAThermometer) {
  boost::asio::io_context io;
  double now_s = 0.0;
  sim::World world = parked_at_100mm();
  // The bar zeroed at 99.99 mm reads +0.01 mm = 1e-5 m; 1000 samples per simulated second.
  sim::GaugeTwin bar(io, world, [&] { return now_s; }, {.zero_length_mm = 99.99});
  sim::GaugeTwin thermo(
      io, world, [&] { return now_s; },
      {.continuous = false, .request = "?", .decimals = 3, .value = [](const sim::World& w) {
         return w.state().machine_temperature_degc;
       }});
  auto gauge = d::make_gauge(io, t::make_serial(io, {.device = bar.device_path(), .baud = 115200}),
                             {.device = 4});
  auto therm = d::make_gauge(io, t::make_serial(io, {.device = thermo.device_path()}),
                             {.device = 5, .poll_period = 10ms},
                             {.request = "?\r",
                              .unit = cal::drivers::codec::GaugeUnit::degc,
                              .min_si = -40,
                              .max_si = 150});
  Recorder rec;
  gauge->start(rec.events());
  therm->start(rec.events());
  now_s = 0.5;  // samples 0..500
  ASSERT_TRUE(run_until(io, [&] {
    return rec.count(d::Quantity::length_m) >= 501 &&
           rec.count(d::Quantity::material_temperature_degc) >= 2;
  }));
  EXPECT_EQ(rec.count(d::Quantity::length_m), 501u);
  EXPECT_DOUBLE_EQ(rec.last(d::Quantity::length_m)->value, 1e-5);
  EXPECT_DOUBLE_EQ(rec.last(d::Quantity::material_temperature_degc)->value, 20.0);
  EXPECT_EQ(rec.codec_errors, 0u);
}

}  // namespace

namespace {

// The SHDR twin streams the simulated control's commanded position; the real position feed
// instrument (SHDR codec over TCP, "* PING" heartbeats) turns it into machine_position_m.
TEST(PositionFeedInstrument, ShdrAdapterPositionAndHeartbeats) {
  boost::asio::io_context io;
  double now_s = 1.0;
  sim::World world = parked_at_100mm();
  sim::ShdrTwin twin(io, world, [&] { return now_s; }, {.period = 2ms});
  auto feed = d::make_shdr(io, t::make_tcp(io, {.host = "127.0.0.1", .port = twin.port()}),
                           {.device = 4, .name = "position", .poll_period = 20ms},
                           {.keys = {{"Xcom", 0}, {"Ycom", 1}, {"Zcom", 2}}});
  Recorder rec;
  feed->start(rec.events());
  ASSERT_TRUE(run_until(io, [&] {
    return rec.count(d::Quantity::machine_position_m) >= 30 && twin.pings_answered() >= 2;
  }));
  // Parked at X = 100 mm: 0.1 m on channel 0, 0 on Y and Z.
  for (const auto& r : rec.readings) {
    ASSERT_EQ(r.quantity, d::Quantity::machine_position_m);
    EXPECT_EQ(r.device, 4);
    EXPECT_NEAR(r.value, r.channel == 0 ? 0.1 : 0.0, 1e-12) << int(r.channel);
  }
  EXPECT_EQ(rec.codec_errors, 0u);  // the "* PONG" answers are heartbeats, not errors
  EXPECT_EQ(feed->state(), d::InstrumentState::streaming);
  feed->stop();
}

}  // namespace
