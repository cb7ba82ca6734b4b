// daq serve --db postgresql://...: the fleet view (docs/web.md, "The fleet view").
#include "serve/fleet_serve.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/thread_pool.hpp>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>

#include "assets.hpp"
#include "cal/analysis/error.hpp"
#include "cal/storage/pg/fleet.hpp"
#include "cal/storage/pg/pool.hpp"
#include "cal/storage/pg/sync.hpp"
#include "http_policy.hpp"
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

// A whole number > 0 written in decimal digits alone, or nullopt.
std::optional<std::int64_t> whole_number(std::string_view text) {
  std::int64_t n = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (ec != std::errc() || end != text.data() + text.size() || n <= 0) return std::nullopt;
  return n;
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

// Requests answered at once (on the workers and the pool's connections, not the event loop):
// as many as the pool has connections; more wait for one.
constexpr std::size_t kConnections = 4;

// f's answer computed on a worker thread, off the event loop (a query holds no other request
// up); f must not refer to the request's arguments by reference.
template <class F>
web::Response on_worker(boost::asio::thread_pool& workers, F f) {
  web::Response r;
  r.deferred = [&workers, f = std::move(f)](std::function<void(web::Response)> done) {
    boost::asio::post(workers, [f, done = std::move(done)] { done(answer(f)); });
  };
  return r;
}

// Each request leases one of the pool's connections for its one READ ONLY transaction (a
// connection per request cost a connection's start-up and the schema check every time).
web::Api fleet_api(pg::ConnectionPool& pool, boost::asio::thread_pool& workers) {
  web::Api api{
      .page =
          [](std::string_view nonce) { return web::fleet_page(nonce, ::daq::unit_signs_json()); },
      .start = [](const std::string&) { return error(403, kReaderOnly); },
      .stop = [](const std::string&) { return error(403, kReaderOnly); }};
  // The queries run on the workers, one per connection of the pool: the page asks for the fleet's
  // first view, a site's page of machines when the site is opened and a machine's trends and
  // history when the machine is opened, each small whatever the fleet's size (docs/benchmarks.md,
  // "The fleet view").
  api.routes.push_back(
      {"GET", "/api/fleet", [&pool, &workers](std::string_view, const std::string&) {
         return on_worker(workers, [&pool] {
           return web::Response{.body = pg::fleet_json(pool, now_unix_ms())};
         });
       }});
  // The first site's first page, which the page asks for beside /api/fleet.
  api.routes.push_back(
      {"GET", "/api/fleet/first-site", [&pool, &workers](std::string_view, const std::string&) {
         return on_worker(workers, [&pool] {
           auto doc = pg::fleet_first_site_json(pool);
           if (!doc) return error(404, "no machine in the central store");
           return web::Response{.body = std::move(*doc)};
         });
       }});
  // /api/fleet/sites/SITE/page/N, SITE percent-encoded (encodeURIComponent: a '/' in it is %2F).
  api.routes.push_back(
      {"GET", "/api/fleet/sites/", [&pool, &workers](std::string_view path, const std::string&) {
         const auto rest = path.substr(std::string_view("/api/fleet/sites/").size());
         const auto at = rest.rfind("/page/");
         const auto page =
             at == std::string_view::npos ? std::nullopt : whole_number(rest.substr(at + 6));
         if (!page || *page > 1'000'000)
           return error(404, "give a site's page as /api/fleet/sites/SITE/page/N (N from 1)");
         const auto site = web::percent_decoded(rest.substr(0, at), false);
         return on_worker(workers, [&pool, site, page = static_cast<int>(*page)] {
           auto doc = pg::fleet_site_json(pool, site, page);
           if (!doc)
             return error(404, fmt::format("no machine of site '{}' on page {}", site, page));
           return web::Response{.body = std::move(*doc)};
         });
       }});
  // /api/fleet/machines/ID, or /api/fleet/machines/ID/since/YYYY-MM-DD (the lines from that day).
  api.routes.push_back(
      {"GET", "/api/fleet/machines/", [&pool, &workers](std::string_view path, const std::string&) {
         auto rest = path.substr(std::string_view("/api/fleet/machines/").size());
         std::optional<std::int64_t> since;
         if (const auto at = rest.find("/since/"); at != std::string_view::npos) {
           since = pg::day_start_unix_ms(rest.substr(at + 7));
           if (!since)
             return error(
                 404, fmt::format("'{}' is not a date written YYYY-MM-DD", rest.substr(at + 7)));
           rest = rest.substr(0, at);
         }
         const auto id = whole_number(rest);
         if (!id) return error(404, "no such machine: give its id, a whole number > 0");
         return on_worker(workers, [&pool, id = *id, since] {
           auto doc = pg::fleet_machine_json(pool, id, since);
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
  pg::ConnectionPool pool(url, kConnections);
  // The store is read before serving, on each of the pool's connections: an absent server, a
  // database without a caldaq store or one of another schema version is refused at start with
  // the reason, and the first page's requests find their connections open and their server
  // processes' caches filled (the page's first load after a start at 1,000 machines: 0.87 s
  // before, 0.23 - 0.31 s with it, load 9 - 13; docs/benchmarks.md).
  pg::fleet_warm(pool, now_unix_ms());
  boost::asio::io_context io;
  boost::asio::thread_pool workers(kConnections);
  web::LiveServer server(io, server_options(o), fleet_api(pool, workers));
  fmt::print("daq serve: http://{}/ (the fleet view of {}, reader only); Ctrl-C stops\n",
             web::host_port(o.address, server.port()), pg::redacted(url));
  std::fflush(stdout);
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](auto ec, int) {
    if (!ec) io.stop();
  });
  io.run();
  // The requests under way end before the server, the pool and the loop they answer to go.
  workers.join();
}

}  // namespace daq::serve
