#pragma once
// The time an event loop runs on: one seam for every timer and clock of a session (instrument
// polls, reconnection back-off, silence watchdogs, transports' timeouts, the twins' pacing, the
// runs' ticks).
//
// Real mode (hardware): nothing is installed; Timer is an Asio steady_timer and loop_clock()
// the steady clock, exactly as before.
//
// Simulated mode: VirtualTime::install(io) puts the io_context on simulated time. Timers made on
// it wait in simulated time, loop_clock() reads it, and VirtualTime::run_until() drives the
// loop: it runs whatever is runnable, and when nothing is (no handler ready, no byte or
// connection in flight between the twins and the drivers), it JUMPS to the next timer's
// deadline. A simulated session then runs as fast as the CPU allows and gives the same
// readings with the same timestamps on a quiet or a loaded machine (docs/benchmarks.md, "Test
// suite and demo"). SIMULATED, and named so.
//
// Boost.Asio stays out of this header (it is widely included): io_context and error_code are
// only declared here.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>

namespace boost::asio {
class io_context;
class execution_context;
}  // namespace boost::asio
namespace boost::system {
class error_code;
}

namespace cal::drivers {

// Monotonic nanoseconds. The default is the steady clock; replay substitutes the recorded
// time of the bytes being delivered, so replayed readings carry their original timestamps; a
// simulated session reads its VirtualTime.
using Clock = std::function<std::int64_t()>;
Clock steady_clock_ns();

class VirtualTime {
 public:
  // Puts `io` on simulated time starting at start_ns. Install it before making any Timer,
  // transport, twin or instrument on `io` (they look it up when made). Throws
  // std::logic_error when `io` already has one.
  static VirtualTime& install(boost::asio::io_context& io, std::int64_t start_ns = 0);
  // The simulated time of `ctx`; nullptr in real mode.
  static VirtualTime* of(boost::asio::execution_context& ctx);

  // Paced (speed > 0): simulated time runs no faster than `speed` times the wall clock, for a
  // simulated shop a person watches (`daq serve --simulate`); it still only moves from event
  // to event, so the order of events stays that of the unpaced run. While it waits for the
  // wall clock the loop serves wall-clock work (HTTP clients, steady timers). 0: unpaced.
  void pace(double speed);

  std::int64_t now_ns() const { return now_ns_; }
  double now_s() const { return static_cast<double>(now_ns_) * 1e-9; }

  // Runs the loop until done() is true (checked after every handler) or simulated time would
  // pass until_ns (it then stops at until_ns). Returns done(). Also returns when nothing can
  // happen any more (no timer pending, no I/O outstanding).
  bool run_until(const std::function<bool()>& done, std::int64_t until_ns);
  bool run_for(std::chrono::nanoseconds simulated, const std::function<bool()>& done = {});

  // I/O accounting, kept by the transports and the twins' channels: bytes written into a
  // channel whose reader is in this process and not read yet, and operations that complete
  // at once in simulated terms but asynchronously in the kernel (a connection being made). The
  // clock does not jump while either is non-zero: a pty's bytes are moved by a kernel worker,
  // so they may not be readable yet when the loop next looks.
  void bytes_written(std::size_t n) { in_flight_ += static_cast<std::int64_t>(n); }
  void bytes_read(std::size_t n) { in_flight_ -= static_cast<std::int64_t>(n); }
  void begin_operation() { ++operations_; }
  void end_operation() { --operations_; }

  struct Stats {
    std::uint64_t jumps = 0;   // times the clock moved forward to a deadline
    std::uint64_t timers = 0;  // timer handlers fired
    // Times bytes counted in flight never arrived within kSettle (their reader had gone, e.g.
    // a twin writing to a closed port): forgotten, then the clock moved on.
    std::uint64_t settle_timeouts = 0;
  };
  const Stats& stats() const { return stats_; }
  // How long (wall time, with nothing arriving) the loop waits for bytes counted in flight
  // before it forgets them. Long enough for a process starved on a loaded 2-core machine;
  // paid in full only when a reader has gone (a twin writing to a closed port).
  static constexpr std::chrono::milliseconds kSettle{2000};

  VirtualTime(const VirtualTime&) = delete;
  VirtualTime& operator=(const VirtualTime&) = delete;
  ~VirtualTime();

 private:
  friend class Timer;
  struct Queue;
  explicit VirtualTime(boost::asio::io_context& io, std::int64_t start_ns);
  friend struct VirtualTimeService;

  boost::asio::io_context& io_;
  std::int64_t now_ns_;
  std::int64_t in_flight_ = 0;
  double pace_ = 0.0;
  std::int64_t pace_origin_ns_ = 0;
  std::chrono::steady_clock::time_point pace_origin_wall_{};
  int operations_ = 0;
  std::unique_ptr<Queue> queue_;
  Stats stats_;
};

// The loop's clock: its VirtualTime where one is installed, else the steady clock.
Clock loop_clock(boost::asio::io_context& io);

// A waitable timer on the loop's time, with the part of Asio's steady_timer interface the
// project uses: expires_after() cancels a pending wait; cancel() and destruction complete it
// with operation_aborted; a handler runs from the loop, never from inside these calls.
class Timer {
 public:
  using Handler = std::function<void(const boost::system::error_code&)>;
  explicit Timer(boost::asio::io_context& io);
  ~Timer();
  Timer(const Timer&) = delete;
  Timer& operator=(const Timer&) = delete;

  void expires_after(std::chrono::nanoseconds d);
  void async_wait(Handler handler);
  void cancel();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cal::drivers
