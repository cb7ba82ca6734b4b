// SIMULATED PTU300 (see twin.hpp): commands end with CR, LF or CR LF; answers and RUN-mode
// lines end with CR LF. The informational commands ?, ??, VERS, ERRS and UNIT answer in the
// shape of the Vaisala 300-series guides (docs/drivers.md); their texts are the twin's own. Output
// in the default FORM of the user's guide ("P= 1033.7 hPa T= 22.2 'C RH= 38.3 %RH"), with one more
// decimal on P and T than that example, as a FORM such as 4.2 P would print.
#include "ptu300/twin.hpp"

#include <fmt/format.h>

#include <cstdio>

#include "sim/twin_io.hpp"

namespace cal::drivers::sim {

struct Ptu300Twin::Impl : detail::PtyChannel, std::enable_shared_from_this<Ptu300Twin::Impl> {
  Impl(boost::asio::io_context& io, World& w, Clock c, Ptu300TwinConfig cfg)
      : PtyChannel(io),
        world(w),
        clock(std::move(c)),
        config(cfg),
        running(cfg.start_in_run_mode) {}

  std::string reading() {
    const double now = clock();
    world.advance_to(now);
    const AirSample a = world.air().sample(now);
    // UNIT N (non-metric) prints the temperature in 'F, as a unit left so would.
    const double t = metric ? a.temperature_degc : a.temperature_degc * 9.0 / 5.0 + 32.0;
    return fmt::format("P= {:7.2f} hPa T= {:6.2f} '{} RH= {:5.1f} %RH\r\n", a.pressure_pa / 100.0,
                       t, metric ? 'C' : 'F', a.humidity_pct);
  }

  static constexpr const char* version = "PTU300 / 5.10 (simulated)";

  // ? and ??: the settings, in the layout of the 300-series guides' example.
  std::string information() const {
    return fmt::format(
        "{}\r\nSerial number  : SIMULATED\r\nOutput format  : (default)\r\n"
        "Start mode     : {}\r\nBaud P D S     : 4800 E 7 1\r\nOutput interval: {} s\r\n"
        "Address        : 0\r\nEcho           : OFF\r\nOutput units   : {}\r\n",
        version, running ? "RUN" : "STOP", config.interval_s, metric ? "metric" : "non metric");
  }

  // UNIT, UNIT M, UNIT N: the output units (metric: 'C; non metric: 'F).
  std::string units(const std::string& cmd) {
    const std::string arg = cmd.size() > 5 ? cmd.substr(5) : "";
    if (arg == "M" || arg == "N")
      metric = arg == "M";
    else if (!arg.empty())
      return "Unknown unit\r\n";
    return fmt::format("Output units   : {}\r\n", metric ? "metric" : "non metric");
  }

  void on_command(const std::string& raw) {
    std::string cmd;
    for (char ch : raw)
      cmd.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(ch))));
    auto self = shared_from_this();
    if (cmd == "SEND" || cmd.rfind("SEND ", 0) == 0) return pty.send(reading(), self);
    if (cmd == "R") {
      running = true;
      return tick();
    }
    if (cmd == "S") {
      running = false;
      return;
    }
    if (cmd.rfind("SMODE", 0) == 0) {
      const std::string mode = cmd.size() > 6 ? cmd.substr(6) : "";
      if (!mode.empty()) running = mode == "RUN";
      return pty.send(
          fmt::format("Output mode   : {}\r\n", mode.empty() ? (running ? "RUN" : "STOP") : mode),
          self);
    }
    if (cmd.rfind("INTV", 0) == 0) {
      int n = 0;
      char unit[8] = "S";
      if (std::sscanf(cmd.c_str(), "INTV %d %7s", &n, unit) >= 1 && n >= 0 && n <= 255) {
        const double scale = std::string(unit) == "MIN" ? 60.0
                             : std::string(unit) == "H" ? 3600.0
                                                        : 1.0;
        config.interval_s = std::max(n * scale, 0.0);
      }
      return pty.send(fmt::format("Output intrv. : {} s\r\n", config.interval_s), self);
    }
    if (cmd.rfind("FORM", 0) == 0) return pty.send("OK\r\n", self);  // formats are not simulated
    if (cmd == "?" || cmd == "??") return pty.send(information(), self);
    if (cmd == "VERS") return pty.send(fmt::format("{}\r\n", version), self);
    if (cmd == "ERRS") return pty.send("No errors\r\n", self);
    if (cmd == "UNIT" || cmd.rfind("UNIT ", 0) == 0) return pty.send(units(cmd), self);
    if (!cmd.empty()) pty.send("Unknown command\r\n", self);
  }

  // RUN mode: a reading every INTV (simulated time), scheduled on the wall clock through the
  // clock's speed, measured rather than assumed.
  void tick() {
    if (!running || !pty.master.is_open()) return;
    const double now = clock();
    if (now >= next_output_s) {
      pty.send(reading(), shared_from_this());
      next_output_s = now + std::max(config.interval_s, 0.01);
    }
    if (simulated_time)  // the clock is the loop's: sleep until the next output is due
      timer.expires_after(std::chrono::nanoseconds(
          static_cast<std::int64_t>(std::max(next_output_s - clock(), 0.0) * 1e9)));
    else
      timer.expires_after(std::chrono::milliseconds(5));
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (!ec) self->tick();
    });
  }

  World& world;
  Clock clock;
  Ptu300TwinConfig config;
  bool running = false;
  bool metric = true;  // UNIT M (the factory setting) or UNIT N
  double next_output_s = 0.0;
};

Ptu300Twin::Ptu300Twin(boost::asio::io_context& io, World& world, Clock clock,
                       Ptu300TwinConfig config)
    : Ptu300Twin(std::make_shared<Impl>(io, world, std::move(clock), config)) {}
Ptu300Twin::Ptu300Twin(std::shared_ptr<Impl> impl)
    : PtyTwin(impl, "4800 7E1"), impl_(std::move(impl)) {
  detail::read_commands(impl_);
  impl_->tick();
}

}  // namespace cal::drivers::sim
