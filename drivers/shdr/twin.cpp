// SIMULATED MTConnect SHDR adapter (see twin.hpp): position lines on change, a full dump to a
// new client, "* PONG" to "* PING"; bursts, split lines and UNAVAILABLE when configured.
#include "shdr/twin.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <random>
#include <utility>
#include <vector>

#include "sim/twin_io.hpp"

namespace cal::drivers::sim {

struct ShdrTwin::Impl : detail::TcpChannel, std::enable_shared_from_this<ShdrTwin::Impl> {
  Impl(boost::asio::io_context& io, World& w, Clock c, ShdrTwinConfig cfg)
      : TcpChannel(io, cfg.port), world(w), clock(std::move(c)), config(cfg) {}

  void on_line(const detail::LineServer::ClientPtr& client, const std::string& line) {
    if (!line.starts_with("* PING")) return;
    ++pongs;
    // An adapter writes whole lines: the rest of a split line goes out before the PONG.
    if (!held.empty()) server->broadcast(std::exchange(held, {}));
    server->send(client, fmt::format("* PONG {}\n", config.pong_timeout_ms));
  }

  // The items as the adapter prints them now: a line of those that differ from `last` (all
  // of them when `all`), or "" when none does; with bursts, a line per item and more lines.
  std::string line(bool all) {
    const double now = clock();
    world.advance_to(now);
    const auto& state = world.state();
    const auto& p =
        config.position == ShdrTwinConfig::Position::actual ? state.axes_mm : state.commanded_mm;
    chatter(now);
    const bool unavailable = now >= config.unavailable_s[0] && now < config.unavailable_s[1];
    std::vector<std::string> items;
    for (std::size_t a = 0; a < 3; ++a) {
      std::string value =
          unavailable ? std::string("UNAVAILABLE")
                      : fmt::format("{:.{}f}", p[a] + (dithered[a] ? config.dither_mm : 0.0),
                                    config.decimals);
      if (all || value != last[a]) items.push_back(fmt::format("|{}|{}", config.keys[a], value));
      last[a] = std::move(value);
    }
    if (items.empty()) return {};
    const std::string stamp = timestamp();
    if (!config.bursts) {
      std::string out = stamp;
      for (const auto& i : items) out += i;
      return out + "\n";
    }
    std::string out;
    if (all) {  // a new agent: the control's state first, as the GF Agie adapter sends it
      for (const char* condition : {"system", "servo", "comms", "logic", "motion"})
        out += fmt::format("{}|{}|Normal||||\n", stamp, condition);
      out += fmt::format("{}|avail|AVAILABLE\n{}|path_pos|{:.10f} {:.10f} {:.10f}\n", stamp, stamp,
                         p[0], p[1], p[2]);
    }
    out += fmt::format("{}|execution|{}\n", stamp, unavailable ? "UNAVAILABLE" : "ACTIVE");
    for (const auto& i : items) out += stamp + i + "\n";
    return out;
  }

  // What goes out at one look: with split_lines, the rest of the last look's text and then
  // the head of this one (cut inside its first line), the rest held for the next look.
  std::string next_write(std::string text) {
    if (!config.split_lines) return text;
    std::string out = std::exchange(held, {});
    if (!text.empty()) {
      const std::size_t cut = std::max<std::size_t>(1, text.find('\n') / 2);
      out += text.substr(0, cut);
      held = text.substr(cut);
    }
    return out;
  }

  // Flips each axis's dither offset when its next chatter time has come (at most one flip per
  // look, as an adapter's scan sees one value).
  void chatter(double now_s) {
    if (!(config.dither_mm > 0.0)) return;
    std::uniform_real_distribution<double> interval(config.chatter_interval_s[0],
                                                    config.chatter_interval_s[1]);
    for (std::size_t a = 0; a < 3; ++a) {
      if (next_flip_s[a] < 0.0) next_flip_s[a] = now_s + interval(random);
      if (now_s < next_flip_s[a]) continue;
      dithered[a] = !dithered[a];
      ++flips;
      next_flip_s[a] = now_s + interval(random);
    }
  }

  static std::string timestamp() {
    const auto now = std::chrono::system_clock::now();
    const auto us = std::chrono::duration_cast<std::chrono::microseconds>(now.time_since_epoch());
    const std::time_t s = static_cast<std::time_t>(us.count() / 1'000'000);
    std::tm tm{};
    gmtime_r(&s, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
    return fmt::format("{}.{:06}Z", buf, us.count() % 1'000'000);
  }

  void tick() {
    timer.expires_after(config.period);
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (ec) return;
      if (self->server->has_clients())
        if (auto l = self->next_write(self->line(false)); !l.empty()) {
          self->server->broadcast(l);
          self->sent += self->server->clients();
        }
      self->tick();
    });
  }

  World& world;
  Clock clock;
  ShdrTwinConfig config;
  std::uint64_t sent = 0, pongs = 0, flips = 0;
  std::array<std::string, 3> last;  // the values last sent
  std::mt19937_64 random{config.seed};
  std::array<double, 3> next_flip_s{-1.0, -1.0, -1.0};  // per axis, the twin's time
  std::array<bool, 3> dithered{};
  std::string held;  // split_lines: the rest of the last look's text, sent at the next look
};

ShdrTwin::ShdrTwin(boost::asio::io_context& io, World& world, Clock clock, ShdrTwinConfig config)
    : ShdrTwin(std::make_shared<Impl>(io, world, std::move(clock), config)) {}
ShdrTwin::ShdrTwin(std::shared_ptr<Impl> impl) : TcpTwin(impl), impl_(std::move(impl)) {
  impl_->server->start(
      [impl = impl_.get()](const detail::LineServer::ClientPtr& client, const std::string& line) {
        impl->on_line(client, line);
      },
      [impl = impl_.get()](const detail::LineServer::ClientPtr& client) {
        // The others first get the rest of a split line; the new agent gets every item (whole:
        // the split starts with the next look).
        if (!impl->held.empty()) impl->server->broadcast(std::exchange(impl->held, {}), client);
        impl->server->send(client, impl->line(true));
        ++impl->sent;
      });
  impl_->tick();
}
std::uint64_t ShdrTwin::lines_sent() const { return impl_->sent; }
std::uint64_t ShdrTwin::pings_answered() const { return impl_->pongs; }
std::uint64_t ShdrTwin::chatter_flips() const { return impl_->flips; }

}  // namespace cal::drivers::sim
