#pragma once
// SIMULATED MTConnect SHDR adapter (a machine position feed) on a loopback TCP port, streaming
// the simulated control's commanded position, or its actual position with the chatter of a
// real adapter at rest (see sim/twin.hpp).
#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "cal/drivers/sim/twin.hpp"

namespace cal::drivers::sim {

struct ShdrTwinConfig {
  std::uint16_t port = 0;  // 0: an ephemeral port on 127.0.0.1
  // Wall-clock period at which the control's commanded position (mm, 4 decimals) is looked
  // at. As an adapter does, a line goes out only when a value changed, with only the items
  // that changed ("2024-01-01T12:00:00.123456Z|Xcom|12.5000"); a new client first gets every
  // item. So the feed is silent while the machine dwells.
  std::chrono::milliseconds period{5};
  std::int64_t pong_timeout_ms = 10000;  // the answer to "* PING": "* PONG 10000"
  std::array<std::string, 3> keys{"Xcom", "Ycom", "Zcom"};  // the data items of X, Y, Z
  // What the adapter reports: the commanded position (silent while parked), or the actual one
  // (the axes after their servo loops), as the GF Agie HPM600U's adapter does.
  enum class Position { commanded, actual };
  Position position = Position::commanded;
  int decimals = 4;  // printed with this many decimals (the GF Agie log: 5, i.e. 10 nm)
  // A real adapter's actual position chatters at rest: in the GF Agie HPM600U log of
  // ../shared/realdata an axis standing still moves by one count (10 nm) and back every
  // 0.14-1 s (e.g. 19.5072, 19.50719, 19.5072). When dither_mm > 0, each axis's printed value is
  // offset by dither_mm and back at intervals drawn uniformly from chatter_interval_s (the
  // twin's time, seeded), in motion as at rest. 0: no chatter.
  double dither_mm = 0.0;
  std::array<double, 2> chatter_interval_s{0.14, 1.0};
  std::uint64_t seed = 1;
  // What else a real adapter does on the wire (the GF Agie HPM600U log, the Handtmann 482
  // telnet capture in ../shared/realdata), each off by default:
  // bursts: every item on a line of its own, several lines at one time (the log's lines 1-30);
  // a new client first gets the control's conditions ("|servo|Normal||||"), its execution
  // state and a THREE_SPACE path_pos before the positions, and each change comes with an
  // execution line.
  bool bursts = false;
  // split_lines: each look's text goes out in two writes, the second at the next look, so the
  // agent holds a partial line in between (TCP keeps no line boundaries).
  bool split_lines = false;
  // While the twin's time lies in [from, to), the positions are "UNAVAILABLE" (the adapter
  // lost its control); -1: never.
  std::array<double, 2> unavailable_s{-1.0, -1.0};
};

// Sends the simulated control's commanded (or actual) position to every connected agent on
// change and answers its heartbeats ("* PING" -> "* PONG <ms>"), as an MTConnect adapter does;
// with the config's bursts, split lines and UNAVAILABLE spans, as a chattering real one does.
class ShdrTwin final : public TcpTwin {
 public:
  ShdrTwin(boost::asio::io_context& io, World& world, Clock clock, ShdrTwinConfig config = {});
  std::uint64_t lines_sent() const;
  std::uint64_t chatter_flips() const;  // times an axis's dither offset changed
  std::uint64_t pings_answered() const;

 private:
  struct Impl;
  explicit ShdrTwin(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::drivers::sim
