// daq run linear|circle --config FILE: acquisition against the configured devices;
// daq gcode linear|circle --config FILE: the part program for the test.
#include <fmt/format.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/streambuf.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/daq/config.hpp"
#include "cal/daq/gcode.hpp"
#include "cal/drivers/instruments.hpp"
#include "cal/drivers/transport/hid.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "iso230_2_output.hpp"
#include "linear_run.hpp"
#include "session_spec.hpp"
#include "web/assets.hpp"
#include "web/server.hpp"

namespace daq {
namespace {

namespace d = cal::drivers;
namespace web = cal::daq::web;
namespace t = cal::drivers::transport;
using namespace std::chrono_literals;

// "hid VID:PID" (hex, as lsusb prints them), or "hid /dev/hidrawN".
t::HidSettings hid_settings(const cal::daq::DeviceConfig& c, const std::string& rest) {
  if (rest.starts_with("/")) return {.path = rest};
  unsigned vid = 0, pid = 0;
  char extra = 0;
  if (std::sscanf(rest.c_str(), "%4x:%4x%c", &vid, &pid, &extra) != 2)
    throw cal::InputError(
        fmt::format("devices.{}.transport '{}': expected hid VID:PID (hex) or hid /dev/hidrawN",
                    c.id, c.transport));
  // TEMPer sticks expose a keyboard interface too; the sensor answers on interface 1.
  return {.vendor_id = static_cast<std::uint16_t>(vid),
          .product_id = static_cast<std::uint16_t>(pid),
          .interface_number = c.driver == "temper" ? 1 : -1};
}

std::unique_ptr<t::Transport> make_transport(boost::asio::io_context& io,
                                             const cal::daq::DeviceConfig& c) {
  const auto space = c.transport.find(' ');
  const std::string kind = c.transport.substr(0, space),
                    rest = space == std::string::npos ? "" : c.transport.substr(space + 1);
  if (kind == "tcp") {
    const auto colon = rest.rfind(':');
    if (colon == std::string::npos)
      throw cal::InputError(
          fmt::format("devices.{}.transport '{}': expected tcp HOST:PORT", c.id, c.transport));
    return t::make_tcp(io, {.host = rest.substr(0, colon),
                            .port = static_cast<std::uint16_t>(std::stoi(rest.substr(colon + 1)))});
  }
  if (kind == "serial") {
    const auto sp = rest.find(' ');
    if (sp == std::string::npos)
      throw cal::InputError(fmt::format(
          "devices.{}.transport '{}': expected serial DEVICE BAUD FRAME", c.id, c.transport));
    return t::make_serial(
        io, t::parse_serial_settings(rest.substr(sp + 1), {.device = rest.substr(0, sp)}));
  }
  if (kind == "hid") return t::make_hid(io, hid_settings(c, rest));
  throw cal::InputError(
      fmt::format("devices.{}: transport '{}' has no driver here yet", c.id, c.transport));
}

InstrumentSpec spec_of(const cal::daq::DeviceConfig& c, std::uint16_t device) {
  InstrumentSpec s{.device = device, .driver = c.driver, .role = c.role, .transport = c.transport};
  if (!c.axes.empty()) {
    s.ids_axes = {false, false, false};
    for (int a : c.axes) s.ids_axes[static_cast<std::size_t>(a)] = true;
  }
  s.gauge = {
      .request = c.request, .pattern = c.pattern, .unit = d::codec::gauge_unit_from_string(c.unit)};
  if (s.gauge.unit == d::codec::GaugeUnit::degc) s.gauge.min_si = -40, s.gauge.max_si = 150;
  s.temper_family = c.family;
  s.feed_key = c.key;
  s.feed_column = c.column;
  s.feed_unit = c.unit == "in" ? "in" : "mm";
  static constexpr std::string_view drivers[] = {"ids3010", "ptu300",     "gauge",
                                                 "temper",  "halsampler", "shdr"};
  if (std::find(std::begin(drivers), std::end(drivers), c.driver) == std::end(drivers))
    throw cal::InputError(
        fmt::format("devices.{}: driver '{}' is not available for runs yet", c.id, c.driver));
  return s;
}

const cal::daq::DeviceConfig& need(const cal::daq::Config& c, const char* role) {
  if (const auto* d = c.device_for(role)) return *d;
  throw cal::InputError(fmt::format("{}: no device with role = \"{}\"", c.source.string(), role));
}

struct RunOptions {
  std::string config, db, capture;
  int give_up_after = 20;
  bool json = false;
};

// Enter on the keyboard is the manual trigger ("capture now").
void watch_keyboard(boost::asio::io_context& io, std::function<void()> on_enter) {
  if (!::isatty(STDIN_FILENO)) return;
  auto in = std::make_shared<boost::asio::posix::stream_descriptor>(io, ::dup(STDIN_FILENO));
  auto buf = std::make_shared<boost::asio::streambuf>();
  auto next = std::make_shared<std::function<void()>>();
  *next = [in, buf, on_enter, next] {
    boost::asio::async_read_until(*in, *buf, '\n',
                                  [in, buf, on_enter, next](auto ec, std::size_t n) {
                                    if (ec) return;
                                    buf->consume(n);
                                    on_enter();
                                    (*next)();
                                  });
  };
  (*next)();
}

// Records the capture of a session when asked to (--capture FILE).
struct SessionCapture {
  std::unique_ptr<cal::replay::CaptureWriter> writer;
  std::unique_ptr<cal::replay::CaptureRecorder> recorder;
  SessionCapture(const std::string& path, const cal::daq::Config& c,
                 const std::vector<InstrumentSpec>& specs) {
    if (path.empty()) return;
    writer =
        std::make_unique<cal::replay::CaptureWriter>(path, capture_header(c, specs, "daq 0.1.0"));
    recorder = std::make_unique<cal::replay::CaptureRecorder>(*writer);
  }
  std::string absolute_path(const std::string& path) const {
    return writer ? std::filesystem::absolute(path).string() : std::string{};
  }
};

d::InstrumentOptions instrument_options(const cal::daq::DeviceConfig& dc, const RunOptions& o,
                                        cal::replay::CaptureRecorder* recorder) {
  d::InstrumentOptions opt{
      .name = dc.id, .backoff = {.max_attempts = o.give_up_after}, .recorder = recorder};
  if (dc.poll_s > 0)
    opt.poll_period = std::chrono::microseconds(static_cast<std::int64_t>(dc.poll_s * 1e6));
  return opt;
}

// Runs the event loop until the run ends (Ctrl-C or SIGTERM stop it as the operator's
// abort), closes the capture, and throws with the reason if the run did not complete.
template <class Run>
const auto& run_to_end(boost::asio::io_context& io, Run& run, SessionCapture& capture) {
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](auto ec, int) {
    if (!ec) run.stop("stopped by the operator");
  });
  while (!run.finished()) io.run_for(100ms);
  if (capture.writer) capture.writer->close();
  const auto& out = run.outcome();
  if (!out.complete)
    throw cal::InputError(fmt::format("run {} stopped: {}", out.run_id, out.reason));
  return out;
}

