// The loop's time (cal/drivers/loop_time.hpp): simulated time that jumps from event to event
// where a VirtualTime is installed, the steady clock where none is (real mode).
#include "cal/drivers/loop_time.hpp"

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "cal/drivers/transport/transport.hpp"
#include "line_gauge/twin.hpp"
#include "ptu300/instrument.hpp"
#include "ptu300/twin.hpp"

namespace {

namespace d = cal::drivers;
namespace sim = cal::drivers::sim;
namespace t = cal::drivers::transport;
using namespace std::chrono_literals;

std::int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

sim::World quiet_world() {
  sim::AirConfig air;
  air.temperature_degc = {.start = 20.0};
  air.pressure_pa = {.start = 101325.0};
  air.humidity_pct = {.start = 50.0};
  return sim::World(sim::MachineConfig{}, air);
}

TEST(VirtualTime, JumpsToEachDeadlineInOrderAndFiresTiesInTheOrderTheyWereMade) {
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io, 1'000);
  d::Timer late(io), early(io), tie_a(io), tie_b(io), cancelled(io);
  std::vector<std::pair<char, std::int64_t>> fired;  // which, at what simulated time
  const auto record = [&](char which) {
    return [&fired, &time, which](const boost::system::error_code& ec) {
      fired.emplace_back(ec ? static_cast<char>(which - 32) : which, time.now_ns());
    };
  };
  late.expires_after(3600s);  // an hour: no wall-clock test could wait for it
  late.async_wait(record('l'));
  early.expires_after(2ms);
  early.async_wait(record('e'));
  tie_b.expires_after(5ms);
  tie_b.async_wait(record('b'));
  tie_a.expires_after(5ms);
  tie_a.async_wait(record('a'));
  cancelled.expires_after(1ms);
  cancelled.async_wait(record('c'));
  cancelled.cancel();  // completes with operation_aborted (upper case), at once

  EXPECT_FALSE(time.run_until({}, 4'000'000'000'000));  // nothing left after `late`
  const std::vector<std::pair<char, std::int64_t>> expected{{'C', 1'000},
                                                            {'e', 1'000 + 2'000'000},
                                                            {'b', 1'000 + 5'000'000},
                                                            {'a', 1'000 + 5'000'000},
                                                            {'l', 1'000 + 3'600'000'000'000}};
  EXPECT_EQ(fired, expected);
  EXPECT_EQ(time.stats().jumps, 3u);  // 2 ms, 5 ms, 1 h
}

TEST(VirtualTime, StopsAtTheLimitAndWhenDone) {
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io);
  d::Timer tick(io);
  int ticks = 0;
  std::function<void(const boost::system::error_code&)> again =
      [&](const boost::system::error_code& ec) {
        if (ec) return;
        ++ticks;
        tick.expires_after(10ms);
        tick.async_wait(again);
      };
  tick.expires_after(10ms);
  tick.async_wait(again);
  EXPECT_FALSE(time.run_for(95ms));  // no `done`: it runs to the limit
  EXPECT_EQ(ticks, 9);
  EXPECT_EQ(time.now_ns(), 95'000'000);
  EXPECT_TRUE(time.run_for(1h, [&] { return ticks == 20; }));
  EXPECT_EQ(time.now_ns(), 200'000'000);  // the 20th tick, not an hour later
  EXPECT_THROW(d::VirtualTime::install(io), std::logic_error);
}

// Paced (daq serve --simulate): simulated time never runs ahead of speed x wall time, and still
// moves from deadline to deadline (a lower bound on the wall time only: load may add to it).
TEST(VirtualTime, PacedItWaitsForTheWallClockAndStillLandsOnTheDeadlines) {
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io);
  time.pace(10.0);
  d::Timer timer(io);
  std::int64_t fired_at = -1;
  timer.expires_after(500ms);  // 50 ms of wall time at 10x
  timer.async_wait([&](const boost::system::error_code& ec) {
    if (!ec) fired_at = time.now_ns();
  });
  const std::int64_t start = steady_now_ns();
  EXPECT_TRUE(time.run_for(10s, [&] { return fired_at >= 0; }));
  EXPECT_GE(steady_now_ns() - start, 50'000'000);
  EXPECT_EQ(fired_at, 500'000'000);
}

// Bytes counted in flight whose reader has gone (a monitor closed when `daq serve --simulate`
// applied a set-up) are forgotten after kSettle of wall time even while wall-clock work keeps
// running (the page's publish timer every few ms). Before, every such handler restarted the
// wait: simulated time stood still for good and every instrument fell silent. The wall-clock
// ticker stops by itself after 30 s, so the old code ends too, but with the timer fired only
// after the ticker had stopped.
TEST(VirtualTime, BytesNeverReadAreForgottenWhileWallClockWorkGoesOn) {
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io);
  time.pace(10.0);
  time.bytes_written(5);  // never read
  boost::asio::steady_timer ticker(io);
  const std::int64_t start = steady_now_ns();
  bool ticking = true;
  std::function<void()> tick = [&] {
    if (steady_now_ns() - start > 30'000'000'000) return void(ticking = false);
    ticker.expires_after(5ms);
    ticker.async_wait([&](const boost::system::error_code& ec) {
      if (!ec) tick();
    });
  };
  tick();
  d::Timer timer(io);
  bool fired_while_ticking = false, fired = false;
  timer.expires_after(100ms);
  timer.async_wait([&](const boost::system::error_code& ec) {
    fired = !ec;
    fired_while_ticking = ticking;
  });
  EXPECT_TRUE(time.run_for(10s, [&] { return fired; }));
  ticker.cancel();
  EXPECT_TRUE(fired_while_ticking);
  EXPECT_EQ(time.stats().settle_timeouts, 1u);
}

// A driver that closes its port while its twin's answer is on the way (`daq serve --simulate`
// closes every monitor when a set-up is applied, and a run closes those it opens itself) is
// not waited for: the answer nobody will read no longer holds simulated time for kSettle (2 s
// of wall time) before it is forgotten. Before, the answer stayed counted in flight: one
// settle timeout, and the next timer fired 2 s of wall time later.
TEST(VirtualTime, BytesToADriverThatClosedAreNotWaitedFor) {
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io);
  sim::World world = quiet_world();
  sim::GaugeTwin twin(
      io, world, [&time] { return time.now_s(); },
      {.continuous = false, .request = "?", .value = [](const sim::World&) { return 0.5; }});
  auto port =
      t::make_serial(io, t::parse_serial_settings("115200 8N1", {.device = twin.device_path()}));
  std::string received;
  bool opened = false;
  port->open({.opened = [&] { opened = true; },
              .data =
                  [&](std::span<const std::byte> b) {
                    received.append(reinterpret_cast<const char*>(b.data()), b.size());
                  }});
  ASSERT_TRUE(time.run_for(1s, [&] { return opened; }));
  const auto ask = [&] {
    const std::string request = "?\r";
    port->write(std::as_bytes(std::span(request)));
  };
  // One answer read as usual: the accounting of a reader that stays is unchanged.
  ask();
  ASSERT_TRUE(time.run_for(1s, [&] { return received.find('\n') != std::string::npos; }));
  // Asked again, and closed as soon as the twin has answered (before the answer is read).
  const auto sent = twin.lines_sent();
  ask();
  const std::int64_t give_up = steady_now_ns() + 10'000'000'000;
  while (twin.lines_sent() == sent && steady_now_ns() < give_up) io.run_one_for(1ms);
  ASSERT_EQ(twin.lines_sent(), sent + 1);
  port->close();
  d::Timer timer(io);
  bool fired = false;
  timer.expires_after(100ms);
  timer.async_wait([&](const boost::system::error_code& ec) { fired = !ec; });
  const std::int64_t start = steady_now_ns();
  EXPECT_TRUE(time.run_for(1s, [&] { return fired; }));
  EXPECT_EQ(time.stats().settle_timeouts, 0u);
  EXPECT_LT(steady_now_ns() - start, 1'000'000'000);  // not kSettle (2 s)
}

// The bytes each driver sends to its twin count as that driver's: two drivers send 6 and 2
// bytes, the first's twin is unplugged before it reads them; the second's twin answers. Only the
// first's 6 bytes are forgotten with its twin: the clock then runs on at once. Counted for all
// drivers together, the 6 bytes stayed in flight and the loop waited kSettle (2 s of wall time)
// for them (1 settle timeout).
TEST(VirtualTime, BytesADriverSentToATwinThatWentAreThatDriversOnly) {
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io);
  sim::World world = quiet_world();
  const auto polled = [] {
    return sim::GaugeTwinConfig{
        .continuous = false, .request = "?", .value = [](const sim::World&) { return 0.5; }};
  };
  sim::GaugeTwin gone(
      io, world, [&time] { return time.now_s(); }, polled());
  sim::GaugeTwin stays(
      io, world, [&time] { return time.now_s(); }, polled());
  const auto open = [&](const sim::GaugeTwin& twin, std::string& received, int& opened) {
    auto port =
        t::make_serial(io, t::parse_serial_settings("115200 8N1", {.device = twin.device_path()}));
    port->open({.opened = [&opened] { ++opened; },
                .data =
                    [&received](std::span<const std::byte> b) {
                      received.append(reinterpret_cast<const char*>(b.data()), b.size());
                    },
                .error = [](const t::Error&) {}});
    return port;
  };
  std::string to_gone, to_stays;
  int opened = 0;
  auto port_gone = open(gone, to_gone, opened);
  auto port_stays = open(stays, to_stays, opened);
  ASSERT_TRUE(time.run_for(1s, [&] { return opened == 2; }));
  const auto send = [](t::Transport& port, const std::string& request) {
    port.write(std::as_bytes(std::span(request)));
  };
  send(*port_gone, "?\r?\r?\r");  // 6 bytes, never read: the twin goes at once
  gone.unplug();
  send(*port_stays, "?\r");  // 2 bytes, read and answered
  d::Timer timer(io);
  bool fired = false;
  timer.expires_after(100ms);
  timer.async_wait([&](const boost::system::error_code& ec) { fired = !ec; });
  const std::int64_t start = steady_now_ns();
  EXPECT_TRUE(time.run_for(1s, [&] { return fired; }));
  EXPECT_NE(to_stays.find('\n'), std::string::npos) << "the twin that stays answered";
  EXPECT_EQ(time.stats().settle_timeouts, 0u);
  EXPECT_LT(steady_now_ns() - start, 1'000'000'000);  // not kSettle (2 s)
}

TEST(VirtualTime, AnInstrumentPollsItsTwinOnSimulatedTimeAndStampsItsReadingsWithIt) {
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io);
  sim::World world = quiet_world();
  sim::Ptu300Twin twin(io, world, [&time] { return time.now_s(); });
  // A poll every 250 ms of simulated time; the instrument's clock is the loop's by default.
  auto ptu = d::make_ptu300(
      io, t::make_serial(io, t::parse_serial_settings("4800 7E1", {.device = twin.device_path()})),
      {.poll_period = 250ms});
  std::vector<std::int64_t> stamps;
  ptu->start({.reading = [&](const d::Reading& r) {
    if (r.quantity == d::Quantity::air_pressure_pa) stamps.push_back(r.time_ns);
  }});
  // Five minutes of polling through a pseudo-terminal, in as long as the CPU needs.
  ASSERT_TRUE(time.run_for(300s, [&] { return stamps.size() >= 1'200; }));
  ptu->stop();
  // The twin answers in the simulated instant it is asked: every reading is stamped with a
  // poll's time exactly, 250 ms apart, whatever the machine's load did to the wall clock.
  ASSERT_EQ(stamps.size(), 1'200u);
  for (std::size_t i = 1; i < stamps.size(); ++i)
    ASSERT_EQ(stamps[i] - stamps[i - 1], 250'000'000) << i;
  EXPECT_LT(stamps.back(), 300'000'000'000);
  EXPECT_EQ(time.stats().settle_timeouts, 0u);  // no byte was ever lost on the way
}

TEST(LoopTime, InRealModeTimersWaitOnTheWallClockAndInstrumentsStampSteadyTime) {
  boost::asio::io_context io;  // no VirtualTime: real mode, as with hardware
  EXPECT_EQ(d::VirtualTime::of(io), nullptr);
  const auto clock = d::loop_clock(io);
  const std::int64_t before = steady_now_ns();
  const std::int64_t read = clock();
  EXPECT_GE(read, before);
  EXPECT_LE(read, steady_now_ns());

  // A timer waits at least its duration of steady time (a lower bound only: a loaded machine
  // may wake it later).
  d::Timer timer(io);
  std::int64_t fired_ns = 0;
  // Read before arming: the deadline is 30 ms after expires_after() (read after it, the clock
  // was 19 us later in a loaded scripts/test, and the timer "fired early" by that much).
  const std::int64_t armed_ns = steady_now_ns();
  timer.expires_after(30ms);
  timer.async_wait([&](const boost::system::error_code& ec) {
    if (!ec) fired_ns = steady_now_ns();
  });
  io.run();
  EXPECT_GE(fired_ns - armed_ns, 30'000'000);

  // An instrument with no clock given reads the steady clock: its readings' times lie between
  // the steady times before and after, not on any simulated time line (the twin's own clock
  // stands at 0 s).
  io.restart();
  sim::World world = quiet_world();
  sim::Ptu300Twin twin(io, world, [] { return 0.0; });
  auto ptu = d::make_ptu300(
      io, t::make_serial(io, t::parse_serial_settings("4800 7E1", {.device = twin.device_path()})),
      {.poll_period = 20ms});
  std::vector<std::int64_t> stamps;
  ptu->start({.reading = [&](const d::Reading& r) { stamps.push_back(r.time_ns); }});
  const std::int64_t start_ns = steady_now_ns();
  for (int i = 0; i < 500 && stamps.size() < 6; ++i) io.run_for(10ms);
  const std::int64_t end_ns = steady_now_ns();
  ptu->stop();
  ASSERT_GE(stamps.size(), 6u);
  for (const auto s : stamps) {
    EXPECT_GE(s, start_ns);
    EXPECT_LE(s, end_ns);
  }
}

}  // namespace
