// The fleet view (docs/web.md, "The fleet view"): a few queries of the tables that central schemas
// 8 and 9 keep by triggers (fleet_schema.hpp, fleet_schema_9.hpp), each request in one READ ONLY
// transaction; no reading is ever read. Every row becomes JSON through one reader (row_object).
#include "cal/storage/pg/fleet.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "cal/analysis/fixed_text.hpp"
#include "cal/storage/pg/sync.hpp"
#include "central_schema.hpp"
#include "pool.hpp"

namespace cal::storage::pg {

using nlohmann::json;

namespace {

constexpr double kMsPerDay = 86'400'000.0;
constexpr double kMsPerYear = 365.25 * kMsPerDay;

// As a verdict judges a value: its magnitude as printed (0.001 of its unit) against the limit.
bool within(double value, double limit) {
  return cal::fixed_value(std::abs(value), 3) <= limit + 1e-12;
}

std::string iso_day(std::chrono::sys_days d) {
  const std::chrono::year_month_day ymd(d);
  return fmt::format("{:04}-{:02}-{:02}", static_cast<int>(ymd.year()),
                     static_cast<unsigned>(ymd.month()), static_cast<unsigned>(ymd.day()));
}

std::chrono::sys_days day_of(double unix_ms) {
  return std::chrono::floor<std::chrono::days>(std::chrono::sys_time<std::chrono::milliseconds>(
      std::chrono::milliseconds(static_cast<std::int64_t>(std::floor(unix_ms)))));
}

// "YYYY-MM-DD" (the configuration's calibration_due), or nullopt.
std::optional<std::chrono::sys_days> parse_day(std::string_view text_view) {
  const std::string text(text_view);
  int y = 0;
  unsigned m = 0, d = 0;
  char end = 0;
  if (text.size() != 10 || text[4] != '-' || text[7] != '-' ||
      std::sscanf(text.c_str(), "%4d-%2u-%2u%c", &y, &m, &d, &end) != 3)
    return std::nullopt;
  const std::chrono::year_month_day ymd{std::chrono::year(y), std::chrono::month(m),
                                        std::chrono::day(d)};
  if (!ymd.ok()) return std::nullopt;
  return std::chrono::sys_days(ymd);
}

std::optional<double> opt_double(const pqxx::field& f) {
  if (f.is_null()) return std::nullopt;
  return f.as<double>();
}

std::optional<std::int64_t> opt_int(const pqxx::field& f) {
  if (f.is_null()) return std::nullopt;
  return f.as<std::int64_t>();
}

// The one row reader of the fleet's queries: a column as JSON by its PostgreSQL type (the
// built-in type OIDs of pg_type.dat); NULL as null.
json field_json(const pqxx::field& f) {
  if (f.is_null()) return nullptr;
  switch (f.type()) {
    case 16:  // bool
      return f.as<bool>();
    case 20:  // int8
    case 21:  // int2
    case 23:  // int4
      return f.as<std::int64_t>();
    case 700:   // float4
    case 701:   // float8
    case 1700:  // numeric
      return f.as<double>();
    case 114:   // json
    case 3802:  // jsonb
      return json::parse(f.c_str());
    default:
      return f.as<std::string>();
  }
}

// A row as a JSON object, each column under its name in the query (its AS).
json row_object(const pqxx::row& r) {
  json o = json::object();
  for (const auto& f : r) o[f.name()] = field_json(f);
  return o;
}

// A bigint[] parameter ("{1,2,3}").
std::string id_array(const std::vector<std::int64_t>& ids) {
  return fmt::format("{{{}}}", fmt::join(ids, ","));
}

// A series' line and latest value, from a query of fleet_series or caldaq.fleet_fit.
TrendFit fit_of(const pqxx::row& r) {
  const auto kind = r["kind"].as<std::string>(), key = r["key"].as<std::string>();
  return {.runs = r["runs"].as<std::int64_t>(),
          .slope_per_ms = opt_double(r["slope_per_ms"]),
          .intercept = opt_double(r["intercept"]),
          .last_unix_ms = r["last_unix_ms"].as<std::int64_t>(),
          .latest = r["latest"].as<double>(),
          .limit = opt_double(r["limit"]),
          .signed_value = kind == "circle" && !key.empty() && key[0] != 'G'};
}

// The window a trend's line is fitted over: the chosen `since` when it is later than the
// series' own (the last change that resets it, kept by caldaq.fleet_refresh), else that.
json window_json(const pqxx::row& r, std::optional<std::int64_t> since) {
  const auto own = opt_int(r["own_from_unix_ms"]);
  const auto at = [](std::int64_t ms) {
    return json{{"from_unix_ms", ms}, {"from_date", iso_day(day_of(static_cast<double>(ms)))}};
  };
  if (since && (!own || *since > *own)) {
    auto w = at(*since);
    w["reason"] = "since chosen", w["detail"] = "";
    return w;
  }
  if (!own)
    return {{"from_unix_ms", nullptr},
            {"from_date", nullptr},
            {"reason", "all history"},
            {"detail", ""}};
  auto w = at(*own);
  w["reason"] = r["window_reason"].as<std::string>();
  w["detail"] = r["window_detail"].as<std::string>();
  return w;
}

// A trend as the page shows it: the row's columns, the slope a year, the line at the latest run,
// the status and projected date, and the window.
json trend_json(const pqxx::row& r, std::optional<std::int64_t> since) {
  const auto fit = fit_of(r);
  const auto p = project(fit);
  json j = row_object(r);
  for (const char* internal :
       {"slope_per_ms", "intercept", "own_from_unix_ms", "window_reason", "window_detail"})
    j.erase(internal);
  j["slope_per_year"] = fit.slope_per_ms ? json(*fit.slope_per_ms * kMsPerYear) : json(nullptr);
  // The line's value at the latest run (the page draws the line through it).
  j["fit_at_last"] =
      fit.slope_per_ms && fit.intercept
          ? json(*fit.intercept + *fit.slope_per_ms * static_cast<double>(fit.last_unix_ms))
          : json(nullptr);
  j["status"] = to_string(p.status);
  j["projected_unix_ms"] = nullptr;
  j["projected_date"] = nullptr;
  if (p.projected_unix_ms) {
    j["projected_unix_ms"] = std::llround(*p.projected_unix_ms);
    j["projected_date"] = iso_day(day_of(*p.projected_unix_ms));
  }
  j["window"] = window_json(r, since);
  return j;
}

// Each site (the machine's, caldaq.machines.site: the one its rows are granted by) with its
// count of machines and of those whose latest verdict of some test fails: a probe per machine
// of the failing tests' index (central schema 13), not a scan of fleet_tests, whose pages grow
// with the results synced between two vacuums (each leaves its test's old row dead).
json sites_summary(pqxx::transaction_base& t) {
  json sites = json::array();
  for (const auto& r :
       t.exec("SELECT m.site, count(*) AS machines, count(*) FILTER (WHERE EXISTS (SELECT FROM "
              "caldaq.fleet_tests AS x WHERE x.machine_id = m.id AND x.verdict = 'fail')) AS "
              "failing_machines FROM caldaq.machines AS m GROUP BY m.site ORDER BY m.site COLLATE "
              "\"C\""))
    sites.push_back(row_object(r));
  return sites;
}

// The instruments, the earliest due first (those past due, then due soon...): the first
// fleet_instruments_listed of them and the count of each status.
json instruments(pqxx::transaction_base& t, std::chrono::sys_days today) {
  const auto rows = t.exec(
      "SELECT i.id, i.role, i.driver, i.serial_number, i.certificate, i.calibration_due, "
      "i.machine_id, COALESCE(m.name, '') AS machine, i.site, i.last_used_unix_ms FROM "
      "caldaq.fleet_instruments AS i LEFT JOIN caldaq.machines AS m ON m.id = i.machine_id "
      "ORDER BY i.calibration_due = '', i.calibration_due COLLATE \"C\", i.instrument COLLATE "
      "\"C\"");
  json list = json::array();
  std::map<std::string, std::int64_t> statuses{
      {"past due", 0}, {"due soon", 0}, {"ok", 0}, {"not stated", 0}, {"not a date", 0}};
  for (const auto& r : rows) {
    const auto due_text = r["calibration_due"].as<std::string>();
    const auto due = parse_day(due_text);
    json days = nullptr;
    std::string status = due_text.empty() ? "not stated" : "not a date";
    if (due) {
      const auto left = (*due - today).count();
      days = left;
      status = left < 0 ? "past due" : left <= fleet_due_soon_days ? "due soon" : "ok";
    }
    ++statuses[status];
    if (std::ssize(list) >= fleet_instruments_listed) continue;
    auto j = row_object(r);
    j["days_left"] = days;
    j["status"] = status;
    list.push_back(std::move(j));
  }
  return {{"count", rows.size()},
          {"listed", list.size()},
          {"statuses", statuses},
          {"list", std::move(list)}};
}

// Current results without an approval (fleet_results.approved, kept by a trigger on the
// approvals; the partial index fleet_results_awaiting holds just these): their count from the
// index alone, and the newest fleet_awaiting_listed with their machines (a count over the listed
// query's rows joined every awaiting result to its machine first).
json awaiting_approval(pqxx::transaction_base& t) {
  const auto count = t.exec1(
                          "SELECT count(*) FROM caldaq.fleet_results AS x WHERE x.current "
                          "AND NOT x.approved")[0]
                         .as<std::int64_t>();
  json list = json::array();
  for (const auto& r : t.exec_params(
           "SELECT x.run_id AS run, x.result_id AS result, x.standard, x.created_unix_ms, "
           "x.started_unix_ms, x.kind, x.test, x.verdict, x.machine_id, COALESCE(m.name, '') AS "
           "machine, COALESCE(m.site, '') AS site FROM (SELECT * FROM caldaq.fleet_results AS y "
           "WHERE y.current AND NOT y.approved ORDER BY y.started_unix_ms DESC, y.run_id DESC, "
           "y.result_id LIMIT $1) AS x LEFT JOIN caldaq.machines AS m ON m.id = x.machine_id "
           "ORDER BY x.started_unix_ms DESC, x.run_id DESC, x.result_id",
           fleet_awaiting_listed))
    list.push_back(row_object(r));
  return {{"count", count}, {"listed", list.size()}, {"results", std::move(list)}};
}

// The machines of a page, each with its tests' latest verdicts and how many of its trend values
// leave their limit or are outside it (their lines as caldaq.fleet_refresh keeps them).
void add_verdicts_and_counts(pqxx::transaction_base& t, json& machines) {
  std::vector<std::int64_t> ids;
  std::map<std::int64_t, json*> by_id;
  for (auto& m : machines) {
    ids.push_back(m["id"].get<std::int64_t>());
    by_id[ids.back()] = &m;
    m["verdicts"] = json::array();
    m["trends"] = {{"series", 0}, {"leaving", 0}, {"outside", 0}};
  }
  for (const auto& r : t.exec_params(
           "SELECT x.machine_id, x.kind, x.test, x.run_id AS run, x.result_id AS result, "
           "x.started_unix_ms, x.verdict, x.failed FROM caldaq.fleet_tests AS x WHERE "
           "x.machine_id = ANY($1::bigint[]) ORDER BY x.machine_id, x.kind COLLATE \"C\", "
           "x.test COLLATE \"C\"",
           id_array(ids))) {
    auto v = row_object(r);
    v.erase("machine_id");
    (*by_id.at(r["machine_id"].as<std::int64_t>()))["verdicts"].push_back(std::move(v));
  }
  for (const auto& r : t.exec_params(
           "SELECT s.machine_id, s.kind, s.key, s.runs, s.slope_per_ms, s.intercept, "
           "s.last_unix_ms, s.latest, s.limit_value AS \"limit\" FROM caldaq.fleet_series AS s "
           "WHERE s.machine_id = ANY($1::bigint[])",
           id_array(ids))) {
    auto& counts = (*by_id.at(r["machine_id"].as<std::int64_t>()))["trends"];
    counts["series"] = counts["series"].get<int>() + 1;
    const auto status = project(fit_of(r)).status;
    if (status == TrendStatus::leaving) counts["leaving"] = counts["leaving"].get<int>() + 1;
    if (status == TrendStatus::outside) counts["outside"] = counts["outside"].get<int>() + 1;
  }
}

}  // namespace

std::string_view to_string(TrendStatus s) {
  switch (s) {
    case TrendStatus::no_tolerance:
      return "no tolerance";
    case TrendStatus::outside:
      return "outside";
    case TrendStatus::not_enough_history:
      return "not enough history";
    case TrendStatus::steady:
      return "steady";
    case TrendStatus::leaving:
      return "leaving";
  }
  return "?";
}

std::optional<std::int64_t> day_start_unix_ms(std::string_view text) {
  const auto day = parse_day(text);
  if (!day) return std::nullopt;
  return std::chrono::duration_cast<std::chrono::milliseconds>(day->time_since_epoch()).count();
}

Projection project(const TrendFit& fit) {
  if (!fit.limit) return {TrendStatus::no_tolerance, {}};
  if (!within(fit.latest, *fit.limit)) return {TrendStatus::outside, {}};
  if (fit.runs < fleet_min_runs_for_trend) return {TrendStatus::not_enough_history, {}};
  if (!fit.slope_per_ms || !fit.intercept || !std::isfinite(*fit.slope_per_ms) ||
      *fit.slope_per_ms == 0 || (*fit.slope_per_ms < 0 && !fit.signed_value))
    return {TrendStatus::steady, {}};
  const double target = *fit.slope_per_ms > 0 ? *fit.limit : -*fit.limit;
  const double at = (target - *fit.intercept) / *fit.slope_per_ms;
  if (!std::isfinite(at)) return {TrendStatus::steady, {}};
  return {TrendStatus::leaving, at};
}

namespace {

// The fleet's first view (fleet_json) in the caller's transaction.
std::string first_view(pqxx::transaction_base& t, const ConnectionPool& pool,
                       std::int64_t now_unix_ms) {
  const auto today = day_of(static_cast<double>(now_unix_ms));
  json sites = sites_summary(t);
  std::int64_t machines = 0;
  for (const auto& s : sites) machines += s["machines"].get<std::int64_t>();
  json doc{{"schema", "caldaq.fleet.v2"},
           {"store", pool.shown_url()},
           {"generated_unix_ms", now_unix_ms},
           {"today", iso_day(today)},
           {"trend",
            {{"method",
              "least squares line of each value on its run's start time, over its current "
              "results since the last change that resets it (a compensation table stored for "
              "an axis the test measures, the control's compensation switched on or off, or a "
              "date chosen when the machine is opened); projected where the line reaches the "
              "limit of the latest run"},
             {"min_runs", fleet_min_runs_for_trend}}},
           {"due_soon_days", fleet_due_soon_days},
           {"machines_per_page", fleet_machines_per_page},
           {"machines", machines},
           {"sites", std::move(sites)},
           {"instruments", instruments(t, today)},
           {"awaiting_approval", awaiting_approval(t)}};
  return doc.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace

std::string fleet_json(ConnectionPool& pool, std::int64_t now_unix_ms) {
  return with_connection(pool, "read the fleet", [&](pqxx::transaction_base& t) {
    return first_view(t, pool, now_unix_ms);
  });
}

namespace {

// Page `page` of the machines of `site` (fleet_site_json), in the caller's transaction.
std::optional<std::string> site_page(pqxx::transaction_base& t, const std::string& site, int page) {
  const auto total = t.exec_params1("SELECT count(*) FROM caldaq.machines WHERE site = $1", site)[0]
                         .as<std::int64_t>();
  const std::int64_t pages = (total + fleet_machines_per_page - 1) / fleet_machines_per_page;
  if (page < 1 || page > pages) return std::nullopt;
  json machines = json::array();
  for (const auto& r : t.exec_params(
           "SELECT m.id, COALESCE(m.uuid::text, '') AS uuid, m.name, (SELECT "
           "max(f.started_unix_ms) FROM caldaq.fleet_runs AS f WHERE f.machine_id = m.id) "
           "AS last_run_unix_ms FROM caldaq.machines AS m WHERE m.site = $1 ORDER BY m.name "
           "COLLATE \"C\", m.id LIMIT $2 OFFSET $3",
           site, fleet_machines_per_page,
           static_cast<std::int64_t>(page - 1) * fleet_machines_per_page))
    machines.push_back(row_object(r));
  add_verdicts_and_counts(t, machines);
  return json{{"schema", "caldaq.fleet-site.v1"},
              {"site", site},
              {"page", page},
              {"pages", pages},
              {"per_page", fleet_machines_per_page},
              {"count", total},
              {"first", (page - 1) * fleet_machines_per_page + 1},
              {"machines", std::move(machines)}}
      .dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace

std::optional<std::string> fleet_site_json(ConnectionPool& pool, std::string_view site, int page) {
  return with_connection(pool, "read the machines of a site",
                         [&](pqxx::transaction_base& t) -> std::optional<std::string> {
                           return site_page(t, std::string(site), page);
                         });
}

namespace {

// Page 1 of the first of the sites in fleet_json's order (byte order), of those this login sees.
std::optional<std::string> first_site_page(pqxx::transaction_base& t) {
  const auto first = t.exec("SELECT min(site COLLATE \"C\") FROM caldaq.machines");
  if (first.empty() || first[0][0].is_null()) return std::nullopt;
  return site_page(t, first[0][0].as<std::string>(), 1);
}

}  // namespace

std::optional<std::string> fleet_first_site_json(ConnectionPool& pool) {
  return with_connection(pool, "read the machines of the first site", first_site_page);
}

void fleet_warm(ConnectionPool& pool, std::int64_t now_unix_ms) {
  guarded(pool.shown_url(), "open the pool's connections and read the first view", [&] {
    // All leased at once, so that each lease is another connection.
    std::vector<std::unique_ptr<Lease>> leases;
    for (std::size_t i = 0; i < pool.max_connections(); ++i)
      leases.push_back(std::make_unique<Lease>(pool.impl()));
    for (auto& lease : leases) {
      pqxx::read_transaction t(lease->connection());
      (void)first_view(t, pool, now_unix_ms);
      (void)first_site_page(t);
    }
  });
}

std::optional<std::string> fleet_machine_json(ConnectionPool& pool, std::int64_t machine_id,
                                              std::optional<std::int64_t> since_unix_ms) {
  return with_connection(
      pool, fmt::format("read machine {}", machine_id),
      [&](pqxx::transaction_base& t) -> std::optional<std::string> {
        const auto m = t.exec_params(
            "SELECT name, COALESCE(uuid::text, ''), site FROM caldaq.machines WHERE id = $1",
            machine_id);
        if (m.empty()) return std::nullopt;
        const std::string since = since_unix_ms ? std::to_string(*since_unix_ms) : "";
        json trends = json::array();
        for (const auto& r : t.exec_params(
                 "SELECT s.kind, s.test, f.key, f.symbol, f.unit, f.runs, f.history_runs, "
                 "f.slope_per_ms, f.intercept, f.first_unix_ms, f.last_unix_ms, f.latest, "
                 "f.limit_value AS \"limit\", s.window_from_unix_ms AS own_from_unix_ms, "
                 "s.window_reason, s.window_detail FROM (SELECT DISTINCT ON (x.kind, x.test) "
                 "x.kind, x.test, x.window_from_unix_ms, x.window_reason, x.window_detail FROM "
                 "caldaq.fleet_series AS x WHERE x.machine_id = $1 ORDER BY x.kind, x.test) AS s "
                 "CROSS JOIN LATERAL caldaq.fleet_fit($1, s.kind, s.test, "
                 "GREATEST(s.window_from_unix_ms, NULLIF($2::text, '')::bigint)) AS f ORDER BY "
                 "s.kind COLLATE \"C\", s.test COLLATE \"C\", f.key COLLATE \"C\"",
                 machine_id, since))
          trends.push_back(trend_json(r, since_unix_ms));
        json series = json::array();
        for (const auto& r : t.exec_params(
                 "SELECT v.kind, v.test, v.key, min(v.symbol) AS symbol, min(v.unit) AS unit, "
                 "json_agg(json_build_array(v.started_unix_ms, v.value, r.run_id, "
                 "v.limit_value) ORDER BY v.started_unix_ms, v.result_id) AS points FROM "
                 "caldaq.fleet_values AS v JOIN caldaq.fleet_results AS r ON r.run_uuid = "
                 "v.run_uuid AND r.result_id = v.result_id WHERE v.machine_id = $1 AND v.current "
                 "AND v.trend GROUP BY 1, 2, 3 ORDER BY 1, 2, 3",
                 machine_id))
          series.push_back(row_object(r));
        return json{{"schema", "caldaq.fleet-machine.v2"},
                    {"id", machine_id},
                    {"name", m[0][0].as<std::string>()},
                    {"uuid", m[0][1].as<std::string>()},
                    {"site", m[0][2].as<std::string>()},
                    {"since_unix_ms", since_unix_ms ? json(*since_unix_ms) : json(nullptr)},
                    {"points", "[run start unix ms, value, run, limit]"},
                    {"trends", std::move(trends)},
                    {"series", std::move(series)}}
            .dump(-1, ' ', false, json::error_handler_t::replace);
      });
}

}  // namespace cal::storage::pg
