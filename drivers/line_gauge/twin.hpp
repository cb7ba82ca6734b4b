#pragma once
// SIMULATED line-oriented serial sensor on a pseudo-terminal: by default the length gauge of a
// telescoping ballbar; with a value function, any scalar (a material thermometer). See
// sim/twin.hpp.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "cal/drivers/sim/twin.hpp"

namespace cal::drivers::sim {

// How the twin prints a value v: plain "+000.01000" CR LF (caldaq's own format); the documented
// lines of the gauge presets (docs/drivers.md): Mitutoyo Digimatic "01A+0000.01000" CR, Sylvac
// "+0.01000" CR, Mahr Millimar "0.01000mm" CR LF.
enum class GaugeLineStyle { plain, mitutoyo_digimatic, sylvac, mahr_millimar };
GaugeLineStyle gauge_line_style(std::string_view preset);  // plain for an unknown name

struct GaugeTwinConfig {
  Vec3 pivot_mm{};                 // centre of the table ball, workpiece coordinates
  double zero_length_mm = 100.0;   // the bar length at which the gauge reads 0
  double sample_rate_hz = 1000.0;  // continuous output rate (simulated time)
  bool continuous = true;          // false: one reading per request line
  std::string request = "?";       // the request line (without its CR) in polled mode
  int decimals = 5;                // "+000.12345": 10 nm resolution
  GaugeLineStyle style = GaugeLineStyle::plain;
  // Polled mode: each answer is sent this long (on the loop's time) after its request, with the
  // value measured at the request: a slow adapter or a loaded host, for the tests of a run
  // that must match a late answer to the stop where it was measured.
  std::chrono::nanoseconds answer_delay{0};
  // With answer_delay: the value is measured when the answer is sent, not at the request (a
  // device or adapter that queues requests and measures when it gets to them; a starved twin
  // process behaves so), so a late answer carries a value from after its request.
  bool measure_on_answer = false;
  // What the line carries; empty: the ballbar, length(tool, pivot) - zero_length_mm. Another
  // function makes a serial thermometer on the structure, e.g. the machine temperature.
  std::function<double(const World&)> value;
};

// transport(): "serial PATH 115200 8N1".
class GaugeTwin final : public PtyTwin {
 public:
  GaugeTwin(boost::asio::io_context& io, World& world, Clock clock, GaugeTwinConfig config = {});

  // Starts (from the current simulated time) or stops the continuous output: a bar is only
  // mounted, and a stream only read, for its test.
  void set_streaming(bool on);

 private:
  struct Impl;
  explicit GaugeTwin(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::drivers::sim
