// SIMULATED MTConnect SHDR adapter (see twin.hpp): position lines to every client on a timer,
// "* PONG" to "* PING".
#include "shdr/twin.hpp"

#include <fmt/format.h>

#include "sim/twin_io.hpp"

namespace cal::drivers::sim {

struct ShdrTwin::Impl : std::enable_shared_from_this<ShdrTwin::Impl> {
  Impl(boost::asio::io_context& io, World& w, Clock c, ShdrTwinConfig cfg)
      : server(std::make_shared<detail::LineServer>(io, cfg.port)),
        timer(io),
        world(w),
        clock(std::move(c)),
        config(cfg) {}

  void on_line(const detail::LineServer::ClientPtr& client, const std::string& line) {
    if (!line.starts_with("* PING")) return;
    ++pongs;
    server->send(client, fmt::format("* PONG {}\n", config.pong_timeout_ms));
  }

  void tick() {
    timer.expires_after(config.period);
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (ec) return;
      if (self->server->has_clients()) {
        self->world.advance_to(self->clock());
        const auto& c = self->world.state().commanded_mm;
        const auto& k = self->config.keys;
        self->server->broadcast(
            fmt::format("|{}|{:.4f}|{}|{:.4f}|{}|{:.4f}\n", k[0], c[0], k[1], c[1], k[2], c[2]));
        self->sent += self->server->clients();
      }
      self->tick();
    });
  }

  std::shared_ptr<detail::LineServer> server;
  boost::asio::steady_timer timer;
  World& world;
  Clock clock;
  ShdrTwinConfig config;
  std::uint64_t sent = 0, pongs = 0;
};

ShdrTwin::ShdrTwin(boost::asio::io_context& io, World& world, Clock clock, ShdrTwinConfig config)
    : impl_(std::make_shared<Impl>(io, world, std::move(clock), config)) {
  impl_->server->start(
      [impl = impl_.get()](const detail::LineServer::ClientPtr& client, const std::string& line) {
        impl->on_line(client, line);
      });
  impl_->tick();
}
ShdrTwin::~ShdrTwin() {
  impl_->timer.cancel();
  impl_->server->close();
}
std::uint16_t ShdrTwin::port() const { return impl_->server->port(); }
std::string ShdrTwin::transport() const { return fmt::format("tcp 127.0.0.1:{}", port()); }
void ShdrTwin::unplug() { impl_->server->drop_clients(); }
std::uint64_t ShdrTwin::lines_sent() const { return impl_->sent; }
std::uint64_t ShdrTwin::pings_answered() const { return impl_->pongs; }

}  // namespace cal::drivers::sim
