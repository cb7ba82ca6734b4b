// The loop's time: steady in real mode, simulated and jumping in simulated mode (see
// cal/drivers/loop_time.hpp).
#include "cal/drivers/loop_time.hpp"

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <cstdio>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

namespace cal::drivers {

namespace asio = boost::asio;

Clock steady_clock_ns() {
  return [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  };
}

// The pending waits, ordered by deadline and then by the order they were made, so that timers
// due at the same simulated instant always fire in the same order.
struct VirtualTime::Queue {
  using Key = std::pair<std::int64_t, std::uint64_t>;  // deadline, sequence
  std::map<Key, Timer::Handler> waits;
  std::uint64_t next_sequence = 0;
};

// Owned by the io_context (an Asio service), so it lives exactly as long as the loop.
struct VirtualTimeService : asio::execution_context::service {
  static asio::execution_context::id id;
  explicit VirtualTimeService(asio::execution_context& ctx) : service(ctx) {}
  void shutdown() override {
    if (time) time->queue_->waits.clear();  // handlers may hold objects that use the loop
  }
  std::unique_ptr<VirtualTime> time;
};
asio::execution_context::id VirtualTimeService::id;

VirtualTime::VirtualTime(asio::io_context& io, std::int64_t start_ns)
    : io_(io), now_ns_(start_ns), queue_(std::make_unique<Queue>()) {}
VirtualTime::~VirtualTime() = default;

VirtualTime& VirtualTime::install(asio::io_context& io, std::int64_t start_ns) {
  auto& service = asio::use_service<VirtualTimeService>(io);
  if (service.time) throw std::logic_error("this event loop already runs on simulated time");
  service.time.reset(new VirtualTime(io, start_ns));
  return *service.time;
}

VirtualTime* VirtualTime::of(asio::execution_context& ctx) {
  if (!asio::has_service<VirtualTimeService>(ctx)) return nullptr;
  return asio::use_service<VirtualTimeService>(ctx).time.get();
}

Clock loop_clock(asio::io_context& io) {
  if (const auto* vt = VirtualTime::of(io)) return [vt] { return vt->now_ns(); };
  return steady_clock_ns();
}

void VirtualTime::pace(double speed) {
  pace_ = speed > 0 ? speed : 0.0;
  pace_origin_ns_ = now_ns_;
  pace_origin_wall_ = std::chrono::steady_clock::now();
}

bool VirtualTime::run_until(const std::function<bool()>& done, std::int64_t until_ns) {
  const auto finished = [&] { return done && done(); };
  // Bytes in flight are waited for until kSettle of wall time passes with no progress; a
  // deadline on the wall clock, not a count of 1 ms polls: a starved process polls less often
  // than that and would forget bytes still on their way (then jump past their answer).
  // Only the counted I/O moving restarts the wait: a wall-clock handler (the page's publish
  // timer, an HTTP request of `daq serve --simulate`) runs every few ms and would otherwise
  // restart it for ever, so bytes a closed reader never takes stopped simulated time for good
  // (every instrument silent after a set-up was applied, while the page kept updating).
  const auto settle_deadline = [] { return std::chrono::steady_clock::now() + kSettle; };
  auto settle_by = settle_deadline();
  auto counted = std::pair(operations_, in_flight_);
  const auto counted_moved = [&] {
    const auto now = std::pair(operations_, in_flight_);
    const bool moved = now != counted;
    counted = now;
    return moved;
  };
  while (!finished()) {
    if (io_.stopped()) io_.restart();
    // Everything runnable now, I/O the kernel has ready included (poll checks it without
    // blocking). The clock stands still meanwhile.
    if (io_.poll_one() > 0) {
      if (counted_moved()) settle_by = settle_deadline();
      continue;
    }
    if (operations_ > 0 || in_flight_ > 0) {
      // Bytes or a connection are on their way through the kernel: wait for them in wall
      // time, then run what they complete, before any simulated time passes.
      if (io_.stopped()) io_.restart();
      if (io_.run_one_for(std::chrono::milliseconds(1)) > 0) {
        if (counted_moved()) settle_by = settle_deadline();
        continue;
      }
      if (std::chrono::steady_clock::now() < settle_by) continue;
      if (operations_ > 0) continue;  // a connection always ends (its own timeout)
      ++stats_.settle_timeouts;
      std::fprintf(stderr,
                   "simulated time: %lld byte(s) counted in flight did not arrive within %lld ms "
                   "of wall time; forgotten, the clock moves on\n",
                   static_cast<long long>(in_flight_), static_cast<long long>(kSettle.count()));
      in_flight_ = 0;
    }
    settle_by = settle_deadline();
    counted = std::pair(operations_, in_flight_);
    auto& waits = queue_->waits;
    if (waits.empty()) {
      // Nothing simulated is pending: only wall-clock work (a socket of a client in another
      // process, a real timer) can make something happen.
      if (io_.stopped()) io_.restart();
      if (io_.run_one_for(std::chrono::milliseconds(10)) == 0 && pace_ == 0.0) return finished();
      continue;
    }
    const std::int64_t next = waits.begin()->first.first;
    if (next > until_ns) {
      now_ns_ = std::max(now_ns_, until_ns);
      return finished();
    }
    if (pace_ > 0.0) {  // not before its time on the wall clock: serve wall-clock work meanwhile
      const auto due =
          pace_origin_wall_ + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                  std::chrono::duration<double, std::nano>(
                                      static_cast<double>(next - pace_origin_ns_) / pace_));
      if (std::chrono::steady_clock::now() < due) {
        if (io_.stopped()) io_.restart();
        io_.run_one_until(due);
        continue;
      }
    }
    if (next > now_ns_) {
      now_ns_ = next;
      ++stats_.jumps;
    }
    // One wait due now, the first made; the next one due at the same instant only once all it
    // set off (a request, its answer through the kernel, the reading) has run. Events of one
    // instant thus always run in the same order (a laser reading and an air sample stamped
    // alike reach the compensation in the same order every time), whatever the kernel's timing.
    auto handler = std::move(waits.begin()->second);
    waits.erase(waits.begin());
    ++stats_.timers;
    asio::post(io_, [h = std::move(handler)] { h(boost::system::error_code()); });
  }
  return true;
}

