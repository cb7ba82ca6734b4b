#pragma once
// The fleet view (issue 35; docs/web.md "The fleet view"): what `daq serve --db postgresql://...`
// shows of a central store, read in a few queries of the tables central schemas 8 and 9 keep by
// triggers (storage/pg/src/fleet_schema.hpp, fleet_schema_9.hpp), never a reading, never a write
// (every query runs in a READ ONLY transaction). libpqxx stays in storage/pg/src. The first view
// is small whatever the fleet's size: the sites with their counts, the instruments and results
// most in need (the first of each, with the counts of all); a site's machines a page at a time,
// each with its verdicts and how many of its values leave their limits; a machine's trends and
// history when it is opened.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "cal/storage/pg/pool.hpp"

namespace cal::storage::pg {

// Fewer current results than this in a series: "not enough history", no projection.
inline constexpr int fleet_min_runs_for_trend = 3;
// An instrument whose calibration falls due within this many days is flagged "due soon".
inline constexpr int fleet_due_soon_days = 30;
// The runs awaiting approval listed (the newest first; the count says how many there are).
inline constexpr int fleet_awaiting_listed = 200;
// The instruments listed (the earliest due first; the counts say how many of each status).
inline constexpr int fleet_instruments_listed = 100;
// A site's machines a page holds (in byte order of their names).
inline constexpr int fleet_machines_per_page = 25;

// A series' least-squares line (value = intercept + slope * t, t in unix ms) over its window
// (runs: the results in it), the latest value and the latest run's limit (nullopt: no limit
// configured).
struct TrendFit {
  std::int64_t runs = 0;
  std::optional<double> slope_per_ms, intercept;
  std::int64_t last_unix_ms = 0;
  double latest = 0;
  std::optional<double> limit;
  bool signed_value = false;  // a diagnostic (either sign leaves); else a magnitude (E, M, G)
};

enum class TrendStatus {
  no_tolerance,        // no limit configured for it
  outside,             // the latest value is outside its limit already
  not_enough_history,  // fewer than fleet_min_runs_for_trend runs
  steady,              // the line does not move toward the limit (or is flat)
  leaving,             // the line reaches the limit at projected_unix_ms
};
struct Projection {
  TrendStatus status = TrendStatus::no_tolerance;
  std::optional<double> projected_unix_ms;  // leaving: when the line reaches the limit
};
// Where the line reaches +limit (rising) or, for a signed value, -limit (falling); a magnitude
// that falls, or a flat line, is steady. The latest value is judged as a verdict judges it (to
// 0.001 of its unit).
Projection project(const TrendFit& fit);
std::string_view to_string(TrendStatus s);

// The start (00:00 UTC, unix ms) of a day written YYYY-MM-DD, or nullopt when `text` is not a
// real date so written.
std::optional<std::int64_t> day_start_unix_ms(std::string_view text);

// The fleet's first view at `now_unix_ms` (the due dates are judged against its UTC day) as a
// JSON document (caldaq.fleet.v2: docs/web.md). Throws StoreError naming the server (password
// hidden) and what failed; a store of another schema version is refused as the read commands
// refuse it.
std::string fleet_json(ConnectionPool& pool, std::int64_t now_unix_ms);
// Page `page` (1, 2, ...) of the machines of `site` (caldaq.fleet-site.v1), or nullopt when the
// site has no machine on that page.
std::optional<std::string> fleet_site_json(ConnectionPool& pool, std::string_view site, int page);
// Page 1 of the first site's machines (the first in fleet_json's order): what the page shows first,
// asked for beside fleet_json (not after it, to learn the site's name); nullopt: no machine.
std::optional<std::string> fleet_first_site_json(ConnectionPool& pool);
// Every connection of the pool opened (each checks the schema once, as a lease does) and the
// first view and the first site's page read on each: the queries' catalog entries, plans and
// pages are then in each server process and its cache before the first page asks (docs/web.md).
// Throws StoreError as fleet_json does.
void fleet_warm(ConnectionPool& pool, std::int64_t now_unix_ms);

// One machine's trends and their series with every point (caldaq.fleet-machine.v2), each line
// fitted from the later of its window's start and `since_unix_ms` when given; nullopt when the
// server has no machine of that id.
std::optional<std::string> fleet_machine_json(ConnectionPool& pool, std::int64_t machine_id,
                                              std::optional<std::int64_t> since_unix_ms = {});

}  // namespace cal::storage::pg
