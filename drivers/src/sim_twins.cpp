// The simulated twins (see sim/twins.hpp): protocol servers over loopback TCP and
// pseudo-terminals, answering from the simulated World.
#include <fcntl.h>
#include <fmt/format.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <boost/asio.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cmath>
#include <deque>
#include <list>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "cal/drivers/sim/twins.hpp"

namespace cal::drivers::sim {
namespace asio = boost::asio;
using asio::ip::tcp;
using nlohmann::json;

World::World(MachineConfig machine, AirConfig air, double step_s)
    : machine_(std::move(machine)), air_(std::move(air)), step_s_(step_s) {}

void World::advance_to(double t_s) {
  while (machine_.state().time_s < t_s - 1e-12)
    machine_.step(std::min(step_s_, t_s - machine_.state().time_s));
}

Clock steady_clock(double speed) {
  const auto start = std::chrono::steady_clock::now();
  return [start, speed] {
    return speed * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
}

namespace {

// Writes queued strings to an Asio stream in order; shared by the TCP and pty servers.
template <class Stream>
struct LineWriter {
  // A device sends whether or not anyone listens; with nobody reading the pty, its buffer
  // fills and a real device's output is lost. Beyond this much queued, new output is dropped
  // (and counted) instead of growing without bound.
  static constexpr std::size_t max_queued = 1 << 16;
  std::deque<std::string> queue;
  std::uint64_t dropped = 0;
  void send(Stream& s, std::string line, std::shared_ptr<void> keep_alive) {
    if (queue.size() >= max_queued) {
      ++dropped;
      return;
    }
    queue.push_back(std::move(line));
    if (queue.size() == 1) next(s, std::move(keep_alive));
  }
  void next(Stream& s, std::shared_ptr<void> keep_alive) {
    asio::async_write(s, asio::buffer(queue.front()),
                      [this, &s, keep_alive](const boost::system::error_code& ec, std::size_t) {
                        if (ec) return queue.clear();
                        queue.pop_front();
                        if (!queue.empty()) next(s, keep_alive);
                      });
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// IDS3010: newline-terminated JSON-RPC 2.0 (one object per line), results [error, values...].

struct IdsTwin::Impl : std::enable_shared_from_this<IdsTwin::Impl> {
  struct Client : std::enable_shared_from_this<Client> {
    explicit Client(tcp::socket s) : socket(std::move(s)) {}
    tcp::socket socket;
    asio::streambuf input;
    LineWriter<tcp::socket> writer;
  };

  Impl(asio::io_context& io, World& w, Clock c, IdsTwinConfig cfg)
      : acceptor(io, tcp::endpoint(asio::ip::address_v4::loopback(), cfg.port)),
        world(w),
        clock(std::move(c)),
        config(cfg) {}

  void accept() {
    acceptor.async_accept(
        [self = shared_from_this()](const boost::system::error_code& ec, tcp::socket socket) {
          if (ec) return;  // acceptor closed
          auto client = std::make_shared<Client>(std::move(socket));
          self->clients.push_back(client);
          self->read(client);
          self->accept();
        });
  }

  void read(const std::shared_ptr<Client>& client) {
    asio::async_read_until(
        client->socket, client->input, '\n',
        [self = shared_from_this(), client](const boost::system::error_code& ec, std::size_t n) {
          if (ec) {
            self->clients.remove(client);
            return;
          }
          std::string line(asio::buffers_begin(client->input.data()),
                           asio::buffers_begin(client->input.data()) + static_cast<long>(n));
          client->input.consume(n);
          client->writer.send(client->socket, self->answer(line) + "\n", client);
          self->read(client);
        });
  }

  std::string mode(double now) const {
    if (measuring_since < 0) return aligning ? "optics alignment running" : "system idle";
    return now - measuring_since < config.starting_s ? "measurement starting"
                                                     : "measurement running";
  }

  // The device's answer to one request line.
  std::string answer(const std::string& line) {
    ++served;
    const json request = json::parse(line, nullptr, false);
    if (request.is_discarded() || !request.is_object() || !request.contains("method"))
      return json{{"jsonrpc", "2.0"},
                  {"error", {{"code", -32700}, {"message", "Parse error"}}},
                  {"id", nullptr}}
          .dump();
    const json id = request.value("id", json());
    const std::string method =
        request["method"].is_string() ? request["method"].get<std::string>() : "";
    const json params = request.value("params", json::array());
    const double now = clock();
    world.advance_to(now);
    json result = dispatch(method, params, now);
    if (result.is_null())
      return json{{"jsonrpc", "2.0"},
                  {"error", {{"code", -32601}, {"message", "Method not found"}}},
                  {"id", id}}
          .dump();
    return json{{"jsonrpc", "2.0"}, {"result", result}, {"id", id}}.dump();
  }

  std::int64_t displacement_pm(int axis) {
    const int machine_axis = config.machine_axis[static_cast<std::size_t>(axis)];
    if (machine_axis < 0) return 0;
    const double n = world.air().sample(world.time_s()).refractive_index;
    const double m = laser_reading_m(world.state(), static_cast<kinematics::Axis>(machine_axis),
                                     config.datum_mm[static_cast<std::size_t>(axis)], n);
    return std::llround(m * 1e12);
  }

  std::int64_t axis_status(int axis, double now) const {
    if (measuring_since < 0 || now - measuring_since < config.starting_s)
      return error_not_measuring;
    return beam_lost[static_cast<std::size_t>(axis)] ? error_beam_lost : 0;
  }

  json dispatch(const std::string& method, const json& params, double now) {
    const std::string ids = "com.attocube.ids.", ecu = "com.attocube.ecu.";
    if (method == ids + "displacement.getAxesDisplacement" ||
        method == ids + "displacement.getAbsolutePositions") {
      std::int64_t code = 0;
      for (int a = 0; a < 3; ++a)
        if (config.machine_axis[static_cast<std::size_t>(a)] >= 0 && code == 0)
          code = axis_status(a, now);
      return json::array({code, displacement_pm(0), displacement_pm(1), displacement_pm(2)});
    }
    if (method == ids + "displacement.getAxisDisplacement") {
      const int axis =
          params.size() == 1 && params[0].is_number_integer() ? params[0].get<int>() : -1;
      if (axis < 0 || axis > 2) return json::array({-1});
      return json::array({axis_status(axis, now), displacement_pm(axis)});
    }
    if (method == ids + "displacement.getMeasurementEnabled")
      return json::array({0, measuring_since >= 0});
    if (method == ids + "system.startMeasurement") {
      if (measuring_since < 0) measuring_since = now;
      aligning = false;
      return json::array({0});
    }
    if (method == ids + "system.stopMeasurement") {
      measuring_since = -1;
      return json::array({0});
    }
    if (method == ids + "system.startOpticsAlignment") {
      measuring_since = -1;
      aligning = true;
      return json::array({0});
    }
    if (method == ids + "system.stopOpticsAlignment") {
      aligning = false;
      return json::array({0});
    }
    if (method == ids + "system.getCurrentMode") return json::array({0, mode(now)});
    if (method == ids + "system.getSystemError") return json::array({0});
    if (method == ids + "system.resetAxes") {
      for (std::size_t a = 0; a < 3; ++a)
        if (config.machine_axis[a] >= 0)
          config.datum_mm[a] =
              world.state().tool_mm[static_cast<std::size_t>(config.machine_axis[a])];
      return json::array({0});
    }
    if (method == ecu + "enable") return json::array({0});
    if (method == ecu + "getConnected") return json::array({0, config.ecu_connected});
    const AirSample air = world.air().sample(now);
    if (method == ecu + "getTemperatureInDegrees") return json::array({0, air.temperature_degc});
    if (method == ecu + "getPressureInHPa") return json::array({0, air.pressure_pa / 100.0});
    if (method == ecu + "getHumidityInPercent") return json::array({0, air.humidity_pct});
    if (method == ecu + "getRefractiveIndex") return json::array({0, air.refractive_index});
    return json();  // unknown: JSON-RPC "Method not found"
  }

  tcp::acceptor acceptor;
  World& world;
  Clock clock;
  IdsTwinConfig config;
  std::list<std::shared_ptr<Client>> clients;
  std::array<bool, 3> beam_lost{};
  double measuring_since = -1.0;
  bool aligning = false;
  std::uint64_t served = 0;
};

IdsTwin::IdsTwin(asio::io_context& io, World& world, Clock clock, IdsTwinConfig config)
    : impl_(std::make_shared<Impl>(io, world, std::move(clock), config)) {
  impl_->accept();
}
IdsTwin::~IdsTwin() {
  boost::system::error_code ignored;
  impl_->acceptor.close(ignored);
  drop_connections();
}
std::uint16_t IdsTwin::port() const { return impl_->acceptor.local_endpoint().port(); }
void IdsTwin::set_beam_lost(int axis, bool lost) {
  impl_->beam_lost.at(static_cast<std::size_t>(axis)) = lost;
}
void IdsTwin::drop_connections() {
  for (auto& c : impl_->clients) {
    boost::system::error_code ignored;
    c->socket.shutdown(tcp::socket::shutdown_both, ignored);
    c->socket.close(ignored);
  }
  impl_->clients.clear();
}
std::uint64_t IdsTwin::requests_served() const { return impl_->served; }

// ---------------------------------------------------------------------------------------------
// MTConnect SHDR adapter: position lines to every client on a timer, "* PONG" to "* PING".

struct ShdrTwin::Impl : std::enable_shared_from_this<ShdrTwin::Impl> {
  struct Client {
    explicit Client(tcp::socket s) : socket(std::move(s)) {}
    tcp::socket socket;
    asio::streambuf input;
    LineWriter<tcp::socket> writer;
  };

  Impl(asio::io_context& io, World& w, Clock c, ShdrTwinConfig cfg)
      : acceptor(io, tcp::endpoint(asio::ip::address_v4::loopback(), cfg.port)),
        timer(io),
        world(w),
        clock(std::move(c)),
        config(cfg) {}

  void accept() {
    acceptor.async_accept(
        [self = shared_from_this()](const boost::system::error_code& ec, tcp::socket socket) {
          if (ec) return;
          auto client = std::make_shared<Client>(std::move(socket));
          self->clients.push_back(client);
          self->read(client);
          self->accept();
        });
  }

  void read(const std::shared_ptr<Client>& client) {
    asio::async_read_until(
        client->socket, client->input, '\n',
        [self = shared_from_this(), client](const boost::system::error_code& ec, std::size_t n) {
          if (ec) {
            self->clients.remove(client);
            return;
          }
          const std::string line(asio::buffers_begin(client->input.data()),
                                 asio::buffers_begin(client->input.data()) + static_cast<long>(n));
          client->input.consume(n);
          if (line.starts_with("* PING")) {
            ++self->pongs;
            client->writer.send(client->socket,
                                fmt::format("* PONG {}\n", self->config.pong_timeout_ms), client);
          }
          self->read(client);
        });
  }

  void tick() {
    timer.expires_after(config.period);
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (ec) return;
      if (!self->clients.empty()) {
        self->world.advance_to(self->clock());
        const auto& c = self->world.state().commanded_mm;
        const auto line = fmt::format("|Xcom|{:.4f}|Ycom|{:.4f}|Zcom|{:.4f}\n", c[0], c[1], c[2]);
        for (const auto& client : self->clients) {
          client->writer.send(client->socket, line, client);
          ++self->sent;
        }
      }
      self->tick();
    });
  }

  tcp::acceptor acceptor;
  asio::steady_timer timer;
  World& world;
  Clock clock;
  ShdrTwinConfig config;
  std::list<std::shared_ptr<Client>> clients;
  std::uint64_t sent = 0, pongs = 0;
};

ShdrTwin::ShdrTwin(asio::io_context& io, World& world, Clock clock, ShdrTwinConfig config)
    : impl_(std::make_shared<Impl>(io, world, std::move(clock), config)) {
  impl_->accept();
  impl_->tick();
}
ShdrTwin::~ShdrTwin() {
  boost::system::error_code ignored;
  impl_->acceptor.close(ignored);
  impl_->timer.cancel();
  for (auto& c : impl_->clients) c->socket.close(ignored);
  impl_->clients.clear();
}
std::uint16_t ShdrTwin::port() const { return impl_->acceptor.local_endpoint().port(); }
std::uint64_t ShdrTwin::lines_sent() const { return impl_->sent; }
std::uint64_t ShdrTwin::pings_answered() const { return impl_->pongs; }

// ---------------------------------------------------------------------------------------------
// Pseudo-terminal devices: the twin holds the master side (and keeps the slave open so the
// master does not see EIO before the driver opens it).

namespace {

struct PtyDevice {
  asio::posix::stream_descriptor master;
  int slave_fd = -1;
  std::string path;
  asio::streambuf input;
  LineWriter<asio::posix::stream_descriptor> writer;
  std::uint64_t lines = 0;

  explicit PtyDevice(asio::io_context& io) : master(io) {
    int m = -1;
    std::array<char, 128> name{};
    if (openpty(&m, &slave_fd, name.data(), nullptr, nullptr) != 0)
      throw std::runtime_error(
          fmt::format("simulated twin: openpty failed: {}", std::strerror(errno)));
    termios raw{};
    tcgetattr(m, &raw);
    cfmakeraw(&raw);
    tcsetattr(m, TCSANOW, &raw);
    master.assign(m);
    path = name.data();
  }
  ~PtyDevice() { unplug(); }
  void unplug() {
    boost::system::error_code ignored;
    master.close(ignored);
    if (slave_fd >= 0) ::close(slave_fd);
    slave_fd = -1;
  }
  void send(std::string line, std::shared_ptr<void> keep_alive, std::uint64_t count = 1) {
    if (!master.is_open()) return;
    lines += count;
    writer.send(master, std::move(line), std::move(keep_alive));
  }
};

// Reads CR- or LF-terminated command lines from the master and hands them to on_line.
template <class Self>
void read_commands(const std::shared_ptr<Self>& self) {
  asio::async_read_until(self->pty.master, self->pty.input, '\r',
                         [self](const boost::system::error_code& ec, std::size_t n) {
                           if (ec) return;
                           std::string line(
                               asio::buffers_begin(self->pty.input.data()),
                               asio::buffers_begin(self->pty.input.data()) + static_cast<long>(n));
                           self->pty.input.consume(n);
                           while (!line.empty() && (line.back() == '\r' || line.back() == '\n'))
                             line.pop_back();
                           while (!line.empty() && line.front() == '\n') line.erase(0, 1);
                           self->on_command(line);
                           read_commands(self);
                         });
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// PTU300: commands end with CR; answers and RUN-mode lines end with CR LF. Output in the
// default FORM of the user's guide ("P= 1033.7 hPa T= 22.2 'C RH= 38.3 %RH"), with one more
// decimal on P and T than that example, as a FORM such as 4.2 P would print.

struct Ptu300Twin::Impl : std::enable_shared_from_this<Ptu300Twin::Impl> {
  Impl(asio::io_context& io, World& w, Clock c, Ptu300TwinConfig cfg)
      : pty(io),
        timer(io),
        world(w),
        clock(std::move(c)),
        config(cfg),
        running(cfg.start_in_run_mode) {}

  std::string reading() {
    const double now = clock();
    world.advance_to(now);
    const AirSample a = world.air().sample(now);
    return fmt::format("P= {:7.2f} hPa T= {:6.2f} 'C RH= {:5.1f} %RH\r\n", a.pressure_pa / 100.0,
                       a.temperature_degc, a.humidity_pct);
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
    timer.expires_after(std::chrono::milliseconds(5));
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (!ec) self->tick();
    });
  }

  PtyDevice pty;
  asio::steady_timer timer;
  World& world;
  Clock clock;
  Ptu300TwinConfig config;
  bool running = false;
  double next_output_s = 0.0;
};

Ptu300Twin::Ptu300Twin(asio::io_context& io, World& world, Clock clock, Ptu300TwinConfig config)
    : impl_(std::make_shared<Impl>(io, world, std::move(clock), config)) {
  read_commands(impl_);
  impl_->tick();
}
Ptu300Twin::~Ptu300Twin() {
  impl_->timer.cancel();
  impl_->pty.unplug();
}
const std::string& Ptu300Twin::device_path() const { return impl_->pty.path; }
void Ptu300Twin::unplug() {
  impl_->timer.cancel();
  impl_->pty.unplug();
}
std::uint64_t Ptu300Twin::lines_sent() const { return impl_->pty.lines; }

// ---------------------------------------------------------------------------------------------
// Line gauge: "+000.12345\r\n" per sample (mm from the gauge's zero), continuously at the
// sample rate (in simulated time) or one per request line.

struct GaugeTwin::Impl : std::enable_shared_from_this<GaugeTwin::Impl> {
  Impl(asio::io_context& io, World& w, Clock c, GaugeTwinConfig cfg)
      : pty(io), timer(io), world(w), clock(std::move(c)), config(std::move(cfg)) {}

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
    timer.expires_after(std::chrono::milliseconds(2));
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (!ec) self->tick();
    });
  }