// The instruments of a linear run (laser, air, material sensors, optional position feed).
std::vector<InstrumentSpec> linear_specs(const cal::daq::Config& config) {
  if (!config.linear)
    throw cal::InputError(fmt::format("{}: no [test.linear]", config.source.string()));
  std::vector<InstrumentSpec> specs;
  std::uint16_t n = 0;
  // The position feed reports the test axis: its channel is the axis' index.
  const int axis = config.linear->axis == "Y" ? 1 : config.linear->axis == "Z" ? 2 : 0;
  for (const auto& dc : config.devices) {
    if (dc.role != "laser" && dc.role != "air" && dc.role != "material" && dc.role != "position")
      continue;
    specs.push_back(spec_of(dc, n++));
    specs.back().feed_axis = axis;
    if (specs.back().feed_key.empty()) specs.back().feed_key = config.linear->axis + "act";
  }
  need(config, "laser"), need(config, "air");
  return specs;
}

void add_linear_instruments(boost::asio::io_context& io, const cal::daq::Config& config,
                            const std::vector<InstrumentSpec>& specs, const RunOptions& o,
                            cal::replay::CaptureRecorder* recorder, LinearRunSetup& setup) {
  for (const auto& s : specs) {
    const auto& dc = *std::find_if(
        config.devices.begin(), config.devices.end(),
        [&](const auto& x) { return x.transport == s.transport && x.role == s.role; });
    auto opt = instrument_options(dc, o, recorder);
    if (dc.poll_s <= 0 && (s.driver == "ptu300" || s.driver == "temper" || s.role == "material"))
      opt.poll_period = 1000ms;
    if (dc.poll_s <= 0 && s.driver == "shdr") opt.poll_period = 5000ms;  // "* PING" heartbeats
    auto inst = make_instrument(io, s, make_transport(io, dc), opt);
    if (s.role == "laser")
      setup.laser = std::move(inst);
    else if (s.role == "air")
      setup.air = std::move(inst);
    else if (s.role == "position")
      setup.position = std::move(inst), setup.position_channel = s.feed_axis;
    else
      setup.material.push_back(std::move(inst));
  }
}

