// daq serve --db postgresql://...: the fleet view (docs/web.md, "The fleet view").
#include "serve/fleet_serve.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "assets.hpp"
#include "cal/analysis/error.hpp"
#include "cal/storage/pg/fleet.hpp"
#include "cal/storage/pg/sync.hpp"
#include "server.hpp"
#include "unit_signs.hpp"

namespace daq::serve {
namespace {

namespace web = cal::daq::web;
namespace pg = cal::storage::pg;

web::Response error(int status, std::string_view message) {
  return {.status = status,
          .body = nlohmann::json{{"error", message}}.dump(
              -1, ' ', false, nlohmann::json::error_handler_t::replace)};
}

// Why nothing is written from here, for every request that would write.
constexpr std::string_view kReaderOnly =
    "the fleet view (daq serve --db postgresql://...) only reads the central store: nothing is "
    "written from this page. Runs are measured at the machine (daq serve -c FILE or --simulate, "
    "with a local store) and sent by daq sync --to; results are approved by a reviewer with daq "
    "approve";

std::int64_t now_unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Store errors (the server gone, a permission refused) are the answer's, not the service's end.
template <class F>
web::Response answer(F&& f) {
  try {
    return f();
  } catch (const cal::storage::StoreError& e) {
    return error(503, e.what());
  }
}

web::Api fleet_api(const std::string& url) {
  web::Api api{
      .page =
          [](std::string_view nonce) { return web::fleet_page(nonce, ::daq::unit_signs_json()); },
      .start = [](const std::string&) { return error(403, kReaderOnly); },
      .stop = [](const std::string&) { return error(403, kReaderOnly); }};
  // The queries run on the event loop, one at a time: the page asks for the fleet once and a
  // machine's history when it is opened, each well under a second at 1,000 machines
  // (docs/benchmarks.md, "The fleet view").
  api.routes.push_back(
      {"GET", "/api/fleet", [url](std::string_view, const std::string&) {
         return answer([&] { return web::Response{.body = pg::fleet_json(url, now_unix_ms())}; });
       }});
  api.routes.push_back(
      {"GET", "/api/fleet/machines/", [url](std::string_view path, const std::string&) {
         const auto id_text = path.substr(std::string_view("/api/fleet/machines/").size());
         std::int64_t id = 0;
         const auto [end, ec] =
             std::from_chars(id_text.data(), id_text.data() + id_text.size(), id);
         if (ec != std::errc() || end != id_text.data() + id_text.size() || id <= 0)
           return error(404, "no such machine: give its id, a whole number > 0");
         return answer([&] {
           auto doc = pg::fleet_machine_json(url, id);
           if (!doc) return error(404, fmt::format("no machine {} in the central store", id));
           return web::Response{.body = std::move(*doc)};
         });
       }});
  // Every other POST (the operator's page's set-up, control, compensation...) is refused.
  api.routes.push_back(
      {"POST", "/", [](std::string_view, const std::string&) { return error(403, kReaderOnly); }});
  return api;
}

}  // namespace

void serve_fleet(const ServeOptions& o) {
  if (o.simulate || !o.run.config.empty())
    throw cal::InputError(
        "daq serve --db postgresql://... is the fleet view, which only reads the central store: "
        "it takes no set-up (-c) and no --simulate. Acquisition writes to a local store (--db "
        "FILE), sent to the central store by daq sync --to");
  if (!o.capture_dir.empty())
    throw cal::InputError(
        "daq serve --db postgresql://... (the fleet view) records no captures: --capture-dir is "
        "for a serve that acquires (-c FILE or --simulate)");
  const std::string& url = o.run.db;
  // The store is read once before serving: an absent server, a database without a caldaq store
  // or one of another schema version is refused at start with the reason.
  (void)pg::fleet_json(url, now_unix_ms());
  boost::asio::io_context io;
  web::LiveServer server(io, server_options(o), fleet_api(url));
  fmt::print("daq serve: http://{}/ (the fleet view of {}, reader only); Ctrl-C stops\n",
             web::host_port(o.address, server.port()), pg::redacted(url));
  std::fflush(stdout);
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](auto ec, int) {
    if (!ec) io.stop();
  });
  io.run();
}

}  // namespace daq::serve
