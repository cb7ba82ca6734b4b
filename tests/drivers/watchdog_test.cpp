// The silence watchdog's re-arm (drivers/src/instrument_core.hpp, silence_wait): a lost
// connection is seen when the silence reaches the timeout, not up to twice that. The timer is
// driven here on a simulated time line (no wall clock): the watchdog fires, asks silence_wait,
// and fires again after the wait it returns, as InstrumentCore::arm_watchdog does.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>

#include "src/instrument_core.hpp"

namespace {

using namespace std::chrono_literals;
using cal::drivers::detail::silence_wait;
using ns = std::chrono::nanoseconds;

TEST(SilenceWatchdog, WaitsOnlyTheTimeRemaining) {
  // SHDR with "* PONG 20": the timeout is 2 x 20 ms = 40 ms.
  EXPECT_EQ(silence_wait(40ms, 0ms), ns(40ms));
  EXPECT_EQ(silence_wait(40ms, 30ms), ns(10ms));      // 10 ms more, not a whole 40 ms more
  EXPECT_EQ(silence_wait(40ms, 40ms), std::nullopt);  // silent for the timeout: lost
  EXPECT_EQ(silence_wait(40ms, 41ms), std::nullopt);
  EXPECT_EQ(silence_wait(40ms, -5ms), ns(40ms));  // a clock stepped back: the whole timeout
}

// Armed at 0 with the timeout, the device's last bytes at `last`: when is the loss seen?
ns detected_at(ns timeout, ns last) {
  ns now = timeout;  // the first check
  for (int fires = 0; fires < 100; ++fires) {
    const auto wait = silence_wait(timeout, now - last);
    if (!wait) return now;
    now += *wait;
  }
  return ns::max();
}

TEST(SilenceWatchdog, ALostConnectionIsSeenAtTheTimeoutOfSilence) {
  // The PONG period p = 20 ms: silence beyond 2p = 40 ms is a lost connection (MTConnect
  // agent). Bytes last came at 1, 20 or 39 ms after the arm: the loss is seen 40 ms later
  // (41, 60, 79 ms). Re-arming for the whole timeout instead saw it at 80 ms in all three
  // cases: up to 2 x 2p, 4p after the last bytes.
  for (const ns last : {ns(1ms), ns(20ms), ns(39ms)}) {
    SCOPED_TRACE(last.count());
    EXPECT_EQ(detected_at(40ms, last), last + ns(40ms));
  }
  EXPECT_EQ(detected_at(40ms, 0ms), ns(40ms));  // silent since the arm: the first check
}

}  // namespace
