#pragma once
// A circle run's live state for the operator's page without resending its polar trace: the
// page receives the run's state about 6 times a second, and the whole trace (two arcs, a point
// per degree, 15 kB in a ballbar set's test) made nearly all of each message. Each message now
// carries the points added in about the last 0.4 s of messages, with where they start; a
// page that missed more (it connected late, or messages were skipped while one was in flight)
// asks for the whole trace once (GET /api/live/trace) and follows the new points from there.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <nlohmann/json.hpp>

#include "circle_run.hpp"

namespace daq::serve {

class LiveTraceFeed {
 public:
  using Clock = std::chrono::steady_clock;
  // How far back each message repeats points: a page that misses messages for less than this
  // catches up from the messages alone.
  static constexpr auto repeat_for = std::chrono::milliseconds(400);

  // The run's latest live state (on every update of the run, before the next message).
  // A trace that shrank (the next test of a set) or another run starts a new epoch.
  void update(const CircleLive& s, std::int64_t run_id);
  void clear();
  bool empty() const { return !have_; }

  // The run's state for the page (schema caldaq.live-circle.v1) with "trace": {"epoch",
  // "ccw": {"n", "from", "points"}, "cw": {...}}: the arc has n points, and points are those
  // from index `from` to its end. Called once per message sent (it remembers what was sent).
  nlohmann::json page_json(Clock::time_point now);
  // The whole trace: {"epoch", "ccw": [[angle_deg, deviation_um]...], "cw": [...]}.
  nlohmann::json whole() const;

 private:
  struct Sent {
    Clock::time_point at;
    std::size_t ccw = 0, cw = 0;
  };
  CircleLive live_;
  bool have_ = false;
  std::int64_t run_id_ = 0;
  std::uint64_t epoch_ = 0;
  std::deque<Sent> sent_;  // the arcs' sizes at the messages of the last `repeat_for`
};

}  // namespace daq::serve
