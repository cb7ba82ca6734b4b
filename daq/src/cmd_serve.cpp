// daq serve: the live web readout and an HTTP/WebSocket API that starts and stops runs of the
// configured test (docs/web.md).
#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "cal/analysis/error.hpp"
#include "cal/storage/store.hpp"
#include "circle_run.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "linear_run.hpp"
#include "run_setup.hpp"
#include "web/assets.hpp"
#include "web/server.hpp"

namespace daq {
namespace {

namespace web = cal::daq::web;
using namespace std::chrono_literals;

struct ServeOptions {
  RunOptions run;  // config, db, give_up_after
  std::string address = "127.0.0.1", token, capture_dir;
  std::uint16_t port = 8080;
  std::vector<std::string> allowed_hosts;
  std::size_t max_connections = 256;
  double request_timeout_s = 10.0;
};

// Error bodies: JSON even when a message carries bytes that are not UTF-8 (a path, a device).
web::Response error(int status, const std::string& message) {
  return {status, nlohmann::json{{"error", message}}.dump(
                      -1, ' ', false, nlohmann::json::error_handler_t::replace)};
}

// The body of POST /api/runs/start: exactly {"test": "linear"} or {"test": "circle"}.
std::optional<std::string> requested_test(const std::string& body, std::string& why) {
  const auto req = nlohmann::json::parse(body, nullptr, false);
  const char* expected = R"(give {"test": "linear"} or {"test": "circle"})";
  if (req.is_discarded()) {
    why = fmt::format("the body is not JSON: {}", expected);
  } else if (!req.is_object() || req.size() != 1 || !req.contains("test")) {
    why = fmt::format("the body must be one object with the key \"test\": {}", expected);
  } else if (!req["test"].is_string()) {
    why = fmt::format("\"test\" must be a string, not {}: {}", req["test"].type_name(), expected);
  } else {
    return req["test"].get<std::string>();
  }
  return std::nullopt;
}

// One run at a time on the service's event loop; its live state is pushed to the page (about
// 10 Hz, the latest state only, so a 10 kHz stream cannot make it fall behind).
class Service {
 public:
  Service(boost::asio::io_context& io, ServeOptions o)
      : io_(io), o_(std::move(o)), config_(cal::daq::load_config(o_.run.config)), check_(io) {
    check_devices_at_start();
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
        io_,
        web::ServerOptions{
            .address = o_.address,
            .port = o_.port,
            .token = o_.token,
            .allowed_hosts = o_.allowed_hosts,
            .max_connections = o_.max_connections,
            .request_timeout =
                std::chrono::milliseconds(std::llround(o_.request_timeout_s * 1000.0)),
            .log = [](std::string_view text) { fmt::print(stderr, "daq serve: {}\n", text); }},
        web::Api{.page = [] { return web::live_page(); },
                 .runs = [this] { return runs(); },
                 .status = [this] { return web::Response{.body = status().dump()}; },
                 .start = [this](const std::string& body) { return start(body); },
                 .stop = [this](const std::string& body) { return stop_request(body); }});
  }

