// The real instruments (transport + codec + state machine) against the simulated twins:
// values in SI equal the simulated truth, the states follow the device, and a dropped
// connection is reconnected with the gap reported.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/write.hpp>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <span>
#include <vector>

#include "ids3010/instrument.hpp"
#include "ids3010/twin.hpp"
#include "line_gauge/instrument.hpp"
#include "line_gauge/twin.hpp"
#include "ptu300/instrument.hpp"
#include "ptu300/twin.hpp"
#include "shdr/instrument.hpp"
#include "shdr/twin.hpp"
#include "temper/instrument.hpp"
#include "temper/twin.hpp"

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
  std::vector<d::DeviceMessage> messages;
  d::InstrumentEvents events() {
    return {.reading = [this](const d::Reading& r) { readings.push_back(r); },
            .state =
                [this](d::InstrumentState s, std::string_view why) {
                  states.push_back(s);
                  reasons.emplace_back(why);
                },
            .gap = [this](const d::Gap& g) { gaps.push_back(g); },
            .codec_error = [this](const auto&) { ++codec_errors; },
            .message = [this](const d::DeviceMessage& m) { messages.push_back(m); }};
  }
  bool failed_with(std::string_view text) const {
    return std::any_of(reasons.begin(), reasons.end(),
                       [&](const auto& r) { return r.find(text) != std::string::npos; });
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

// What an IDS3010 on `twin` told until it failed with `reason` (a test failure if it did not).
Recorder ids_until_failed(boost::asio::io_context& io, sim::IdsTwin& twin,
                          const d::Ids3010Options& options, std::string_view reason) {
  auto ids = d::make_ids3010(io, t::make_tcp(io, {.host = "127.0.0.1", .port = twin.port()}),
                             {.name = "laser", .poll_period = 2ms}, options);
  Recorder rec;
  ids->start(rec.events());
  EXPECT_TRUE(run_until(io, [&] { return rec.failed_with(reason); })) << reason;
  ids->stop();
  return rec;
}

// The device's own number and text (errorNumberToString) reach the user: in the reason that
// ends the connection, and as messages, warnings told apart from errors.
TEST(Ids3010Instrument, RefusalsAndWarningsCarryTheDevicesNumberAndText) {
  boost::asio::io_context io;
  sim::World world = parked_at_100mm();
  {  // startMeasurement refused three times (its text known from the first refusal)
    sim::IdsTwin twin(io, world, [] { return 1.0; }, {.refuse_start = true});
    const Recorder rec =
        ids_until_failed(io, twin, {.read_environment = false}, "startMeasurement refused");
    EXPECT_TRUE(
        rec.failed_with("startMeasurement refused 3 times (error 4: laser not ready "
                        "(simulated))"))
        << rec.reasons.back();
    const auto m = std::find_if(rec.messages.begin(), rec.messages.end(), [](const auto& x) {
      return x.code == sim::IdsTwin::error_start_refused;
    });
    ASSERT_NE(m, rec.messages.end());
    EXPECT_EQ(m->severity, d::DeviceMessage::Severity::error);
    EXPECT_NE(m->text.find("startMeasurement: laser not ready (simulated)"), std::string::npos)
        << m->text;
  }
  {  // the ECU refuses at its first answer: the text is asked of the device before failing
    sim::IdsTwin twin(io, world, [] { return 1.0; }, {.refuse_ecu_enable = true});
    const Recorder rec = ids_until_failed(io, twin, {}, "ECU interface not enabled");
    EXPECT_TRUE(
        rec.failed_with("ECU interface not enabled (com.attocube.ecu.enable) (error 5: "
                        "ECU interface refused (simulated))"))
        << rec.reasons.back();
    ASSERT_EQ(rec.messages.size(), 2u);  // the API generation (info), then the refusal
    EXPECT_EQ(rec.messages[1].severity, d::DeviceMessage::Severity::error);
    EXPECT_EQ(rec.messages[1].code, sim::IdsTwin::error_ecu_refused);
  }
  {  // a blocked beam: a warning with the device's number and text, readings flagged
    double now_s = 1.0;
    sim::IdsTwin twin(io, world, [&] { return now_s; });
    auto ids = d::make_ids3010(io, t::make_tcp(io, {.host = "127.0.0.1", .port = twin.port()}),
                               {.name = "laser", .poll_period = 2ms}, {.read_environment = false});
    Recorder rec;
    ids->start(rec.events());
    ASSERT_TRUE(run_until(io, [&] { return ids->state() == d::InstrumentState::configuring; }));
    run_until(
        io, [] { return false; }, 50ms);  // startMeasurement sent at the twin's 1.0 s
    now_s = 2.0;                          // past the twin's "measurement starting"
    ASSERT_TRUE(run_until(io, [&] { return rec.count(d::Quantity::displacement_m) >= 3; }));
    twin.set_beam_lost(0, true);
    const auto warned = [&] {
      return std::any_of(rec.messages.begin(), rec.messages.end(),
                         [](const auto& m) { return m.code == sim::IdsTwin::error_beam_lost; });
    };
    ASSERT_TRUE(run_until(io, warned));
    ids->stop();
    const auto m = std::find_if(rec.messages.begin(), rec.messages.end(), [](const auto& x) {
      return x.code == sim::IdsTwin::error_beam_lost;
    });
    EXPECT_EQ(m->severity, d::DeviceMessage::Severity::warning);
    EXPECT_NE(m->text.find("signal lost on an axis (simulated)"), std::string::npos) << m->text;
    EXPECT_FALSE(rec.failed_with("signal lost"));  // a warning does not end the connection
  }
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

TEST(GaugeInstrument, HandsAChunksReadingsOverInOneCallToABatchConsumer) {
  // The same ballbar stream with events.readings set: every reading arrives through it, in
  // order, with its device, after the state change to streaming; none through `reading`.
  boost::asio::io_context io;
  double now_s = 0.0;
  sim::World world = parked_at_100mm();
  sim::GaugeTwin bar(io, world, [&] { return now_s; }, {.zero_length_mm = 99.99});
  auto gauge = d::make_gauge(io, t::make_serial(io, {.device = bar.device_path(), .baud = 115200}),
                             {.device = 4});
  Recorder rec;
  std::size_t calls = 0, single = 0;
  bool streaming_first = true;
  auto events = rec.events();
  events.reading = [&](const d::Reading&) { ++single; };
  events.readings = [&](std::span<const d::Reading> rs) {
    ++calls;
    EXPECT_FALSE(rs.empty());
    streaming_first = streaming_first && !rec.states.empty() &&
                      rec.states.back() == d::InstrumentState::streaming;
    rec.readings.insert(rec.readings.end(), rs.begin(), rs.end());
  };
  gauge->start(events);
  now_s = 0.5;  // samples 0..500
  ASSERT_TRUE(run_until(io, [&] { return rec.count(d::Quantity::length_m) >= 501; }));
  EXPECT_EQ(rec.count(d::Quantity::length_m), 501u);
  EXPECT_EQ(single, 0u);
  EXPECT_GE(calls, 1u);
  EXPECT_LE(calls, 501u);
  EXPECT_TRUE(streaming_first);
  for (const auto& r : rec.readings) {
    EXPECT_EQ(r.device, 4);
    EXPECT_DOUBLE_EQ(r.value, 1e-5);
  }
  EXPECT_EQ(rec.codec_errors, 0u);
}

}  // namespace

namespace {

// The SHDR twin streams the simulated control's commanded position; the real position feed
// instrument (SHDR codec over TCP, "* PING" heartbeats) turns it into machine_position_m.
TEST(PositionFeedInstrument, ShdrAdapterPositionAndHeartbeats) {
  // The twin, as an adapter, sends every item to a new agent, then only what changes: parked,
  // it is silent. The instrument pings once on connecting; the twin's "* PONG 40" makes it ping
  // every 40 ms from then on (cppagent's connector does the same).
  boost::asio::io_context io;
  double now_s = 1.0;
  sim::World world = parked_at_100mm();
  sim::ShdrTwin twin(io, world, [&] { return now_s; }, {.period = 2ms, .pong_timeout_ms = 40});
  auto feed = d::make_shdr(io, t::make_tcp(io, {.host = "127.0.0.1", .port = twin.port()}),
                           {.device = 4, .name = "position", .poll_period = 20ms},
                           {.keys = {{"Xcom", 0}, {"Ycom", 1}, {"Zcom", 2}}});
  Recorder rec;
  std::vector<std::string> messages;
  auto events = rec.events();
  events.message = [&](const d::DeviceMessage& m) { messages.push_back(m.text); };
  feed->start(events);
  ASSERT_TRUE(run_until(io, [&] { return twin.pings_answered() >= 4; }));
  // Parked at X = 100 mm: one line with the three items, 0.1 m on channel 0, 0 on Y and Z.
  ASSERT_EQ(rec.count(d::Quantity::machine_position_m), 3u);
  for (const auto& r : rec.readings) {
    ASSERT_EQ(r.quantity, d::Quantity::machine_position_m);
    EXPECT_EQ(r.device, 4);
    EXPECT_NEAR(r.value, r.channel == 0 ? 0.1 : 0.0, 1e-12) << int(r.channel);
  }
  EXPECT_EQ(rec.codec_errors, 0u);  // the "* PONG" answers are heartbeats, not errors
  EXPECT_EQ(feed->state(), d::InstrumentState::streaming);
  ASSERT_FALSE(messages.empty());
  EXPECT_EQ(messages.front(), "adapter answered * PONG 40: heartbeat every 40 ms");
  // Silent for much longer than the 3 s default watchdog? No: the PONG's heartbeats keep the
  // connection alive (measured here in pings, each answered), and no reconnection happened.
  EXPECT_EQ(std::count(rec.states.begin(), rec.states.end(), d::InstrumentState::reconnecting), 0);
  feed->stop();
}

TEST(PositionFeedInstrument, ShdrWithoutPongIsNeverTimedOutForSilence) {
  // A loopback adapter that replays the Okuma OSP-P300 recording (../shared/realdata) in three
  // parts with quiet periods between them and never answers "* PING" (the agent then uses no
  // heartbeat). The quiet periods are 10 times the instrument's silence timeout (30 ms here,
  // 3 s by default: the logic does not depend on the length, and the suite does not wait 30 s
  // of wall time): no reconnection, and every frame of the recording arrives.
  std::ifstream in(CALDAQ_REALDATA_DIR "/shdr_okuma_osp_p300.txt", std::ios::binary);
  ASSERT_TRUE(in) << CALDAQ_REALDATA_DIR << ": the real recordings are expected in "
                  << "../shared/realdata beside the checkout";
  const std::string okuma((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> parts;
  for (std::size_t at = 0, k = 1; k <= 3; ++k) {
    const std::size_t end = k == 3 ? okuma.size() : okuma.find('\n', okuma.size() * k / 3) + 1;
    parts.push_back(okuma.substr(at, end - at));
    at = end;
  }
  boost::asio::io_context io;
  boost::asio::ip::tcp::acceptor acceptor(io, {boost::asio::ip::address_v4::loopback(), 0});
  boost::asio::ip::tcp::socket peer(io);
  acceptor.async_accept(peer, [](const boost::system::error_code&) {});
  auto feed = d::make_shdr(
      io, t::make_tcp(io, {.host = "127.0.0.1", .port = acceptor.local_endpoint().port()}),
      {.device = 4, .name = "position", .silence_timeout = 30ms},
      {.keys = {{"X1actw", 0}, {"YI1actw", 1}, {"Z1actw", 2}}});
  Recorder rec;
  feed->start(rec.events());
  ASSERT_TRUE(run_until(io, [&] { return peer.is_open(); }));
  for (const auto& part : parts) {
    boost::asio::write(peer, boost::asio::buffer(part));
    run_until(
        io, [] { return false; }, 300ms);  // quiet: 10 x the silence timeout
  }
  EXPECT_EQ(rec.count(d::Quantity::machine_position_m), 4905u);  // the file's 3,989 frames
  EXPECT_EQ(rec.codec_errors, 0u);
  EXPECT_EQ(std::count(rec.states.begin(), rec.states.end(), d::InstrumentState::reconnecting), 0);
  EXPECT_EQ(feed->state(), d::InstrumentState::streaming);
  feed->stop();
}

TEST(PositionFeedInstrument, ShdrSilenceBeyondTwiceThePongPeriodDropsTheConnection) {
  // The adapter answers "* PONG 20", then stops answering anything: after 2 x 20 ms of
  // silence the connection counts as lost (reconnecting), as in the agent.
  boost::asio::io_context io;
  boost::asio::ip::tcp::acceptor acceptor(io, {boost::asio::ip::address_v4::loopback(), 0});
  boost::asio::ip::tcp::socket peer(io);
  boost::asio::streambuf in;
  acceptor.async_accept(peer, [&](const boost::system::error_code& ec) {
    if (ec) return;
    boost::asio::async_read_until(
        peer, in, '\n', [&](const boost::system::error_code& e, std::size_t) {
          if (!e)
            boost::asio::write(peer, boost::asio::buffer(std::string("* PONG 20\n|Xact|1\n")));
        });
  });
  auto feed = d::make_shdr(
      io, t::make_tcp(io, {.host = "127.0.0.1", .port = acceptor.local_endpoint().port()}),
      {.device = 4, .name = "position", .backoff = {.initial = 10s}}, {});
  Recorder rec;
  feed->start(rec.events());
  ASSERT_TRUE(run_until(
      io,
      [&] {
        return std::count(rec.states.begin(), rec.states.end(), d::InstrumentState::reconnecting) >
               0;
      },
      2s));
  EXPECT_EQ(rec.reasons.back(), "no data for 40 ms");
  feed->stop();
}

// The TEMPer twin speaks hidapi's way in this process (USB-HID cannot be offered here).
struct TemperBench {
  boost::asio::io_context io;
  sim::World world = [] {
    sim::MachineConfig m;
    m.thermal.start_degc = 19.5;  // the probe on the structure
    sim::AirConfig a;
    a.temperature_degc.start = 21.25;  // the stick in the air
    return sim::World(m, a);
  }();
  double now_s = 1.0;
  std::unique_ptr<sim::TemperTwin> twin;
  Recorder rec;
  std::vector<std::string> messages;
  std::unique_ptr<d::Instrument> start(std::string firmware, d::TemperOptions options,
                                       int half_firmware_answers = 0) {
    twin = std::make_unique<sim::TemperTwin>(
        io, world, [this] { return now_s; },
        sim::TemperTwinConfig{.firmware = firmware,
                              .half_firmware_answers = half_firmware_answers});
    auto inst = d::make_temper(
        io, twin->connect(io),
        {.device = 2, .name = "table", .backoff = {.max_attempts = 1}, .poll_period = 5ms},
        std::move(options));
    auto events = rec.events();
    events.message = [this](const d::DeviceMessage& m) { messages.push_back(m.text); };
    inst->start(events);
    return inst;
  }
};

TEST(TemperInstrument, ATemper2GivesItsTwoSensorsAsTwoChannelsFoundFromItsFirmware) {
  // Family and sensors from the firmware string (TEMPer2_V3.7: gold, stick and probe): the
  // stick reads the air (21.25 degC), the probe the structure (19.5 degC), each on its channel,
  // never one interleaved series.
  TemperBench b;
  auto t = b.start("TEMPer2_V3.7    ", {.family = std::nullopt});
  ASSERT_TRUE(run_until(b.io, [&] { return b.rec.readings.size() >= 10; }));
  for (const auto& r : b.rec.readings) {
    ASSERT_EQ(r.quantity, d::Quantity::material_temperature_degc);
    EXPECT_DOUBLE_EQ(r.value, r.channel == 0 ? 21.25 : 19.5) << int(r.channel);
  }
  const auto on = [&](int c) {
    return std::count_if(b.rec.readings.begin(), b.rec.readings.end(),
                         [&](const auto& r) { return r.channel == c; });
  };
  EXPECT_GE(on(0), 4);
  EXPECT_GE(on(1), 4);
  ASSERT_FALSE(b.messages.empty());
  EXPECT_EQ(b.messages.front(),
            "firmware 'TEMPer2_V3.7    ': gold family, sensors 0 (the stick), 1 (the probe)");
  t->stop();
}

TEST(TemperInstrument, TheConfigurationChoosesTheChannelsAndAMissingOneIsRefused) {
  {  // the probe only: no reading of the stick
    TemperBench b;
    auto t = b.start("TEMPer2_V3.7    ", {.family = std::nullopt, .channels = {1}});
    ASSERT_TRUE(run_until(b.io, [&] { return b.rec.readings.size() >= 5; }));
    for (const auto& r : b.rec.readings) EXPECT_EQ(r.channel, 1);
    t->stop();
  }
  {  // a probe-only TEMPer1F_V3.9 asked for the stick: refused, saying what it has
    TemperBench b;
    auto t = b.start("TEMPer1F_V3.9   ", {.family = std::nullopt, .channels = {0}});
    ASSERT_TRUE(run_until(b.io, [&] { return t->state() == d::InstrumentState::closed; }));
    EXPECT_TRUE(b.rec.readings.empty());
    EXPECT_NE(b.rec.reasons.back().find("TEMPer 'TEMPer1F_V3.9   ' has no channel 0; its sensors: "
                                        "1 (the probe)"),
              std::string::npos)
        << b.rec.reasons.back();
  }
}

TEST(TemperInstrument, AnUnknownFirmwareIsRefusedNamingItNeverGuessed) {
  TemperBench b;
  auto t = b.start("TEMPerGold_V9.9 ", {.family = std::nullopt});
  ASSERT_TRUE(run_until(b.io, [&] { return t->state() == d::InstrumentState::closed; }));
  EXPECT_TRUE(b.rec.readings.empty());
  EXPECT_NE(b.rec.reasons.back().find("TEMPer firmware 'TEMPerGold_V9.9 ' is not in the "
                                      "detection table (docs/drivers.md); if you know its report "
                                      "layout, set family = "),
            std::string::npos)
      << b.rec.reasons.back();
}

TEST(TemperInstrument, AHalfAnsweredFirmwareQueryIsAskedAgainAndTheProbeRead) {
  // A TEMPer1F on TEMPerX_V3.3 answers the first query with its second half only ("V3.3    ",
  // urwen/temper PR #16's usbmon trace); asked again, it answers whole. The probe (id 01) is
  // then read, without waiting for the silence watchdog to reconnect.
  TemperBench b;
  auto t = b.start("TEMPerX_V3.3    ", {.family = std::nullopt, .channels = {1}}, 1);
  ASSERT_TRUE(run_until(b.io, [&] { return b.rec.readings.size() >= 3; }))
      << (b.rec.reasons.empty() ? "" : b.rec.reasons.back());
  std::size_t probe = 0;
  for (const auto& r : b.rec.readings) {
    if (r.quantity != d::Quantity::material_temperature_degc) continue;  // the stick's humidity
    EXPECT_EQ(r.channel, 1);
    EXPECT_DOUBLE_EQ(r.value, 19.5);  // the probe on the structure
    ++probe;
  }
  EXPECT_GE(probe, 1u);
  EXPECT_EQ(b.twin->firmware_queries(), 2);
  EXPECT_EQ(std::count(b.rec.states.begin(), b.rec.states.end(), d::InstrumentState::reconnecting),
            0);
  ASSERT_GE(b.messages.size(), 2u);
  EXPECT_EQ(b.messages[0],
            "TEMPer firmware query 1 of 10: 'V3.3    ' (1 report of the 2, the second half only); "
            "asking again");
  EXPECT_EQ(b.messages[1].rfind("firmware 'TEMPerX_V3.3    ': temperx family", 0), 0u)
      << b.messages[1];
  t->stop();
}

TEST(TemperInstrument, TheFirmwareQueryIsAskedABoundedNumberOfTimes) {
  // A stick that never answers whole: asked firmware_tries times, then the connection ends
  // naming what came (never a model guessed from half a string).
  TemperBench b;
  auto t = b.start("TEMPerX_V3.3    ",
                   {.family = std::nullopt, .firmware_tries = 3, .firmware_quiet = 10ms}, 1000);
  ASSERT_TRUE(run_until(b.io, [&] { return t->state() == d::InstrumentState::closed; }));
  EXPECT_TRUE(b.rec.readings.empty());
  EXPECT_EQ(b.twin->firmware_queries(), 3);
  EXPECT_NE(b.rec.reasons.back().find("TEMPer: no whole answer to the firmware query (01 86 ff "
                                      "01) in 3 tries; the last: 'V3.3    ' (1 report of the 2, "
                                      "the second half only)"),
            std::string::npos)
      << b.rec.reasons.back();
}

}  // namespace
