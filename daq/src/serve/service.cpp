// daq serve: the operator's page, its API and the runs (see service.hpp and docs/web.md).
#include "serve/service.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/daq/gcode.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/storage/store.hpp"
#include "circle_run.hpp"
#include "compensate_run.hpp"
#include "database.hpp"
#include "devices_list.hpp"
#include "json_input.hpp"
#include "kinds/kind.hpp"
#include "linear_run.hpp"
#include "part_program.hpp"
#include "provenance.hpp"
#include "report/report.hpp"
#include "report_pdf.hpp"
#include "result_rows.hpp"
#include "run_document.hpp"
#include "serve/ballbar_set.hpp"
#include "serve/device_allow.hpp"
#include "serve/device_board.hpp"
#include "serve/instrument_form.hpp"
#include "serve/live_trace.hpp"
#include "serve/model_view.hpp"
#include "serve/setup_form.hpp"
#include "serve/volumetric_checklist.hpp"
#include "sim_shop.hpp"
#include "unit_signs.hpp"
#include "web/assets.hpp"
#include "web/server.hpp"

namespace daq::serve {
namespace {

namespace web = cal::daq::web;
namespace fs = std::filesystem;
using nlohmann::json;
using namespace std::chrono_literals;

// Error bodies: JSON even when a message carries bytes that are not UTF-8 (a path, a device).
web::Response error(int status, const std::string& message, json extra = json::object()) {
  extra["error"] = message;
  return {status, extra.dump(-1, ' ', false, json::error_handler_t::replace)};
}
web::Response ok(const json& j, int status = 200) {
  return {status, j.dump(-1, ' ', false, json::error_handler_t::replace)};
}

// A request body as JSON, its nesting bounded before anything recurses into it (json_input.hpp:
// a body nested 100 000 deep would crash whatever dumps or copies it); discarded when it is
// not JSON or too deep, so each endpoint answers 400 with its own reason.
json parse_body(const std::string& body) {
  try {
    cal::daq::check_json_depth(body, "request body");
  } catch (const cal::InputError&) {
    return json(json::value_t::discarded);
  }
  return json::parse(body, nullptr, false);
}

// The body of POST /api/runs/start: exactly {"test": "linear"} or {"test": "circle"}.
std::optional<std::string> requested_test(const std::string& body, std::string& why) {
  const auto req = parse_body(body);
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

// The set-up of a POST body {"setup": {...}, ...}; the other keys allowed are named.
std::optional<json> setup_body(const std::string& body, std::initializer_list<const char*> others,
                               std::string& why) {
  const auto req = parse_body(body);
  if (req.is_discarded() || !req.is_object()) {
    why = "the body must be a JSON object {\"setup\": {...}}";
    return std::nullopt;
  }
  for (const auto& [key, v] : req.items()) {
    const bool known = key == "setup" || std::any_of(others.begin(), others.end(),
                                                     [&](const char* k) { return key == k; });
    if (!known) {
      why = fmt::format("unknown key \"{}\"", key);
      return std::nullopt;
    }
  }
  if (!req.contains("setup") || !req["setup"].is_object()) {
    why = "\"setup\" must be an object (the set-up, caldaq.setup.v1)";
    return std::nullopt;
  }
  return req["setup"];
}

// A string field of a request, or `fallback` when absent; a value of another type, or one
// `valid` refuses (cal::InputError), is refused naming the field.
template <typename Check>
std::optional<std::string> string_field(const json& req, const char* key, const char* fallback,
                                        Check valid, std::string& why) {
  const auto it = req.find(key);
  if (it == req.end()) return fallback;
  if (!it->is_string()) {
    why = fmt::format("\"{}\" must be a string, not {}", key, it->type_name());
    return std::nullopt;
  }
  const auto value = it->get<std::string>();
  try {
    valid(value);
  } catch (const cal::InputError& e) {
    why = fmt::format("\"{}\": {}", key, e.what());
    return std::nullopt;
  }
  return value;
}

// The (id, transport) of each device of a set-up as the page sends it; entries that are not
// objects with a string transport are the loader's to refuse.
std::vector<std::pair<std::string, std::string>> devices_in_setup(const json& setup) {
  std::vector<std::pair<std::string, std::string>> out;
  const auto devices = setup.find("devices");
  if (devices == setup.end() || !devices->is_object()) return out;
  for (const auto& [id, d] : devices->items())
    if (d.is_object() && d.contains("transport") && d["transport"].is_string())
      out.emplace_back(id, d["transport"].get<std::string>());
  return out;
}

std::vector<std::pair<std::string, std::string>> devices_of(const cal::daq::Config& c) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& d : c.devices) out.emplace_back(d.id, d.transport);
  return out;
}

// The linear test kinds the set-up's instruments can measure (kinds/kind.hpp): positioning and
// angular with a laser (an angular test's beams are checked at Start against the laser's axes),
// straightness with an indicator, roll with a level, a rotary axis's positioning with an
// angular reference (its stops are the reference's: no laser).
std::vector<std::string> linear_kinds(const cal::daq::Config& c) {
  std::vector<std::string> out;
  const bool laser = c.device_for("laser") != nullptr;
  if (laser) out.push_back("positioning");
  if (laser && c.device_for("indicator")) out.push_back("straightness");
  if (laser) out.push_back("angular");
  if (laser && c.device_for("level")) out.push_back("roll");
  if (c.device_for("angle")) out.push_back("rotary");
  return out;
}

// "run-12.html" -> 12 with the extension; nullopt for anything else.
std::optional<std::pair<std::int64_t, std::string>> report_name(std::string_view name) {
  if (!name.starts_with("run-")) return std::nullopt;
  const auto dot = name.rfind('.');
  if (dot == std::string_view::npos) return std::nullopt;
  const auto ext = name.substr(dot + 1);
  if (ext != "html" && ext != "pdf") return std::nullopt;
  std::int64_t id = 0;
  const auto digits = name.substr(4, dot - 4);
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), id);
  if (ec != std::errc{} || end != digits.data() + digits.size() || id < 1) return std::nullopt;
  return std::pair{id, std::string(ext)};
}

// The capture directory, created at start; refused (naming it and why) when it cannot be
// created or written.
void prepare_capture_dir(const std::string& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw cal::InputError(fmt::format("--capture-dir {}: cannot be created: {}", dir,
                                      ec ? ec.message() : "not a directory"));
  const auto probe = fs::path(dir) / fmt::format(".caldaq-write-test-{}", ::getpid());
  {
    std::ofstream out(probe);
    if (!(out << "x") || !(out.flush()))
      throw cal::InputError(fmt::format("--capture-dir {}: cannot be written", dir));
  }
  fs::remove(probe, ec);
}