void run_linear(const RunOptions& o) {
  const auto config = cal::daq::load_config(o.config);
  boost::asio::io_context io;
  const auto specs = linear_specs(config);
  SessionCapture capture(o.capture, config, specs);
  LinearRunSetup setup;
  setup.config = config;
  setup.database = database_path(o.db);
  setup.capture_path = capture.absolute_path(o.capture);
  add_linear_instruments(io, config, specs, o, capture.recorder.get(), setup);
  const bool tty = ::isatty(STDOUT_FILENO);
  setup.on_event = [tty](const std::string& e) {
    fmt::print("{}  {}\n", tty ? "\r\033[K" : "", e);
  };
  setup.on_live = [tty](const LiveState& s) {
    if (!tty || !s.progress.next_position_mm) return;
    fmt::print(
        "\rrun {} of {} {}  target {} of {}  {:+9.2f} um  air {:.2f} degC  material {:.2f} degC  ",
        s.progress.run, s.progress.runs,
        s.progress.direction == cal::iso230_2::Direction::up ? "up" : "down", s.progress.target,
        s.progress.targets, s.deviation_um, s.air_temperature_degc, s.material_degc);
    std::fflush(stdout);
  };
  LinearRun run(io, std::move(setup));
  run.start();
  fmt::print(
      "Waiting for the machine: run the program from `daq gcode linear --config {}`; Enter "
      "captures the current stop by hand; Ctrl-C stops.\n",
      o.config);
  watch_keyboard(io, [&] { run.manual_capture(); });
  const auto& out = run_to_end(io, run, capture);
  print(*out.evaluation);
}

// daq run circle: the ballbar streams; the run waits for the feed-in, then records both arcs.
void run_circle(const RunOptions& o) {
  const auto config = cal::daq::load_config(o.config);
  const auto [program, analysis] = circle_test(config);
  const auto& dc = need(config, "ballbar");
  if (dc.driver != "gauge")
    throw cal::InputError(
        fmt::format("{}: devices.{}: the ballbar needs driver = \"gauge\"", o.config, dc.id));
  boost::asio::io_context io;
  const std::vector<InstrumentSpec> specs{spec_of(dc, 0)};
  SessionCapture capture(o.capture, config, specs);
  CircleRunSetup setup{
      .config = config,
      .program = program,
      .analysis = analysis,
      .database = database_path(o.db),
      .ballbar = make_instrument(io, specs[0], make_transport(io, dc),
                                 instrument_options(dc, o, capture.recorder.get())),
      .capture_path = capture.absolute_path(o.capture)};
  const bool tty = ::isatty(STDOUT_FILENO);
  setup.on_event = [tty](const std::string& e) {
    fmt::print("{}  {}\n", tty ? "\r\033[K" : "", e);
  };
  setup.on_live = [tty](const CircleLive& s) {
    if (!tty) return;
    fmt::print("\r{:<24} {:7.1f} deg  {:+9.2f} um  {:5.1f} %  ", s.phase, s.angle_deg,
               s.deviation_um, 100 * s.fraction);
    std::fflush(stdout);
  };
  CircleRun run(io, std::move(setup));
  run.start();
  fmt::print(
      "Waiting for the feed-in: run the program from `daq gcode circle --config {}`; Ctrl-C "
      "stops.\n",
      o.config);
  const auto& out = run_to_end(io, run, capture);
  if (o.json)
    return fmt::print(
        "{}\n", circle_json(*out.result, program.radius_mm, analysis.plane, program.feed_mm_per_min)
                    .dump(2));
  fmt::print("\nrun {}: {} readings\n", out.run_id, out.readings);
  print_circle(*out.result, program.radius_mm, analysis.plane, program.feed_mm_per_min);
}

