// SIMULATED halsampler (see twin.hpp). Line format after LinuxCNC's sampler_usr.c: "overrun"
// alone on a line when samples were lost, then (with -t) the sample number and a space, then
// each pin as "%f " (so every line ends with a space).
#include "halsampler/twin.hpp"

#include <fmt/format.h>

#include "sim/twin_io.hpp"

namespace cal::drivers::sim {

struct HalsamplerTwin::Impl : detail::TcpChannel,
                              std::enable_shared_from_this<HalsamplerTwin::Impl> {
  Impl(boost::asio::io_context& io, World& w, Clock c, HalsamplerTwinConfig cfg)
      : TcpChannel(io, cfg.port), world(w), clock(std::move(c)), config(cfg) {}

  // Every sample that is due (k / rate <= now), in one batch per wake-up.
  void tick() {
    timer.expires_after(std::chrono::milliseconds(2));
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (ec) return;
      self->emit_due();
      self->tick();
    });
  }

  void emit_due() {
    const double now = clock();
    std::string batch;
    while (static_cast<double>(next) / config.sample_rate_hz <= now) {
      world.advance_to(static_cast<double>(next) / config.sample_rate_hz);
      if (config.overrun_every > 0 && next > 0 && next % config.overrun_every == 0) {
        batch += "overrun\n";
        next += config.overrun_lost;
      }
      const auto& p = world.state().tool_mm;
      if (config.tagged) batch += fmt::format("{} ", next);
      batch += fmt::format("{:f} {:f} {:f} \n", p[0], p[1], p[2]);
      ++next;
      ++lines;
    }
    if (!batch.empty() && server->has_clients()) server->broadcast(batch);
  }

  World& world;
  Clock clock;
  HalsamplerTwinConfig config;
  std::uint64_t next = 0, lines = 0;
};

HalsamplerTwin::HalsamplerTwin(boost::asio::io_context& io, World& world, Clock clock,
                               HalsamplerTwinConfig config)
    : HalsamplerTwin(std::make_shared<Impl>(io, world, std::move(clock), config)) {}
HalsamplerTwin::HalsamplerTwin(std::shared_ptr<Impl> impl) : TcpTwin(impl), impl_(std::move(impl)) {
  impl_->next = static_cast<std::uint64_t>(impl_->clock() * impl_->config.sample_rate_hz);
  impl_->server->start({});
  impl_->tick();
}
std::uint64_t HalsamplerTwin::lines_sent() const { return impl_->lines; }

}  // namespace cal::drivers::sim