class Service {
 public:
  Service(boost::asio::io_context& io, ServeOptions o)
      : io_(io),
        o_(std::move(o)),
        tick_(io),
        publish_timer_(io),
        program_timer_(io),
        allowed_(o_.allowed_devices) {
    prepare_capture_dir(o_.capture_dir);
    if (o_.simulate) {
      // The shop, the instruments' timers and the runs' timers on one simulated time line
      // (cal/drivers/loop_time.hpp), paced at `speed` times the wall clock for the person
      // watching; the page's own timers stay on the wall clock.
      cal::drivers::VirtualTime::install(io_).pace(o_.speed);
      // The truth of `daq sim --test circle-set` (squareness in XY, ZX and YZ; X's linear
      // errors as the default shop's) with X's roll, pitch and yaw and a vibration of Y
      // (ShopTruth::served): a ballbar set on the page shows real diagnostics in every plane,
      // and its angular and roll tests read known non-zero rotations.
      shop_ = std::make_unique<SimulatedShop>(io_, ShopTruth::served(), o_.speed);
      o_.run.clock = shop_->clock_ns();
      o_.run.poll_scale = 1.0;  // the instruments' timers wait in simulated time
      const auto text = simulated_shop_config(*shop_, {.speed = o_.speed, .in_process = true});
      use_config(cal::daq::parse_config(text, "simulated shop"));
      for (const auto& d : config_.devices) twins_.push_back(device_address(d.transport));
    } else {
      use_config(cal::daq::load_config(o_.run.config));
      check_devices_at_start();
    }
    allowed_.allow_devices_of(config_);  // the devices it started with, and no others
    try {
      make_server();
    } catch (const std::invalid_argument& e) {
      throw cal::InputError(e.what());
    } catch (const std::runtime_error& e) {
      // The address or port given (or the default) is taken or not ours: the user's to
      // change, a usage error (status 2) as a bad value is.
      throw cal::InputError(fmt::format("{} (--address, --port)", e.what()));
    }
    tick();
    publish_loop();
  }

  std::uint16_t port() const { return server_->port(); }
  std::string source() const { return o_.simulate ? "the simulated shop" : o_.run.config; }