// --- daq serve: the live web readout and an API that starts and stops runs ------------------

struct ServeOptions {
  RunOptions run;  // config, db, give_up_after
  std::string address = "127.0.0.1", token, capture_dir;
  std::uint16_t port = 8080;
};

// One run at a time on the service's event loop; its live state is pushed to the page (about
// 10 Hz, the latest state only, so a 10 kHz stream cannot make it fall behind).
class Service {
 public:
  Service(boost::asio::io_context& io, ServeOptions o)
      : io_(io), o_(std::move(o)), config_(cal::daq::load_config(o_.run.config)), check_(io) {
    try {
      make_server();
    } catch (const std::invalid_argument& e) {
      throw cal::InputError(fmt::format("daq serve: {}", e.what()));
    }
    publish_idle("no run: start one");
    tick();
  }

  void make_server() {
    server_ = std::make_unique<web::LiveServer>(
        io_, web::ServerOptions{.address = o_.address, .port = o_.port, .token = o_.token},
        web::Api{.page = [] { return web::live_page(); },
                 .runs = [this] { return runs(); },
                 .status = [this] { return web::Response{.body = status().dump()}; },
                 .start = [this](const std::string& body) { return start(body); },
                 .stop = [this] { return stop("stopped from the web page"); }});
  }

  // The page shows this between runs.
  void publish_idle(const std::string& message) {
    server_->publish(
        nlohmann::json{{"schema", "caldaq.live.v1"}, {"state", "idle"}, {"message", message}}
            .dump());
  }
  std::uint16_t port() const { return server_->port(); }
  void shutdown() {
    if (running()) stop("the service was stopped");
    check_.cancel();
    server_.reset();
  }

 private:
  bool running() const { return linear_ || circle_; }

  web::Response runs() const {
    cal::storage::Store store(database_path(o_.run.db));
    nlohmann::json list = nlohmann::json::array();
    for (const auto& r : store.runs())
      list.push_back({{"id", r.id},
                      {"kind", r.kind},
                      {"axis", r.axis},
                      {"campaign", r.campaign},
                      {"status", cal::storage::to_string(r.status)},
                      {"started_unix_ms", r.started_unix_ms},
                      {"note", r.note}});
    return {.body = nlohmann::json{{"schema", "caldaq.runs.v1"}, {"runs", list}}.dump()};
  }

  nlohmann::json status() const {
    nlohmann::json j{{"schema", "caldaq.status.v1"},
                     {"running", running()},
                     {"config", o_.run.config},
                     {"tests", nlohmann::json::array()}};
    if (config_.linear) j["tests"].push_back("linear");
    if (config_.circle) j["tests"].push_back("circle");
    if (running()) j["run"] = {{"id", run_id_}, {"test", test_}};
    if (last_) j["last"] = *last_;
    return j;
  }

  web::Response start(const std::string& body) {
    if (running())
      return {409,
              nlohmann::json{{"error", fmt::format("run {} is still running", run_id_)}}.dump()};
    const auto req = nlohmann::json::parse(body.empty() ? "{}" : body, nullptr, false);
    const std::string test = req.is_object() ? req.value("test", "linear") : "";
    try {
      if (test == "linear")
        start_linear();
      else if (test == "circle")
        start_circle();
      else
        return {400, nlohmann::json{{"error", "give {\"test\": \"linear\"} or \"circle\""}}.dump()};
    } catch (const std::exception& e) {
      linear_.reset(), circle_.reset(), capture_.reset();
      return {400, nlohmann::json{{"error", e.what()}}.dump()};
    }
    test_ = test;
    return {202, nlohmann::json{{"run", run_id_}, {"test", test}}.dump()};
  }

  web::Response stop(const std::string& why) {
    if (!running()) return {409, nlohmann::json{{"error", "no run is running"}}.dump()};
    if (linear_) linear_->stop(why);
    if (circle_) circle_->stop(why);
    finish();
    return {.body = nlohmann::json{{"stopped", last_->at("run")}}.dump()};
  }

  std::string capture_path() const {
    if (o_.capture_dir.empty()) return {};
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count();
    return (std::filesystem::path(o_.capture_dir) / fmt::format("serve-{}.cdq", ms)).string();
  }

