// SIMULATED line gauge (see twin.hpp): "+000.12345\r\n" per sample (mm from the gauge's zero),
// continuously at the sample rate (in simulated time) or one per request line.
#include "line_gauge/twin.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>

#include "sim/twin_io.hpp"

namespace cal::drivers::sim {

struct GaugeTwin::Impl : detail::PtyChannel, std::enable_shared_from_this<GaugeTwin::Impl> {
  Impl(boost::asio::io_context& io, World& w, Clock c, GaugeTwinConfig cfg)
      : PtyChannel(io), ctx(io), world(w), clock(std::move(c)), config(std::move(cfg)) {}

  std::string line_at(double t) {
    world.advance_to(t);
    const double value =
        config.value ? config.value(world)
                     : ballbar_length_mm(world.state(), config.pivot_mm) - config.zero_length_mm;
    const int d = config.decimals;
    switch (config.style) {
      case GaugeLineStyle::mitutoyo_digimatic:  // 8 characters of digits and point, CR only
        return fmt::format("01A{:+0{}.{}f}\r", value, std::max(9, d + 3), d);
      case GaugeLineStyle::sylvac:
        return fmt::format("{:+.{}f}\r", value, d);
      case GaugeLineStyle::mahr_millimar:
        return fmt::format("{:.{}f}mm\r\n", value, d);
      case GaugeLineStyle::plain:
        break;
    }
    return fmt::format("{:+0{}.{}f}\r\n", value, d + 5, d);
  }

  void on_command(const std::string& cmd) {
    if (config.continuous || cmd != config.request) return;
    if (config.answer_delay <= std::chrono::nanoseconds::zero())
      return pty.send(line_at(clock()), shared_from_this());
    // Measured now, whenever it is sent; or when it is sent (an empty line: measured then).
    answers.emplace_back(loop_now() + config.answer_delay.count(),
                         config.measure_on_answer ? std::string() : line_at(clock()));
    if (answers.size() == 1) arm_answer();
  }

  // The delayed answers go out in the order of their requests, each when it is due.
  void arm_answer() {
    answer_timer.expires_after(
        std::chrono::nanoseconds(std::max<std::int64_t>(0, answers.front().first - loop_now())));
    answer_timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (!ec) self->send_due();
    });
  }
  void send_due() {
    const std::int64_t now = loop_now();
    while (!answers.empty() && answers.front().first <= now) {
      auto& line = answers.front().second;
      if (line.empty()) line = line_at(clock());
      if (pty.master.is_open()) pty.send(std::move(line), shared_from_this());
      answers.pop_front();
    }
    if (!answers.empty()) arm_answer();
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

  std::int64_t loop_now() const { return loop_clock(ctx)(); }

  boost::asio::io_context& ctx;
  Timer answer_timer{ctx};
  std::deque<std::pair<std::int64_t, std::string>> answers;  // (due, loop ns), delayed answers
  World& world;
  Clock clock;
  GaugeTwinConfig config;
  std::uint64_t next_sample = 0;
};

GaugeLineStyle gauge_line_style(std::string_view preset) {
  if (preset == "mitutoyo_digimatic") return GaugeLineStyle::mitutoyo_digimatic;
  if (preset == "sylvac") return GaugeLineStyle::sylvac;
  if (preset == "mahr_millimar") return GaugeLineStyle::mahr_millimar;
  return GaugeLineStyle::plain;
}

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
