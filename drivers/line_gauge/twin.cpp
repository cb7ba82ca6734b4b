// SIMULATED line gauge (see twin.hpp): "+000.12345\r\n" per sample (mm from the gauge's zero),
// continuously at the sample rate (in simulated time) or one per request line.
#include "line_gauge/twin.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "sim/twin_io.hpp"

namespace cal::drivers::sim {

struct GaugeTwin::Impl : detail::PtyChannel, std::enable_shared_from_this<GaugeTwin::Impl> {
  Impl(boost::asio::io_context& io, World& w, Clock c, GaugeTwinConfig cfg)
      : PtyChannel(io), world(w), clock(std::move(c)), config(std::move(cfg)) {}

  std::string line_at(double t) {
    world.advance_to(t);
    const double value =
        config.value ? config.value(world)
                     : ballbar_length_mm(world.state(), config.pivot_mm) - config.zero_length_mm;
    return fmt::format("{:+0{}.{}f}\r\n", value, config.decimals + 5, config.decimals);
  }

  void on_command(const std::string& cmd) {
    if (!config.continuous && cmd == config.request) pty.send(line_at(clock()), shared_from_this());
  }

  // Emits every sample that is due (k / rate <= now) in one batch per wake-up, so the stream
  // keeps its exact sample times whatever the timer's jitter.
  void tick() {
    if (!config.continuous || !pty.master.is_open()) return;
    const double now = clock();
    std::string batch;
    std::uint64_t count = 0;
    while (static_cast<double>(next_sample) / config.sample_rate_hz <= now) {
      batch += line_at(static_cast<double>(next_sample) / config.sample_rate_hz);
      ++next_sample;
      ++count;
    }
    if (count > 0) pty.send(std::move(batch), shared_from_this(), count);
    // Simulated time: a batch per 10 ms (10 samples at 1 kHz; at 60x, a live shop's 2 ms of
    // wall time hold 120).
    timer.expires_after(std::chrono::milliseconds(simulated_time ? 10 : 2));
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (!ec) self->tick();
    });
  }

  World& world;
  Clock clock;
  GaugeTwinConfig config;
  std::uint64_t next_sample = 0;
};

GaugeTwin::GaugeTwin(boost::asio::io_context& io, World& world, Clock clock, GaugeTwinConfig config)
    : GaugeTwin(std::make_shared<Impl>(io, world, std::move(clock), std::move(config))) {}
GaugeTwin::GaugeTwin(std::shared_ptr<Impl> impl)
    : PtyTwin(impl, "115200 8N1"), impl_(std::move(impl)) {
  if (!(impl_->config.sample_rate_hz > 0.0))
    throw std::invalid_argument("gauge twin: sample rate must be > 0");
  detail::read_commands(impl_);
  impl_->tick();
}
void GaugeTwin::set_streaming(bool on) {
  impl_->timer.cancel();
  impl_->config.continuous = on;
  if (!on) return;
  impl_->next_sample =
      static_cast<std::uint64_t>(std::ceil(impl_->clock() * impl_->config.sample_rate_hz));
  impl_->tick();
}

}  // namespace cal::drivers::sim
