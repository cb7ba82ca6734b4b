#pragma once
// SIMULATED Attocube IDS3010: JSON-RPC 2.0 on a loopback TCP port, answering from the
// simulated World (see sim/twin.hpp). Boost.Asio stays out of this header.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>

#include "cal/drivers/sim/twin.hpp"
#include "ids3010/codec.hpp"

namespace cal::drivers::sim {

struct IdsTwinConfig {
  std::uint16_t port = 0;  // 0: an ephemeral port on 127.0.0.1 (see IdsTwin::port())
  // Which machine axis each of the three interferometer axes measures (-1: none, reads 0),
  // and the tool position (mm along that axis) where its displacement was reset to zero.
  std::array<int, 3> machine_axis{0, -1, -1};
  std::array<double, 3> datum_mm{0.0, 0.0, 0.0};
  // Where each axis's reflector sits relative to the tool reference point (mm), when set: the
  // axis then reads the displacement of that point, with the machine's angular errors acting
  // on the offset (two axes with reflectors apart measure an angle, as angular optics do).
  // Unset: the tool tip of the machine's geometry.
  std::array<std::optional<Vec3>, 3> reflector_mm{};
  double starting_s = 0.2;  // "measurement starting" lasts this long after startMeasurement
  bool ecu_connected = true;
  // startMeasurement answers error_start_refused instead of starting (a laser not ready).
  bool refuse_start = false;
  // com.attocube.ecu.enable answers error_ecu_refused (a stand-in for a refusing ECU).
  bool refuse_ecu_enable = false;
  // The API generation it speaks (com.attocube.ids before firmware 1.9.1, com.attocube.sen
  // from it); methods of the other one are unknown to it (JSON-RPC -32601), as on the device.
  codec::IdsApi api = codec::IdsApi::ids;
};

class IdsTwin final : public TcpTwin {
 public:
  IdsTwin(boost::asio::io_context& io, World& world, Clock clock, IdsTwinConfig config = {});

  // Simulates a blocked beam on one axis: its displacement requests answer with an error
  // code (the twin's stand-in for the device's signal-lost warning) until restored.
  void set_beam_lost(int axis, bool lost);
  // The optics set up for another test (the operator moved them between tests): which machine
  // axis each interferometer axis measures and where its reflector sits (IdsTwinConfig).
  void set_optics(const std::array<int, 3>& machine_axis,
                  const std::array<std::optional<Vec3>, 3>& reflector_mm);
  // Drops every client connection (as a power cycle or a pulled cable would).
  void drop_connections() { unplug(); }
  std::uint64_t requests_served() const;

  // The twin's own numbers (the device's are not published); errorNumberToString gives their
  // texts, marked simulated.
  static constexpr std::int64_t error_not_measuring = 1;  // twin's code: not in measurement
  static constexpr std::int64_t error_beam_lost = 2;      // twin's code: signal lost on axis
  static constexpr std::int64_t error_ecu_disabled = 3;   // twin's code: ECU not enabled
  static constexpr std::int64_t error_start_refused = 4;  // twin's code: start refused
  static constexpr std::int64_t error_ecu_refused = 5;    // twin's code: ECU enable refused

 private:
  struct Impl;
  explicit IdsTwin(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::drivers::sim