  void start_linear() {
    const auto specs = linear_specs(config_);
    const auto path = capture_path();
    capture_ = std::make_unique<SessionCapture>(path, config_, specs);
    LinearRunSetup setup;
    setup.config = config_;
    setup.database = database_path(o_.run.db);
    setup.capture_path = capture_->absolute_path(path);
    add_linear_instruments(io_, config_, specs, o_.run, capture_->recorder.get(), setup);
    setup.on_live = [this](const LiveState& s) { server_->publish(to_json_text(s)); };
    setup.on_event = [](const std::string& e) { fmt::print("  {}\n", e); };
    linear_ = std::make_unique<LinearRun>(io_, std::move(setup));
    linear_->start();
    run_id_ = linear_->outcome().run_id;
    fmt::print("run {} (linear) started from the web page\n", run_id_);
    std::fflush(stdout);
  }

  void start_circle() {
    const auto [program, analysis] = circle_test(config_);
    const auto& dc = need(config_, "ballbar");
    const std::vector<InstrumentSpec> specs{spec_of(dc, 0)};
    const auto path = capture_path();
    capture_ = std::make_unique<SessionCapture>(path, config_, specs);
    CircleRunSetup setup{
        .config = config_,
        .program = program,
        .analysis = analysis,
        .database = database_path(o_.run.db),
        .ballbar = make_instrument(io_, specs[0], make_transport(io_, dc),
                                   instrument_options(dc, o_.run, capture_->recorder.get())),
        .capture_path = capture_->absolute_path(path)};
    setup.on_live = [this](const CircleLive& s) { server_->publish(to_json_text(s)); };
    setup.on_event = [](const std::string& e) { fmt::print("  {}\n", e); };
    circle_ = std::make_unique<CircleRun>(io_, std::move(setup));
    circle_->start();
    run_id_ = circle_->outcome().run_id;
    fmt::print("run {} (circle) started from the web page\n", run_id_);
    std::fflush(stdout);
  }

  // A run ends by itself (all stops, both arcs) or is stopped: keep its outcome, close its
  // capture, and accept the next start.
  void finish() {
    const bool complete = linear_ ? linear_->outcome().complete : circle_->outcome().complete;
    const std::string reason = linear_ ? linear_->outcome().reason : circle_->outcome().reason;
    last_ = nlohmann::json{
        {"run", run_id_}, {"test", test_}, {"complete", complete}, {"reason", reason}};
    if (capture_ && capture_->writer) capture_->writer->close();
    fmt::print("run {} {}{}\n", run_id_, complete ? "complete" : "stopped: ", reason);
    std::fflush(stdout);
    linear_.reset(), circle_.reset(), capture_.reset();
    publish_idle(fmt::format("run {} {}{}", run_id_, complete ? "complete" : "stopped: ", reason));
  }

  void tick() {
    check_.expires_after(200ms);
    check_.async_wait([this](const boost::system::error_code& ec) {
      if (ec) return;
      if ((linear_ && linear_->finished()) || (circle_ && circle_->finished())) finish();
      if (capture_ && capture_->writer) capture_->writer->flush();
      tick();
    });
  }

  boost::asio::io_context& io_;
  ServeOptions o_;
  cal::daq::Config config_;
  boost::asio::steady_timer check_;
  std::unique_ptr<web::LiveServer> server_;
  std::unique_ptr<SessionCapture> capture_;
  std::unique_ptr<LinearRun> linear_;
  std::unique_ptr<CircleRun> circle_;
  std::int64_t run_id_ = 0;
  std::string test_;
  std::optional<nlohmann::json> last_;
};

void serve(const ServeOptions& o) {
  boost::asio::io_context io;
  Service service(io, o);
  fmt::print("daq serve: http://{}:{}/ ({}), runs in {}; Ctrl-C stops\n", o.address, service.port(),
             o.run.config, database_path(o.run.db).string());
  std::fflush(stdout);
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](auto ec, int) {
    if (ec) return;
    service.shutdown();
    io.stop();
  });
  io.run();
}

struct GcodeOptions {
  std::string config, dialect = "fanuc", output;
};