  void shutdown() {
    if (running()) stop("the service was stopped");
    tick_.cancel();
    publish_timer_.cancel();
    program_timer_.cancel();
    monitors_.clear();
    join_workers();
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
      start_monitors();
    }
  }

 private:
  bool running() const { return linear_ || circle_; }

  // --check-s S > 0: the devices of the configured tests open and speak before the service
  // starts, or it is refused naming the device (as daq run checks before a run).
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

  void make_server() {
    web::Api api{.page =
                     [](std::string_view nonce) {
                       return web::operator_page(nonce, ::daq::unit_signs_json());
                     },
                 .runs = [this] { return runs(); },
                 .status = [this] { return ok(status_with_seq()); },
                 .start = [this](const std::string& body) { return start(body); },
                 .stop = [this](const std::string& body) { return stop_request(body); }};
    const auto get = [&](std::string path, auto handler) {
      api.routes.push_back(
          {"GET", std::move(path), [this, handler](std::string_view p, const std::string&) {
             return (this->*handler)(p);
           }});
    };
    const auto post = [&](std::string path, auto handler) {
      api.routes.push_back(
          {"POST", std::move(path), [this, handler](std::string_view, const std::string& body) {
             return (this->*handler)(body);
           }});
    };
    // The operator's control of a linear run: POST /api/runs/capture, skip, retry, pause, resume.
    for (const auto c :
         {Control::capture, Control::skip, Control::retry, Control::pause, Control::resume})
      api.routes.push_back({"POST", fmt::format("/api/runs/{}", to_string(c)),
                            [this, c](std::string_view, const std::string& body) {
                              return control_request(c, body);
                            }});
    get("/api/setup", &Service::setup_get);
    get("/api/devices", &Service::devices);
    get("/api/drivers", &Service::drivers);
    get("/api/detected", &Service::detected);
    get("/api/machines", &Service::machines);
    get("/api/volumetric", &Service::volumetric);
    get("/api/model", &Service::model);
    get("/api/live/trace", &Service::live_trace);
    get("/api/runs/", &Service::run_doc);
    get("/reports/", &Service::report);
    post("/api/setup/check", &Service::setup_check);
    post("/api/setup/program", &Service::setup_program);
    post("/api/setup/apply", &Service::setup_apply);
    post("/api/compensation", &Service::compensation);
    if (o_.simulate) post("/api/simulation/speed", &Service::simulation_speed);
    server_ = std::make_unique<web::LiveServer>(io_, server_options(o_), std::move(api));
  }

  // --- the set-up and the idle instruments --------------------------------------------------

  // A new set-up: a new board, and its devices watched while no run is running.
  void use_config(cal::daq::Config c) {
    monitors_.clear();
    config_ = std::move(c);
    board_ = std::make_shared<DeviceBoard>(config_);
    setup_summary_ = summary_of(config_, ++setup_version_);
    start_monitors();
  }

  // What Start runs, for the page's Run view (in every status: a set-up applied from another
  // page shows at once): each test's axis or plane, range, targets, runs and instruments; the
  // version counts the set-ups applied, so a page knows its form's base is outdated.
  static json summary_of(const cal::daq::Config& c, int version) {
    json j{{"version", version}, {"instruments", json::array()}};
    for (const auto& d : c.devices)
      j["instruments"].push_back(
          {{"id", d.id}, {"driver", d.driver}, {"role", d.role}, {"origin", d.origin}});
    const auto instruments_of = [&](std::string_view test) {
      json ids = json::array();
      for (const auto& d : c.devices)
        if (run_uses(c, test, d)) ids.push_back(d.id);
      return ids;
    };
    if (c.linear) {
      const auto& l = *c.linear;
      json t{{"axis", l.axis},
             {"first_mm", l.first_mm},
             {"last_mm", l.last_mm},
             {"runs", l.runs},
             {"bidirectional", l.bidirectional},
             {"cycle", l.cycle},
             {"feed_mm_per_min", l.feed_mm_per_min},
             {"instruments", instruments_of("linear")}};
      try {  // what it measures: the Run view names the kind, not only "linear"
        const auto& kind = kinds::kind(l.measure.kind);
        t["kind"] = kind.name();
        t["component"] = kind.component(l);
        t["rotary"] = kind.stops_from_probe();
        const auto plan = linear_plan(l);
        t["targets"] = plan.targets_mm.size();
        t["stops"] = std::count_if(plan.moves.begin(), plan.moves.end(), [](const auto& m) {
          return m.kind == cal::iso230_2::MoveKind::measure;
        });
      } catch (const cal::InputError& e) {
        t["problem"] = e.what();  // Start names it too
      }
      j["linear"] = std::move(t);
    }
    if (c.circle) {
      j["circle"] = {{"plane", c.circle->plane},
                     {"radius_mm", c.circle->radius_mm},
                     {"feed_mm_per_min", c.circle->feed_mm_per_min},
                     {"instruments", instruments_of("circle")}};
      try {  // a set's tests in the order Start runs them (one for a single test)
        j["circle"]["tests"] = set_plan_json(circle_tests(c));
      } catch (const cal::InputError& e) {
        j["circle"]["problem"] = e.what();
      }
    }
    return j;
  }

  // Every configured device is opened while idle, so the page shows its state and values and
  // the environment settles in view; a run closes those it uses and opens its own (its capture
  // holds each device's bytes from the connection on, as `daq replay` needs), and they are
  // watched again when it ends (only_of_test: the devices of that test; empty: all, anew).
  void start_monitors(std::string_view only_of_test = {}) {
    if (only_of_test.empty()) monitors_.clear();
    const int axis = config_.linear && config_.linear->axis == "Y"   ? 1
                     : config_.linear && config_.linear->axis == "Z" ? 2
                                                                     : 0;
    std::uint16_t n = 0;
    for (const auto& dc : config_.devices) {
      if (!only_of_test.empty() && !run_uses(config_, only_of_test, dc)) {
        ++n;
        continue;
      }
      try {
        const auto spec = spec_of(dc, n++, axis);
        auto opt = instrument_options(dc, spec, o_.run, nullptr);
        opt.backoff.max_attempts = -1;  // idle: wait for the device however long it takes
        // The page needs about 10 values a second, not the run's rate.
        opt.poll_period = std::max(opt.poll_period, std::chrono::microseconds(100ms));
        // A ballbar sends nothing until it is mounted and moving: silence is no fault here.
        if (dc.role == "ballbar") opt.silence_timeout = 24h;
        board_->expect(dc.id,
                       std::chrono::duration_cast<std::chrono::milliseconds>(opt.poll_period), -1);
        auto inst =
            watched(make_instrument(io_, spec, make_transport(io_, dc), opt), dc.id, board_);
        inst->start({});
        monitors_[dc.id] = std::move(inst);
      } catch (const std::exception& e) {
        board_->on_failed(dc.id, e.what());
      }
    }
  }

  // Closes the idle monitors of the devices the run opens; the others stay watched.
  void stop_monitors_of(std::string_view test) {
    for (const auto& dc : config_.devices)
      if (run_uses(config_, test, dc)) monitors_.erase(dc.id);
  }

  web::Response setup_get(std::string_view) {
    const auto setup = setup_of(config_);
    auto check = check_setup(setup);
    json standards = json::array();
    for (const auto& s : cal::iso230_2::standards())
      standards.push_back({{"key", s.key}, {"title", s.title}});
    return ok({{"schema", "caldaq.setup-state.v1"},
               {"setup", setup},
               {"toml", check.toml},
               {"check", to_json(check)},
               {"source", source()},
               {"version", setup_version_},
               {"simulated", o_.simulate},
               {"choices",
                {{"standards", standards},
                 {"dialects", {"fanuc", "heidenhain", "siemens"}},
                 {"cycles", {"linear", "pendulum", "pilgrim-step"}},
                 {"equations", {"ciddor", "edlen", "shop-floor"}},
                 // A rotary test's axis too (A, B, C): the loader refuses an axis its kind
                 // does not measure (the form of a rotary set-up lost its axis C).
                 {"axes", {"X", "Y", "Z", "A", "B", "C"}},
                 {"kinds", linear_kinds(config_)},
                 {"directions", {"X", "Y", "Z", "A", "B", "C"}},
                 {"planes", {"XY", "YZ", "ZX"}}}}});
  }

  web::Response setup_check(const std::string& body) {
    std::string why;
    const auto setup = setup_body(body, {}, why);
    if (!setup) return error(400, why);
    auto check = check_setup(*setup);
    // A device the service may not open is a problem at its field, as the loader's are.
    for (const auto& [id, transport] : devices_in_setup(*setup))
      if (const auto refused = allowed_.refusal({{id, transport}}))
        check.problems.push_back({refused->device + ".transport", refused->message});
    auto j = to_json(check);
    j["toml"] = check.toml;
    // The kinds the form's instruments can measure: the page offers these while the operator
    // edits (the applied set-up's kinds would offer a roll test with the level removed).
    if (check.config) j["kinds"] = linear_kinds(*check.config);
    return ok(j);
  }

  // POST {"setup", "test": "linear" | "circle", "dialect": "fanuc" | ...}: the part program
  // (text/plain), the same text `daq gcode` writes for the set-up's TOML.
  web::Response setup_program(const std::string& body) {
    std::string why;
    const auto setup = setup_body(body, {"test", "dialect"}, why);
    if (!setup) return error(400, why);
    const auto req = parse_body(body);  // setup_body accepted it: an object
    const auto test = string_field(
        req, "test", "linear",
        [](const std::string& t) {
          if (t != "linear" && t != "circle")
            throw cal::InputError(fmt::format("no test '{}': give \"linear\" or \"circle\"", t));
        },
        why);
    if (!test) return error(400, why);
    const auto dialect = string_field(
        req, "dialect", "fanuc", [](const std::string& d) { cal::daq::dialect_from_string(d); },
        why);
    if (!dialect) return error(400, why);
    const auto check = check_setup(*setup);
    if (!check.config) return error(400, "the set-up has problems: fix them first", to_json(check));
    try {
      return {.body = part_program(*check.config, *test, *dialect),
              .content_type = "text/plain; charset=utf-8"};
    } catch (const cal::InputError& e) {
      return error(400, e.what());
    }
  }

  // POST {"setup"}: the set-up becomes the service's (its devices are opened, the page's runs
  // use it). Refused while a run is running, and (403, before anything is opened) when it
  // names a device the service may not open (device_allow.hpp).
  web::Response setup_apply(const std::string& body) {
    std::string why;
    const auto setup = setup_body(body, {}, why);
    if (!setup) return error(400, why);
    if (const auto refused = allowed_.refusal(devices_in_setup(*setup)))
      return device_refused(*refused);
    if (running())
      return error(409, fmt::format("run {} is running: the set-up can change after it", run_id_));
    auto check = check_setup(*setup);
    if (!check.config) return error(400, "the set-up has problems: fix them first", to_json(check));
    // The loader's devices, as they would be opened (the same texts; checked again all the same).
    if (const auto refused = allowed_.refusal(devices_of(*check.config)))
      return device_refused(*refused);
    keep_twins_simulated(*check.config);
    use_config(std::move(*check.config));
    fmt::print("set-up applied from the web page\n");
    std::fflush(stdout);
    auto j = to_json(check);
    j["toml"] = check.toml;
    j["version"] = setup_version_;
    return ok(j);
  }

  // "serial /dev/pts/3 4800 7E1" -> "serial /dev/pts/3": the device whatever its line settings.
  static std::string device_address(std::string_view transport) {
    const auto kind = transport.find(' ');
    const auto end = kind == std::string_view::npos ? kind : transport.find(' ', kind + 1);
    return std::string(transport.substr(0, end));
  }

  // A set-up applied from the page that names the simulated shop's twins reads simulated
  // instruments, whatever the page sent: its runs must not be stored as real measurements.
  void keep_twins_simulated(cal::daq::Config& c) const {
    for (auto& d : c.devices)
      if (std::find(twins_.begin(), twins_.end(), device_address(d.transport)) != twins_.end())
        d.origin = "simulated";
  }

  static web::Response device_refused(const DeviceRefusal& r) {
    fmt::print(stderr, "daq serve: set-up refused: {}\n", r.message);
    return error(403, r.message,
                 {{"device", r.device}, {"transport", r.transport}, {"allow", r.allow}});
  }

  // The run database for a read: opened read-only (never created, migrated or changed: a
  // mistyped --db creates nothing, and a read-only medium works); nullopt while there is no
  // database yet (no run stored).
  std::optional<cal::storage::Store> read_store() const {
    std::error_code ec;
    if (!fs::exists(database_path(o_.run.db), ec)) return std::nullopt;
    return open_database_read_only(o_.run.db);
  }

  static RunOrigin origin_in(const cal::storage::RunReader& db, const cal::storage::RunRecord& r) {
    const auto machine = db.machine(r.machine_id);
    return run_origin(r, db.instruments(r.id), machine ? machine->name : "");
  }

  // Where the run's readings come from, as stored with its instruments when it started
  // (docs/storage.md, "Origin"): the page says SIMULATED or REPLAYED from this, not from
  // --simulate or the set-up's names. {"label": "", ...} for real instruments.
  json stored_origin(std::int64_t id) const {
    try {
      const auto db = read_store();
      const auto run = db ? db->run(id) : std::nullopt;
      return run ? to_json(origin_in(*db, *run)) : json(nullptr);
    } catch (const std::exception& e) {
      fmt::print(stderr, "daq serve: run {}: its origin could not be read: {}\n", id, e.what());
      return nullptr;
    }
  }

  std::string no_database() const {
    return fmt::format("no database at {} yet (the first run creates it)",
                       database_path(o_.run.db).string());
  }

  // POST /api/simulation/speed {"speed": N} (--simulate only): the SIMULATED shop's pace from
  // now on, 1 .. 100 times the wall clock as --speed. The simulated time line is unchanged (it
  // only moves from event to event): a run's readings and results do not depend on it.
  web::Response simulation_speed(const std::string& body) {
    const auto j = parse_body(body);
    if (!j.is_object() || j.size() != 1 || !j.contains("speed") || !j["speed"].is_number())
      return error(400, "the body must be {\"speed\": N} with N from 1 to 100");
    const double speed = j["speed"].get<double>();
    if (!(speed >= 1.0 && speed <= 100.0))
      return error(400, fmt::format("speed {}: the SIMULATED shop runs 1 to 100 times faster "
                                    "than real time",
                                    speed));
    o_.speed = speed;
    cal::drivers::VirtualTime::of(io_)->pace(speed);
    fmt::print("daq serve: SIMULATED shop now {}x faster than real time\n", speed);
    std::fflush(stdout);
    return ok(json{{"speed", speed}});
  }

  web::Response devices(std::string_view) { return ok(board_->to_json()); }
  // The live circle's whole polar trace, for a page that missed some of its new points.
  web::Response live_trace(std::string_view) {
    if (circle_live_.empty()) return error(404, "no circle run has a live trace");
    return ok(circle_live_.whole());
  }
  web::Response drivers(std::string_view) { return ok(driver_descriptions()); }
  web::Response detected(std::string_view) { return ok(list_devices({})); }

  // The machines of the stored runs, newest first, as their runs recorded them.
  web::Response machines(std::string_view) {
    json list = json::array();
    const auto db = read_store();
    if (!db) return ok({{"schema", "caldaq.machines.v1"}, {"machines", list}});
    const auto& store = *db;
    std::map<std::string, bool> seen;
    auto runs = store.runs();
    for (auto it = runs.rbegin(); it != runs.rend(); ++it) {
      const auto settings = json::parse(it->settings_json, nullptr, false);
      json m = settings.is_object() && settings.contains("context")
                   ? settings["context"].value("machine", json::object())
                   : json::object();
      if (!m.is_object() || !m.contains("name")) {
        const auto rec = store.machine(it->machine_id);
        if (!rec) continue;
        m = {{"name", rec->name}, {"description", rec->description}};
      }
      const auto name = m.value("name", std::string());
      if (name.empty() || seen[name]) continue;
      seen[name] = true;
      m["last_run"] = it->id;
      list.push_back(m);
    }
    return ok({{"schema", "caldaq.machines.v1"}, {"machines", list}});
  }

  // GET /api/volumetric: the 21-error campaign of the set-up's machine as a checklist, from the
  // store (volumetric_checklist.hpp): what is measured, by which run and when, what is left.
  web::Response volumetric(std::string_view) {
    const auto db = read_store();
    return ok(volumetric_checklist(db ? &*db : nullptr, config_.machine_name,
                                   database_path(o_.run.db).string()));
  }

  // GET /api/model: the set-up's machine's model built from the store as `daq model build`
  // builds it (missing errors allowed and listed) and its map (model_view.hpp); nothing written.
  web::Response model(std::string_view) {
    const auto db = read_store();
    return ok(model_view(db ? &*db : nullptr, config_.machine_name));
  }

  // --- stored runs and reports -----------------------------------------------------------

  web::Response runs() {
    json list = json::array();
    const auto db = read_store();
    if (db)
      for (const auto& r : db->runs()) {
        // Where its readings came from ("SIMULATED", "REPLAYED", ...; "" for real instruments):
        // the list shows it beside every run, as everything derived from a run does.
        const auto origin = origin_in(*db, r);
        list.push_back({{"id", r.id},
                        {"kind", r.kind},
                        {"axis", r.axis},
                        {"campaign", r.campaign},
                        {"status", cal::storage::to_string(r.status)},
                        {"started_unix_ms", r.started_unix_ms},
                        {"note", r.note},
                        {"origin", origin.label()}});
      }
    return ok({{"schema", "caldaq.runs.v1"}, {"runs", list}});
  }

  // GET /api/runs/N: the run as `daq show N --json` gives it, with its report links.
  web::Response run_doc(std::string_view path) {
    const auto digits = path.substr(std::string_view("/api/runs/").size());
    std::int64_t id = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), id);
    if (ec != std::errc{} || end != digits.data() + digits.size() || id < 1)
      return error(404, "no such resource: runs are /api/runs/N");
    const auto db = read_store();
    if (!db) return error(404, fmt::format("no run {}: {}", id, no_database()));
    const auto& store = *db;
    if (!store.run(id)) return error(404, fmt::format("no run {}", id));
    auto j = run_document(store, id);
    // The page's plot of the stops and its tables: the stored stops, and each result's rows
    // as the terminal and the report list them (result_rows.hpp).
    j["stops"] = json::array();
    for (const auto& t : store.targets(id))
      j["stops"].push_back({{"target_index", t.target_index},
                            {"run", t.run_number},
                            {"direction", t.direction == '+' ? "up" : "down"},
                            {"nominal_mm", t.nominal_mm},
                            {"deviation_um", t.deviation_um}});
    for (auto& r : j["results"])
      if (r["result"].is_object()) r["values"] = rows_json(result_rows(r["result"]));
    // A circle's polar plot: its two traces, a point per degree (bounded, docs/web.md).
    if (const auto run = store.run(id); run && run->kind == "circle") {
      const json* current = nullptr;
      for (const auto& r : j["results"])
        if (r.value("current", false) && r["result"].is_object()) current = &r["result"];
      try {
        j["trace"] = current
                         ? circle_trace_json(store, id, json::parse(run->settings_json), *current)
                         : json(nullptr);
      } catch (const std::exception& e) {
        j["trace"] = {{"error", e.what()}};
      }
    }
    j["reports"] = {{"html", fmt::format("/reports/run-{}.html", id)},
                    {"pdf", fmt::format("/reports/run-{}.pdf", id)}};
    return ok(j);
  }

  // POST /api/compensation {"run": N, "format": "fanuc"}: the compensation table of a stored
  // linear run as `daq compensate` writes it, through the same code (compensate_run.hpp);
  // with "store": true also stored with the run as the command stores it (for daq verify).
  // 400 for a bad body or format, 404 for no such run, 409 with the command's refusal (a
  // suspect run, too few targets, not a linear run), 500 when the store cannot be written.
  web::Response compensation(const std::string& body) {
    const auto j = json::parse(body, nullptr, false);
    const bool store = j.is_object() && j.contains("store");
    const bool good = j.is_object() && j.size() == (store ? 3u : 2u) && j.contains("run") &&
                      j["run"].is_number_integer() && j.contains("format") &&
                      j["format"].is_string() && (!store || j["store"].is_boolean());
    if (!good)
      return error(400,
                   R"(the body must be {"run": N, "format": "csv"} and optionally "store": true)");
    const auto id = j["run"].get<std::int64_t>();
    const auto format = j["format"].get<std::string>();
    try {
      cal::comptable::format_meaning(format);
    } catch (const cal::InputError& e) {
      return error(400, e.what());
    }
    const auto db = read_store();
    if (!db) return error(404, fmt::format("no run {}: {}", id, no_database()));
    if (!db->run(id)) return error(404, fmt::format("no run {}", id));
    try {
      // "store": true stores the table with the run as `daq compensate --run` does (daq verify).
      return ok(run_compensation(*db, id, format,
                                 store && j["store"].get<bool>() ? &o_.run.db : nullptr));
    } catch (const cal::InputError& e) {
      return error(409, e.what());
    } catch (const std::exception& e) {
      return error(500, fmt::format("the compensation could not be stored: {}", e.what()));
    }
  }

  // GET /reports/run-N.html | .pdf: the run's report as `daq report N` writes it. The HTML is
  // made here (PLplot is not thread-safe); the PDF is printed by headless Chromium on a worker
  // thread, so the event loop (and a run) goes on meanwhile.
  web::Response report(std::string_view path) {
    const auto name = report_name(path.substr(std::string_view("/reports/").size()));
    if (!name) return error(404, "no such report: reports are /reports/run-N.html or .pdf");
    const auto [id, ext] = *name;
    const auto db = read_store();
    if (!db) return error(404, fmt::format("no run {}: {}", id, no_database()));
    const auto& store = *db;
    if (!store.run(id)) return error(404, fmt::format("no run {}", id));
    auto html =
        cal::daq::report::run_report(store, id, {.software = std::string(daq::software_version)});
    if (ext == "html")
      return {.body = std::move(html),
              .content_type = "text/html; charset=utf-8",
              .disposition = fmt::format("inline; filename=\"report-run-{}.html\"", id),
              // An inert document (docs/web.md): no script runs in it whatever a name holds.
              .content_security_policy = std::string(web::inert_document_policy)};
    if (printing_ >= 2) return error(503, "two PDFs are being printed: try again in a moment");
    if (printing_ == 0) join_workers();  // the threads of earlier PDFs have all ended
    web::Response r;
    r.deferred = [this, id, html = std::move(html)](std::function<void(web::Response)> done) {
      ++printing_;
      std::lock_guard lock(workers_mutex_);
      workers_.emplace_back([this, id, html, done] {  // NOLINT: the thread owns its copies
        done(print_report(id, html));
        --printing_;
      });
    };
    return r;
  }

  static web::Response print_report(std::int64_t id, const std::string& html) {
    char dir_template[] = "/tmp/caldaq-report-XXXXXX";
    const char* dir = ::mkdtemp(dir_template);
    if (!dir) return error(500, "cannot make a temporary directory for the PDF");
    const fs::path html_file = fs::path(dir) / fmt::format("report-run-{}.html", id);
    const fs::path pdf = fs::path(dir) / fmt::format("report-run-{}.pdf", id);
    web::Response r;
    try {
      std::ofstream(html_file, std::ios::binary) << html;
      print_pdf(html_file, pdf);
      std::ifstream in(pdf, std::ios::binary);
      std::ostringstream bytes;
      bytes << in.rdbuf();
      r = {.body = bytes.str(),
           .content_type = "application/pdf",
           .disposition = fmt::format("inline; filename=\"report-run-{}.pdf\"", id)};
    } catch (const std::exception& e) {
      r = error(500, e.what());
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    return r;
  }

  void join_workers() {
    std::lock_guard lock(workers_mutex_);
    for (auto& w : workers_)
      if (w.joinable()) w.join();
    workers_.clear();
  }

  // --- runs -------------------------------------------------------------------------------

  // Whether each test could start now, and why not.
  json readiness() const {
    json j = json::object();
    for (const char* test : {"linear", "circle"}) {
      std::optional<std::string> why;
      try {
        if (std::string_view(test) == "linear")
          linear_specs(config_);
        else
          ballbar_device(config_), circle_test(config_);
        why = simulation_limits(test);
        if (!why) why = board_->refusal(test);
      } catch (const cal::InputError& e) {
        why = e.what();
      }
      if (running()) why = fmt::format("run {} is running", run_id_);
      j[test] = {{"ready", !why}, {"why", why ? json(*why) : json(nullptr)}};
    }
    return j;
  }

  // What the simulated shop cannot do: its bar is 100 mm long. (A linear test of any kind and
  // axis: the shop is set up for it at Start, SimulatedShop::set_test.)
  std::optional<std::string> simulation_limits(std::string_view test) const {
    if (!shop_ || test != "circle" || !config_.circle) return std::nullopt;
    // One circle: in XY only (the shop's single-test program); a set: any planes, over the
    // sphere about the table ball as `daq sim --test circle-set` runs it.
    const auto tests = circle_tests(config_);
    const bool bar = std::all_of(tests.begin(), tests.end(), [&](const CircleTest& t) {
      return std::abs(t.program.radius_mm - shop_->truth().ballbar_mm) <= 1e-9;
    });
    if (!bar || (tests.size() == 1 && config_.circle->plane != "XY"))
      return fmt::format(
          "the simulated ballbar is {} mm long, a single test in the XY plane: set the "
          "circle's radius to {} mm and its plane to XY (or planes for a set)",
          shop_->truth().ballbar_mm, shop_->truth().ballbar_mm);
    return std::nullopt;
  }

  json status() const {
    json j{{"schema", "caldaq.status.v1"}, {"running", running()},   {"config", source()},
           {"simulated", o_.simulate},     {"tests", json::array()}, {"start", readiness()}};
    if (o_.simulate) j["speed"] = o_.speed;
    if (config_.linear) j["tests"].push_back("linear");
    if (config_.circle) j["tests"].push_back("circle");
    if (running()) j["run"] = {{"id", run_id_}, {"test", test_}, {"origin", run_origin_}};
    if (last_) j["last"] = *last_;
    if (set_) j["set"] = set_->to_json();
    j["setup"] = setup_summary_;
    return j;
  }

  // GET /api/status: the status and the version of the one last published (the page's, which
  // asks when its version is older than a message's; see publish_loop).
  json status_with_seq() const {
    json j = status();
    j["seq"] = status_seq_;
    return j;
  }

  // 400 for what the client got wrong (the body, a test the set-up lacks, a device that cannot
  // be opened); 409 while a run runs or a device it needs is not ready (the reason named);
  // 500 for the store or the capture failing.
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
        linear_specs(config_);
      else
        ballbar_device(config_), circle_test(config_);
    } catch (const cal::InputError& e) {
      return error(400, e.what());
    }
    if (const auto limit = simulation_limits(*test))
      return error(409, fmt::format("Start refused: {}", *limit));
    if (const auto refusal = board_->refusal(*test))
      return error(409, fmt::format("Start refused: {}", *refusal));
    stop_monitors_of(*test);  // the run opens them itself (its capture starts at the connection)
    run_live_.clear();
    circle_live_.clear();
    try {
      if (*test == "linear")
        start_linear();
      else
        start_circle();
    } catch (const cal::InputError& e) {
      abandon_start();
      return error(400, e.what());
    } catch (const std::exception& e) {
      abandon_start();
      return error(500, e.what());
    }
    test_ = *test;
    run_origin_ = stored_origin(run_id_);
    name_capture();
    if (shop_) start_program_when_ready(0);
    return {202, json{{"run", run_id_}, {"test", *test}}.dump()};
  }

  void abandon_start() {
    linear_.reset(), circle_.reset(), capture_.reset();
    capture_pending_.clear();
    start_monitors();
  }

  // POST /api/runs/stop: an empty body or a JSON object (the page sends {}).
  web::Response stop_request(const std::string& body) {
    if (!body.empty() && !parse_body(body).is_object())
      return error(400, "the body of a stop must be empty or a JSON object");
    return stop("stopped from the web page");
  }

  // POST /api/runs/{capture,skip,retry,pause,resume} (docs/web.md): an empty body or {}; 409
  // when there is no linear run or the action does not apply now (the reason named), else the
  // action done, in words, as the run records it.
  web::Response control_request(Control c, const std::string& body) {
    if (!body.empty()) {
      const auto req = parse_body(body);
      if (!req.is_object() || !req.empty())
        return error(400,
                     fmt::format("the body of /api/runs/{} must be empty or {{}}", to_string(c)));
    }
    if (!running()) return error(409, "no run is running");
    if (!linear_)
      return error(409, fmt::format("run {} is a circle test: capture, skip, retry, pause and "
                                    "resume are for linear runs (a circle has no stops)",
                                    run_id_));
    const auto out = linear_->control(c, "web page");
    if (!out.applied) {
      json extra{{"action", to_string(c)}};
      if (out.force_within_s > 0) extra["force_within_s"] = out.force_within_s;
      return error(409, out.message, extra);
    }
    fmt::print("  {} (from the web page)\n", out.message);
    std::fflush(stdout);
    return ok({{"run", run_id_}, {"action", to_string(c)}, {"message", out.message}});
  }

  web::Response stop(const std::string& why) {
    if (!running()) return error(409, "no run is running");
    if (linear_) linear_->stop(why);
    if (circle_) circle_->stop(why);
    finish();
    return {.body = json{{"stopped", last_->at("run")}}.dump()};
  }

  // The capture of a run is written under a temporary name (the run's number is known only
  // once it has begun) and renamed run-N.cdq at once; the run record names the final file.
  std::string capture_path() {
    if (o_.capture_dir.empty()) return {};
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count();
    capture_pending_ =
        (fs::absolute(o_.capture_dir) / fmt::format(".run-starting-{}.cdq", ms)).string();
    return capture_pending_;
  }

  void name_capture() {
    if (capture_pending_.empty()) return;
    const auto dir = fs::path(capture_pending_).parent_path();
    auto target = dir / fmt::format("run-{}.cdq", run_id_);
    if (fs::exists(target))  // another database's run N wrote here before
      target = dir / fmt::format("run-{}-{}.cdq", run_id_,
                                 fs::path(capture_pending_).stem().string().substr(14));
    std::error_code ec;
    fs::rename(capture_pending_, target, ec);
    if (!ec) {
      try {
        cal::storage::Store(database_path(o_.run.db)).set_capture_path(run_id_, target.string());
      } catch (const std::exception& e) {
        fmt::print(stderr, "daq serve: run {}: capture {}: {}\n", run_id_, target.string(),
                   e.what());
      }
    }
    capture_pending_.clear();
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

  RunOptions run_options() {
    RunOptions r = o_.run;
    r.wrap = [board = board_](const cal::daq::DeviceConfig& dc,
                              std::unique_ptr<cal::drivers::Instrument> inst) {
      return watched(std::move(inst), dc.id, board);
    };
    return r;
  }

  // With --simulate every instrument is a twin of the shop, whatever a set-up applied from the
  // page says of its devices: stored so, no renaming can make the run pass for a real one.
  void mark_simulated(Origins& origins) const {
    if (!o_.simulate) return;
    for (auto& [role, origin] : origins)
      origin = {"simulated", "a twin of the built-in simulated shop (daq serve --simulate)"};
  }

  void start_linear() {
    set_.reset();
    const auto specs = linear_specs(config_);
    const auto path = capture_path();
    capture_ = std::make_unique<SessionCapture>(path, config_, specs);
    watch_capture();
    // The simulated instruments set up for this test (its axis, optics, probe and the other
    // axes' positions), as the operator sets up the real ones before Start.
    if (shop_) shop_->set_test(*config_.linear);
    LinearRunSetup setup;
    setup.config = config_;
    setup.database = database_path(o_.run.db);
    setup.capture_path = capture_->absolute_path(path);
    add_linear_instruments(io_, config_, specs, run_options(), capture_->recorder.get(), setup);
    mark_simulated(setup.origins);
    setup.on_live = [this](const LiveState& s) { run_live_ = to_json_text(s); };
    setup.on_event = [](const std::string& e) { fmt::print("  {}\n", e); };
    linear_ = std::make_unique<LinearRun>(io_, std::move(setup));
    linear_->start();
    run_id_ = linear_->outcome().run_id;
    fmt::print("run {} (linear) started from the web page\n", run_id_);
    std::fflush(stdout);
  }

  // One test, or a set (planes, feeds, radii): the tests after the first follow on the same
  // bar stream, each stored as its own run, as `daq run circle` runs a set.
  void start_circle() {
    const auto tests = circle_tests(config_);
    const auto& first = tests.front();
    const auto& dc = ballbar_device(config_);
    const std::vector<InstrumentSpec> specs{spec_of(dc, 0)};
    const auto path = capture_path();
    capture_ = std::make_unique<SessionCapture>(path, config_, specs);
    watch_capture();
    const auto options = run_options();
    CircleRunSetup setup{
        .config = config_,
        .program = first.program,
        .analysis = first.analysis,
        .database = database_path(o_.run.db),
        .ballbar = options.wrap(dc, make_instrument(io_, specs[0], make_transport(io_, dc),
                                                    instrument_options(dc, specs[0], options,
                                                                       capture_->recorder.get()))),
        .capture_path = capture_->absolute_path(path),
        .origins = {{"ballbar", origin_of(specs[0].origin, "")}},
        .following = std::vector<CircleTest>(tests.begin() + 1, tests.end())};
    mark_simulated(setup.origins);
    setup.on_live = [this](const CircleLive& s) { circle_live_.update(s, run_id_); };
    setup.on_event = [](const std::string& e) { fmt::print("  {}\n", e); };
    circle_ = std::make_unique<CircleRun>(io_, std::move(setup));
    circle_->start();
    run_id_ = circle_->outcome().run_id;
    set_.reset();
    set_done_ = 0;
    if (tests.size() > 1) set_.emplace(tests);
    follow_set();
    fmt::print("run {} (circle) started from the web page\n", run_id_);
    std::fflush(stdout);
  }

  // The simulated machine starts the test's program once the run's instruments are ready, as
  // an operator presses Cycle Start once the acquisition waits (a program started while the
  // laser still connects would lose its first approach).
  void start_program_when_ready(int waited_ms) {
    program_timer_.expires_after(50ms);
    program_timer_.async_wait([this, waited_ms](const boost::system::error_code& ec) {
      if (ec || !running() || !shop_) return;
      const auto not_ready = board_->refusal(test_);
      if (not_ready && waited_ms < 15'000) return start_program_when_ready(waited_ms + 50);
      if (not_ready)
        fmt::print("  simulated machine: starting the program although {}\n", *not_ready);
      if (linear_) {
        const auto& l = *config_.linear;
        shop_->run_linear(linear_->plan(), l.feed_mm_per_min, l.dwell_s);
      } else if (set_) {  // the whole set in one program, the bar moved over the sphere
        std::vector<cal::daq::BallbarSetTest> program;
        for (const auto& t : circle_tests(config_)) program.push_back({t.plane, t.program});
        shop_->run_circle_set(program);
      } else {
        shop_->run_circle(circle_test(config_).first);
      }
      fmt::print("  simulated machine: {} program started\n", test_);
      std::fflush(stdout);
    });
  }

  // A run ends by itself (all stops, both arcs) or is stopped: keep its outcome, close its
  // capture, watch the devices again, and accept the next start.
  void finish() {
    program_timer_.cancel();
    // A linear run that reached its end with stops missed is evaluated but not complete.
    const bool complete = linear_ ? linear_->outcome().status == cal::storage::RunStatus::complete
                                  : circle_->outcome().complete;
    const bool evaluated = linear_ ? linear_->outcome().complete : circle_->outcome().complete;
    const std::string reason = linear_ ? linear_->outcome().reason : circle_->outcome().reason;
    // A linear run's end as stored: one that reached the end of its plan with a stop missed is
    // incomplete also when too few stops were left to evaluate (it read "aborted", i.e.
    // stopped, on the page while the store and the Results said "incomplete").
    const auto stored = linear_ ? linear_->outcome().status : cal::storage::RunStatus::running;
    const char* status = complete                                        ? "complete"
                         : evaluated                                     ? "incomplete"
                         : stored == cal::storage::RunStatus::incomplete ? "incomplete"
                                                                         : "aborted";
    follow_set();
    if (set_ && circle_) {
      const auto db = read_store_quietly();
      set_->end(status, reason, db ? &*db : nullptr);
    }
    last_ = json{{"run", run_id_},       {"test", test_},    {"complete", complete},
                 {"status", status},     {"reason", reason}, {"evaluated", evaluated},
                 {"origin", run_origin_}};
    if (capture_ && capture_->recorder) capture_->recorder->close();
    const char* how = complete ? "complete" : status[0] == 'i' ? "incomplete: " : "stopped: ";
    fmt::print("run {} {}{}\n", run_id_, how, reason);
    std::fflush(stdout);
    linear_.reset(), circle_.reset(), capture_.reset();
    start_monitors(test_);
  }

  // A set's progress: the run of the test in progress is the run the page shows; each test
  // done is read from the store once.
  void follow_set() {
    if (!circle_) return;
    run_id_ = circle_->outcome().run_id;
    if (!set_) return;
    std::vector<std::int64_t> done;
    for (const auto& c : circle_->completed()) done.push_back(c.run_id);
    const bool last_done = circle_->outcome().complete;
    if (last_done) done.push_back(circle_->outcome().run_id);
    const std::int64_t current = last_done ? 0 : run_id_;
    if (done.size() == set_done_) return set_->update(done, current, nullptr);
    set_done_ = done.size();
    const auto db = read_store_quietly();
    set_->update(done, current, db ? &*db : nullptr);
  }

  std::optional<cal::storage::Store> read_store_quietly() const {
    try {
      return read_store();
    } catch (const std::exception& e) {
      fmt::print(stderr, "daq serve: the ballbar set's runs could not be read: {}\n", e.what());
      return std::nullopt;
    }
  }

  void tick() {
    tick_.expires_after(200ms);
    tick_.async_wait([this](const boost::system::error_code& ec) {
      if (ec) return;
      if ((linear_ && linear_->finished()) || (circle_ && circle_->finished())) finish();
      if (circle_) follow_set();
      if (capture_ && capture_->recorder) capture_->recorder->flush();
      tick();
    });
  }

  // The page's state, 10 times a second (the server sends only the latest, and only when it
  // changed): the status, every device, and the run's live state (kept after it ends, so the
  // page still shows its last table).
  //
  // The status changes a few times a run (a start, a set's next test, the end) and weighed 1 to
  // 2.5 kB of every message: it is sent in the messages of the 0.4 s after each change (a page
  // skips a message or two at most while it keeps up) and every message names its version,
  // `status_seq`; a page whose version is older asks GET /api/status (with `seq`). Likewise a
  // circle's trace: its new points only (serve/live_trace.hpp).
  void publish_loop() {
    const auto now = LiveTraceFeed::Clock::now();
    if (std::string s = status().dump(); s != status_text_) {
      status_text_ = std::move(s);
      ++status_seq_;
      status_changed_ = now;
    }
    const bool with_status = now - status_changed_ < LiveTraceFeed::repeat_for;
    // The run's state as of now, beside the device board's newest readings: from the run's own
    // 100 ms tick it was up to 100 ms older than the laser's raw reading on the same page (at
    // 6000 mm/min and 2x a moving axis showed "Position 21.175" beside "raw 31.1810 mm").
    if (linear_) linear_->publish_live();
    const std::string run = !run_live_.empty()      ? run_live_
                            : !circle_live_.empty() ? circle_live_.page_json(now).dump()
                                                    : "null";
    std::string page = R"({"schema":"caldaq.page.v1","status_seq":)" + std::to_string(status_seq_) +
                       (with_status ? R"(,"status":)" + status_text_ : std::string()) +
                       R"(,"devices":)" +
                       board_->to_json().dump(-1, ' ', false, json::error_handler_t::replace) +
                       R"(,"run":)" + run + "}";
    server_->publish(std::move(page));
    publish_timer_.expires_after(100ms);
    publish_timer_.async_wait([this](const boost::system::error_code& ec) {
      if (!ec) publish_loop();
    });
  }

  boost::asio::io_context& io_;
  ServeOptions o_;
  boost::asio::steady_timer tick_, publish_timer_, program_timer_;
  std::unique_ptr<SimulatedShop> shop_;
  cal::daq::Config config_;
  std::shared_ptr<DeviceBoard> board_;
  std::map<std::string, std::unique_ptr<cal::drivers::Instrument>> monitors_;  // by device id
  std::unique_ptr<web::LiveServer> server_;
  std::unique_ptr<SessionCapture> capture_;
  std::string capture_pending_;
  std::unique_ptr<LinearRun> linear_;
  std::unique_ptr<CircleRun> circle_;
  std::optional<BallbarSetProgress> set_;  // a ballbar set's progress (kept after it ends)
  std::size_t set_done_ = 0;               // its tests whose stored values were read
  std::int64_t run_id_ = 0;
  std::string test_;
  std::string status_text_;  // the status last published, its version and when it changed
  std::uint64_t status_seq_ = 0;
  LiveTraceFeed::Clock::time_point status_changed_{};
  std::string run_live_;            // a linear run's live state
  LiveTraceFeed circle_live_;       // a circle run's
  json run_origin_;                 // stored_origin(run_id_) of the run in progress
  json setup_summary_;              // summary_of(config_): what Start runs
  std::vector<std::string> twins_;  // --simulate: the shop's devices (device_address)
  int setup_version_ = 0;
  std::optional<json> last_;
  DeviceAllowList allowed_;
  std::atomic<int> printing_{0};
  std::mutex workers_mutex_;
  std::vector<std::thread> workers_;
};

}  // namespace