bool VirtualTime::run_for(std::chrono::nanoseconds simulated, const std::function<bool()>& done) {
  return run_until(done, now_ns_ + simulated.count());
}

// A timer is either an Asio steady_timer (real mode) or waits in its VirtualTime's queue.
struct Timer::Impl {
  asio::io_context& io;
  VirtualTime* time;
  std::optional<asio::steady_timer> steady;
  std::int64_t expiry_ns = 0;
  std::vector<VirtualTime::Queue::Key> pending;  // this timer's waits in the queue

  Impl(asio::io_context& i) : io(i), time(VirtualTime::of(i)) {
    if (!time) steady.emplace(i);
  }

  void cancel() {
    if (steady) {
      steady->cancel();
      return;
    }
    auto& waits = time->queue_->waits;
    for (const auto& key : pending) {
      const auto it = waits.find(key);
      if (it == waits.end()) continue;  // fired already
      asio::post(io, [h = std::move(it->second)] { h(asio::error::operation_aborted); });
      waits.erase(it);
    }
    pending.clear();
  }
};

Timer::Timer(asio::io_context& io) : impl_(std::make_unique<Impl>(io)) {}
Timer::~Timer() { impl_->cancel(); }

void Timer::expires_after(std::chrono::nanoseconds d) {
  if (impl_->steady) {
    impl_->steady->expires_after(d);
    return;
  }
  impl_->cancel();
  impl_->expiry_ns = impl_->time->now_ns() + d.count();
}

void Timer::async_wait(Handler handler) {
  if (impl_->steady) {
    impl_->steady->async_wait(std::move(handler));
    return;
  }
  auto& q = *impl_->time->queue_;
  // Forget the keys of waits that have fired, so that `pending` stays short.
  std::erase_if(impl_->pending, [&](const auto& k) { return !q.waits.contains(k); });
  const VirtualTime::Queue::Key key{impl_->expiry_ns, q.next_sequence++};
  q.waits.emplace(key, std::move(handler));
  impl_->pending.push_back(key);
}

void Timer::cancel() { impl_->cancel(); }

}  // namespace cal::drivers