void gcode(const GcodeOptions& o, bool circle) {
  const auto config = cal::daq::load_config(o.config);
  const auto dialect = cal::daq::dialect_from_string(o.dialect);
  std::string text;
  if (circle) {
    if (!config.circle) throw cal::InputError(fmt::format("{}: no [test.circle]", o.config));
    const auto& c = *config.circle;
    text = cal::daq::circle_program({.radius_mm = c.radius_mm,
                                     .feed_mm_per_min = c.feed_mm_per_min,
                                     .sample_rate_hz = c.sample_rate_hz,
                                     .overshoot_deg = c.overshoot_deg},
                                    {.centre_x_mm = c.centre_mm[0], .centre_y_mm = c.centre_mm[1]},
                                    dialect);
  } else {
    if (!config.linear) throw cal::InputError(fmt::format("{}: no [test.linear]", o.config));
    const auto& l = *config.linear;
    const auto plan = linear_plan(l);
    text = cal::daq::linear_program(
        plan, {.axis = l.axis[0], .feed_mm_per_min = l.feed_mm_per_min, .dwell_s = l.dwell_s},
        dialect);
  }
  if (o.output.empty()) return fmt::print("{}", text);
  std::ofstream out(o.output);
  if (!(out << text)) throw cal::InputError(fmt::format("{}: cannot write", o.output));
}

}  // namespace

void add_serve_command(CLI::App& app) {
  auto o = std::make_shared<ServeOptions>();
  auto* cmd = app.add_subcommand(
      "serve",
      "Serve the live readout page and an HTTP/WebSocket API that starts and stops runs of the "
      "configured test (docs/web.md)");
  cmd->add_option("-c,--config", o->run.config, "Machine/campaign TOML (docs/config.md)")
      ->required();
  add_db_option(*cmd, o->run.db);
  cmd->add_option("--address", o->address, "Listen address; not loopback only with --token")
      ->capture_default_str();
  cmd->add_option("--port", o->port, "TCP port (0: any free port)")->capture_default_str();
  cmd->add_option("--token", o->token, "Required from every client (Bearer or ?token=)");
  cmd->add_option("--capture-dir", o->capture_dir, "Record each run's capture in this directory");
  cmd->add_option("--give-up-after", o->run.give_up_after,
                  "Reconnection attempts before a device is given up")
      ->capture_default_str();
  cmd->callback([o] { serve(*o); });
}

void add_run_commands(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  auto* run = app.add_subcommand("run", "Acquire a test with the configured instruments");
  run->require_subcommand(1);
  auto* lin = run->add_subcommand("linear", "ISO 230-2 positioning test (laser, air, material)");
  lin->add_option("-c,--config", o->config, "Machine/campaign TOML (docs/config.md)")->required();
  add_db_option(*lin, o->db);
  lin->add_option("--capture", o->capture, "Record the wire-level capture to this file");
  lin->add_option("--give-up-after", o->give_up_after,
                  "Reconnection attempts before a device is given up")
      ->capture_default_str();
  lin->callback([o] { run_linear(*o); });
  auto* circ = run->add_subcommand("circle", "ISO 230-4 circular test with a ballbar");
  circ->add_option("-c,--config", o->config, "Machine/campaign TOML with [test.circle]")
      ->required();
  add_db_option(*circ, o->db);
  circ->add_option("--capture", o->capture, "Record the wire-level capture to this file");
  circ->add_option("--give-up-after", o->give_up_after,
                   "Reconnection attempts before the ballbar is given up")
      ->capture_default_str();
  circ->add_flag("--json", o->json, "Print the result as caldaq.circle.v1 JSON");
  circ->callback([o] { run_circle(*o); });

  auto g = std::make_shared<GcodeOptions>();
  auto* gc = app.add_subcommand("gcode", "Part program for a configured test");
  gc->require_subcommand(1);
  for (const char* kind : {"linear", "circle"}) {
    auto* sub = gc->add_subcommand(kind, std::string("Program for [test.") + kind + "]");
    sub->add_option("-c,--config", g->config, "Machine/campaign TOML")->required();
    sub->add_option("-d,--dialect", g->dialect, "fanuc, heidenhain or siemens")
        ->capture_default_str();
    sub->add_option("-o,--output", g->output, "Write to a file instead of stdout");
    const bool circle = std::string(kind) == "circle";
    sub->callback([g, circle] { gcode(*g, circle); });
  }
}

}  // namespace daq