  PtyDevice pty;
  asio::steady_timer timer;
  World& world;
  Clock clock;
  GaugeTwinConfig config;
  std::uint64_t next_sample = 0;
};

GaugeTwin::GaugeTwin(asio::io_context& io, World& world, Clock clock, GaugeTwinConfig config)
    : impl_(std::make_shared<Impl>(io, world, std::move(clock), std::move(config))) {
  if (!(impl_->config.sample_rate_hz > 0.0))
    throw std::invalid_argument("gauge twin: sample rate must be > 0");
  read_commands(impl_);
  impl_->tick();
}
GaugeTwin::~GaugeTwin() {
  impl_->timer.cancel();
  impl_->pty.unplug();
}
const std::string& GaugeTwin::device_path() const { return impl_->pty.path; }
void GaugeTwin::unplug() {
  impl_->timer.cancel();
  impl_->pty.unplug();
}
std::uint64_t GaugeTwin::lines_sent() const { return impl_->pty.lines; }
void GaugeTwin::set_streaming(bool on) {
  impl_->timer.cancel();
  impl_->config.continuous = on;
  if (!on) return;
  impl_->next_sample =
      static_cast<std::uint64_t>(std::ceil(impl_->clock() * impl_->config.sample_rate_hz));
  impl_->tick();
}

}  // namespace cal::drivers::sim