web::ServerOptions server_options(const ServeOptions& o) {
  return {.address = o.address,
          .port = o.port,
          .token = o.token,
          .allowed_hosts = o.allowed_hosts,
          .max_connections = o.max_connections,
          .max_connections_per_client = o.max_connections_per_client,
          .request_timeout = std::chrono::milliseconds(std::llround(o.request_timeout_s * 1000.0)),
          .log = [](std::string_view text) { fmt::print(stderr, "daq serve: {}\n", text); }};
}

void serve(const ServeOptions& o) {
  boost::asio::io_context io;
  Service service(io, o);
  fmt::print("daq serve: http://{}/ ({}), runs in {}; Ctrl-C stops\n",
             web::host_port(o.address, service.port()), service.source(),
             database_path(o.run.db).string());
  if (o.simulate)
    fmt::print("daq serve: SIMULATED shop in this process, {}x faster than real time\n", o.speed);
  std::fflush(stdout);
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  bool stopping = false;
  signals.async_wait([&](auto ec, int) {
    if (ec) return;
    service.shutdown();
    stopping = true;
    io.stop();
  });
  // Nothing a handler throws ends the service: the loop is run again after the run in
  // progress (if any) is ended with the reason (asio allows run() again after an exception).
  // --simulate: the loop is driven by its simulated time (paced), which also serves the page.
  auto* simulated = cal::drivers::VirtualTime::of(io);
  for (;;) {
    try {
      if (simulated)
        simulated->run_until([&] { return stopping; }, std::numeric_limits<std::int64_t>::max());
      else
        io.run();
      return;
    } catch (const std::exception& e) {
      service.failed(e.what());
    }
  }
}

}  // namespace daq::serve