  // The devices of the configured tests open and speak before the service starts, or it is
  // refused naming the device (as daq run does before a run).
  void check_devices_at_start() {
    if (o_.run.check_s <= 0) return;
    std::vector<InstrumentSpec> specs;
    if (config_.linear) specs = linear_specs(config_);
    if (config_.circle && config_.device_for("ballbar"))
      specs.push_back(spec_of(need(config_, "ballbar"), static_cast<std::uint16_t>(specs.size())));
    if (specs.empty()) return;
    fmt::print("Checking the devices (up to {} s):\n", o_.run.check_s);
    check_devices(config_, specs, std::chrono::duration<double>(o_.run.check_s),
                  [](const std::string& line) { fmt::print("{}\n", line); });
    std::fflush(stdout);
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

  // An exception escaped a handler of the event loop (e.g. the store failed under a run):
  // the run ends as aborted with the reason, the service goes on.
  void failed(const std::string& what) {
    fmt::print(stderr, "daq serve: error: {} (the service goes on)\n", what);
    if (!running()) return;
    try {
      stop("aborted: " + what);
    } catch (const std::exception& e) {
      fmt::print(stderr, "daq serve: error: the run could not be ended cleanly: {}\n", e.what());
      linear_.reset(), circle_.reset(), capture_.reset();
      publish_idle(fmt::format("run {} aborted: {}", run_id_, what));
    }
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

  // 400 for what the client got wrong (the body, a test the configuration lacks, a device
  // that cannot be opened); 500 for the store or the capture failing.
  web::Response start(const std::string& body) {
    std::string why;
    const auto test = requested_test(body, why);
    if (!test) return error(400, why);
    if (*test != "linear" && *test != "circle")
      return error(400, fmt::format("no test '{}': give {{\"test\": \"linear\"}} or "
                                    "{{\"test\": \"circle\"}}",
                                    *test));
    if (running()) return error(409, fmt::format("run {} is still running", run_id_));
    try {
      if (*test == "linear")
        start_linear();
      else
        start_circle();
    } catch (const cal::InputError& e) {
      linear_.reset(), circle_.reset(), capture_.reset();
      return error(400, e.what());
    } catch (const std::exception& e) {
      linear_.reset(), circle_.reset(), capture_.reset();
      return error(500, e.what());
    }
    test_ = *test;
    return {202, nlohmann::json{{"run", run_id_}, {"test", *test}}.dump()};
  }

  // POST /api/runs/stop: an empty body or a JSON object (the page sends {}).
  web::Response stop_request(const std::string& body) {
    if (!body.empty() && !nlohmann::json::parse(body, nullptr, false).is_object())
      return error(400, "the body of a stop must be empty or a JSON object");
    return stop("stopped from the web page");
  }

  web::Response stop(const std::string& why) {
    if (!running()) return error(409, "no run is running");
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

  // A capture that cannot be written (a full disk) aborts the run, naming the file.
  void watch_capture() {
    if (!capture_->recorder) return;
    capture_->recorder->on_failure([this](const std::string& e) {
      boost::asio::post(io_, [this, e] {
        if (running()) stop("capture failed: " + e);
      });
    });
  }

  void start_linear() {
    const auto specs = linear_specs(config_);
    const auto path = capture_path();
    capture_ = std::make_unique<SessionCapture>(path, config_, specs);
    watch_capture();
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
    watch_capture();
    CircleRunSetup setup{.config = config_,
                         .program = program,
                         .analysis = analysis,
                         .database = database_path(o_.run.db),
                         .ballbar = make_instrument(
                             io_, specs[0], make_transport(io_, dc),
                             instrument_options(dc, specs[0], o_.run, capture_->recorder.get())),
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
    // A linear run that reached its end with stops missed is evaluated but not complete.
    const bool complete = linear_ ? linear_->outcome().status == cal::storage::RunStatus::complete
                                  : circle_->outcome().complete;
    const bool evaluated = linear_ ? linear_->outcome().complete : circle_->outcome().complete;
    const std::string reason = linear_ ? linear_->outcome().reason : circle_->outcome().reason;
    last_ = nlohmann::json{
        {"run", run_id_}, {"test", test_}, {"complete", complete}, {"reason", reason}};
    if (capture_ && capture_->recorder) capture_->recorder->close();
    const char* how = complete ? "complete" : evaluated ? "incomplete: " : "stopped: ";
    fmt::print("run {} {}{}\n", run_id_, how, reason);
    std::fflush(stdout);
    linear_.reset(), circle_.reset(), capture_.reset();
    publish_idle(fmt::format("run {} {}{}", run_id_, how, reason));
  }

  void tick() {
    check_.expires_after(200ms);
    check_.async_wait([this](const boost::system::error_code& ec) {
      if (ec) return;
      if ((linear_ && linear_->finished()) || (circle_ && circle_->finished())) finish();
      if (capture_ && capture_->recorder) capture_->recorder->flush();
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
  // Nothing a handler throws ends the service: the loop is run again after the run in
  // progress (if any) is ended with the reason (asio allows run() again after an exception).
  for (;;) {
    try {
      io.run();
      return;
    } catch (const std::exception& e) {
      service.failed(e.what());
    }
  }
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
  cmd->add_option("--allow-host", o->allowed_hosts,
                  "A Host name accepted beside localhost and the address (repeatable), e.g. the "
                  "machine's name when serving beyond loopback");
  cmd->add_option("--max-connections", o->max_connections,
                  "Open connections at most (at the cap the one idle longest is closed)")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{4}, std::size_t{100000}));
  cmd->add_option("--request-timeout-s", o->request_timeout_s,
                  "A request must arrive within this (idle and slow connections are closed)")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--capture-dir", o->capture_dir, "Record each run's capture in this directory");
  cmd->add_option("--give-up-after", o->run.give_up_after,
                  "Reconnection attempts before a device is given up")
      ->capture_default_str();
  cmd->add_option("--check-s", o->run.check_s,
                  "At start, every configured device must open and speak within this time (0: "
                  "no check)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->callback([o] { serve(*o); });
}

}  // namespace daq
