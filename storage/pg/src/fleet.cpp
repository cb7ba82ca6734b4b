// The fleet view (docs/web.md, "The fleet view"): a few queries of the tables that central schema 8
// keeps by triggers (fleet_schema.hpp), in one READ ONLY transaction; no reading is ever read.
#include "cal/storage/pg/fleet.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>

#include "cal/storage/pg/sync.hpp"
#include "central_schema.hpp"

namespace cal::storage::pg {

using nlohmann::json;

namespace {

constexpr double kMsPerDay = 86'400'000.0;
constexpr double kMsPerYear = 365.25 * kMsPerDay;

// As a verdict judges a value: its magnitude as printed (0.001 of its unit) against the limit.
bool within(double value, double limit) {
  return std::round(std::abs(value) * 1e3) / 1e3 <= limit + 1e-12;
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
std::optional<std::chrono::sys_days> parse_day(const std::string& text) {
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

template <class T>
json nullable(const pqxx::field& f) {
  return f.is_null() ? json(nullptr) : json(f.as<T>());
}

json machines_by_site(pqxx::transaction_base& t) {
  // The site is the latest run's (its configuration's customer.site).
  const auto rows = t.exec(
      "SELECT m.id, COALESCE(m.uuid::text, ''), m.name, COALESCE(l.site, ''), l.started_unix_ms "
      "FROM caldaq.machines AS m LEFT JOIN LATERAL (SELECT f.site, f.started_unix_ms FROM "
      "caldaq.fleet_runs AS f WHERE f.machine_id = m.id ORDER BY f.started_unix_ms DESC LIMIT 1) "
      "AS l ON true ORDER BY COALESCE(l.site, '') COLLATE \"C\", m.name COLLATE \"C\", m.id");
  json sites = json::array();
  for (const auto& r : rows) {
    const auto site = r[3].as<std::string>();
    if (sites.empty() || sites.back()["site"] != site)
      sites.push_back({{"site", site}, {"machines", json::array()}});
    sites.back()["machines"].push_back({{"id", r[0].as<std::int64_t>()},
                                        {"uuid", r[1].as<std::string>()},
                                        {"name", r[2].as<std::string>()},
                                        {"last_run_unix_ms", nullable<std::int64_t>(r[4])},
                                        {"verdicts", json::array()},
                                        {"trends", json::array()}});
  }
  return sites;
}

// Each machine's latest current result of each test (a linear axis; a circle's plane, feed and
// radius) with its verdict.
void add_verdicts(pqxx::transaction_base& t, std::map<std::int64_t, json*>& machines) {
  const auto rows = t.exec(
      "SELECT machine_id, kind, test, run_id, result_id, started_unix_ms, verdict, failed FROM "
      "caldaq.fleet_tests ORDER BY machine_id, kind COLLATE \"C\", test COLLATE \"C\"");
  for (const auto& r : rows) {
    const auto m = machines.find(r[0].as<std::int64_t>());
    if (m == machines.end()) continue;
    (*m->second)["verdicts"].push_back({{"kind", r[1].as<std::string>()},
                                        {"test", r[2].as<std::string>()},
                                        {"run", r[3].as<std::int64_t>()},
                                        {"result", r[4].as<std::int64_t>()},
                                        {"started_unix_ms", r[5].as<std::int64_t>()},
                                        {"verdict", r[6].as<std::string>()},
                                        {"failed", r[7].as<std::string>()}});
  }
}

// Each trend series: a least-squares line of the value on the run's start over every current
// result of the series (regr_slope, regr_intercept: PostgreSQL's own, kept per series by
// caldaq.fleet_refresh), the latest value and limit.
void add_trends(pqxx::transaction_base& t, std::map<std::int64_t, json*>& machines) {
  const auto rows = t.exec(
      "SELECT machine_id, kind, test, key, symbol, unit, runs, slope_per_ms, intercept, "
      "first_unix_ms, last_unix_ms, latest, limit_value FROM caldaq.fleet_series ORDER BY "
      "machine_id, kind COLLATE \"C\", test COLLATE \"C\", key COLLATE \"C\"");
  for (const auto& r : rows) {
    const auto m = machines.find(r[0].as<std::int64_t>());
    if (m == machines.end()) continue;
    TrendFit fit{
        .runs = r[6].as<std::int64_t>(),
        .slope_per_ms = opt_double(r[7]),
        .intercept = opt_double(r[8]),
        .last_unix_ms = r[10].as<std::int64_t>(),
        .latest = r[11].as<double>(),
        .limit = opt_double(r[12]),
        .signed_value = r[1].as<std::string>() == "circle" && r[3].as<std::string>()[0] != 'G'};
    const auto p = project(fit);
    json j{
        {"kind", r[1].as<std::string>()},
        {"test", r[2].as<std::string>()},
        {"key", r[3].as<std::string>()},
        {"symbol", r[4].as<std::string>()},
        {"unit", r[5].as<std::string>()},
        {"runs", fit.runs},
        {"first_unix_ms", r[9].as<std::int64_t>()},
        {"last_unix_ms", fit.last_unix_ms},
        {"latest", fit.latest},
        {"limit", fit.limit ? json(*fit.limit) : json(nullptr)},
        {"slope_per_year", fit.slope_per_ms ? json(*fit.slope_per_ms * kMsPerYear) : json(nullptr)},
        // The line's value at the latest run (the page draws the line through it).
        {"fit_at_last",
         fit.slope_per_ms && fit.intercept
             ? json(*fit.intercept + *fit.slope_per_ms * static_cast<double>(fit.last_unix_ms))
             : json(nullptr)},
        {"status", to_string(p.status)},
        {"projected_unix_ms", nullptr},
        {"projected_date", nullptr}};
    if (p.projected_unix_ms) {
      j["projected_unix_ms"] = std::llround(*p.projected_unix_ms);
      j["projected_date"] = iso_day(day_of(*p.projected_unix_ms));
    }
    (*m->second)["trends"].push_back(std::move(j));
  }
}

json instruments(pqxx::transaction_base& t, std::chrono::sys_days today) {
  const auto rows = t.exec(
      "SELECT i.id, i.role, i.driver, i.serial_number, i.certificate, i.calibration_due, "
      "i.machine_id, COALESCE(m.name, ''), i.site, i.last_used_unix_ms FROM "
      "caldaq.fleet_instruments AS i LEFT JOIN caldaq.machines AS m ON m.id = i.machine_id "
      "ORDER BY i.calibration_due = '', i.calibration_due COLLATE \"C\", i.instrument COLLATE "
      "\"C\"");
  json out = json::array();
  for (const auto& r : rows) {
    const auto due_text = r[5].as<std::string>();
    const auto due = parse_day(due_text);
    json days = nullptr;
    std::string status = due_text.empty() ? "not stated" : "not a date";
    if (due) {
      const auto left = (*due - today).count();
      days = left;
      status = left < 0 ? "past due" : left <= fleet_due_soon_days ? "due soon" : "ok";
    }
    out.push_back({{"id", r[0].as<std::string>()},
                   {"role", r[1].as<std::string>()},
                   {"driver", r[2].as<std::string>()},
                   {"serial_number", r[3].as<std::string>()},
                   {"certificate", r[4].as<std::string>()},
                   {"calibration_due", due_text},
                   {"days_left", days},
                   {"status", status},
                   {"machine_id", nullable<std::int64_t>(r[6])},
                   {"machine", r[7].as<std::string>()},
                   {"site", r[8].as<std::string>()},
                   {"last_used_unix_ms", r[9].as<std::int64_t>()}});
  }
  return out;
}

// Current results without an approval (fleet_results.approved, kept by a trigger on the
// approvals; the partial index fleet_results_awaiting holds just these).
json awaiting_approval(pqxx::transaction_base& t) {
  const auto rows = t.exec_params(
      "SELECT count(*) OVER (), x.run_id, x.result_id, x.standard, x.created_unix_ms, "
      "x.started_unix_ms, x.kind, x.test, x.verdict, x.machine_id, COALESCE(m.name, ''), "
      "COALESCE(f.site, '') FROM caldaq.fleet_results AS x "
      "LEFT JOIN caldaq.machines AS m ON m.id = x.machine_id "
      "LEFT JOIN caldaq.fleet_runs AS f ON f.run_uuid = x.run_uuid "
      "WHERE x.current AND NOT x.approved "
      "ORDER BY x.started_unix_ms DESC, x.run_id DESC, x.result_id LIMIT $1",
      fleet_awaiting_listed);
  json list = json::array();
  for (const auto& r : rows)
    list.push_back({{"run", r[1].as<std::int64_t>()},
                    {"result", r[2].as<std::int64_t>()},
                    {"standard", r[3].as<std::string>()},
                    {"created_unix_ms", r[4].as<std::int64_t>()},
                    {"started_unix_ms", r[5].as<std::int64_t>()},
                    {"kind", r[6].as<std::string>()},
                    {"test", r[7].as<std::string>()},
                    {"verdict", r[8].as<std::string>()},
                    {"machine_id", r[9].as<std::int64_t>()},
                    {"machine", r[10].as<std::string>()},
                    {"site", r[11].as<std::string>()}});
  return {{"count", rows.empty() ? 0 : rows[0][0].as<std::int64_t>()},
          {"listed", list.size()},
          {"results", std::move(list)}};
}

template <class F>
auto read_only(std::string_view url, std::string_view what, F&& f) {
  const std::string shown = redacted(url);
  const auto conn = connect(shown, url);
  guarded(shown, "read the central schema version", [&] { check_reader_schema(*conn, shown); });
  return guarded(shown, what, [&] {
    pqxx::read_transaction t(*conn);
    return f(t);
  });
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

std::string fleet_json(std::string_view url, std::int64_t now_unix_ms) {
  return read_only(url, "read the fleet", [&](pqxx::transaction_base& t) {
    const auto today = day_of(static_cast<double>(now_unix_ms));
    json sites = machines_by_site(t);
    std::map<std::int64_t, json*> machines;
    for (auto& s : sites)
      for (auto& m : s["machines"]) machines[m["id"].get<std::int64_t>()] = &m;
    add_verdicts(t, machines);
    add_trends(t, machines);
    json doc{{"schema", "caldaq.fleet.v1"},
             {"store", redacted(url)},
             {"generated_unix_ms", now_unix_ms},
             {"today", iso_day(today)},
             {"trend",
              {{"method",
                "least squares line of each value on its run's start time, over every current "
                "result of the series; projected where the line reaches the limit of the latest "
                "run"},
               {"min_runs", fleet_min_runs_for_trend}}},
             {"due_soon_days", fleet_due_soon_days},
             {"sites", std::move(sites)},
             {"instruments", instruments(t, today)},
             {"awaiting_approval", awaiting_approval(t)}};
    return doc.dump(-1, ' ', false, json::error_handler_t::replace);
  });
}

std::optional<std::string> fleet_machine_json(std::string_view url, std::int64_t machine_id) {
  return read_only(
      url, fmt::format("read machine {}", machine_id),
      [&](pqxx::transaction_base& t) -> std::optional<std::string> {
        const auto m = t.exec_params(
            "SELECT name, COALESCE(uuid::text, '') FROM caldaq.machines "
            "WHERE id = $1",
            machine_id);
        if (m.empty()) return std::nullopt;
        const auto rows = t.exec_params(
            "SELECT v.kind, v.test, v.key, min(v.symbol), min(v.unit), json_agg(json_build_array("
            "v.started_unix_ms, v.value, r.run_id, v.limit_value) ORDER BY "
            "v.started_unix_ms, v.result_id)::text FROM caldaq.fleet_values AS v JOIN "
            "caldaq.fleet_results AS r ON r.run_uuid = v.run_uuid AND r.result_id = v.result_id "
            "WHERE v.machine_id = $1 AND v.current AND v.trend GROUP BY 1, 2, 3 ORDER BY 1, 2, 3",
            machine_id);
        json series = json::array();
        for (const auto& r : rows)
          series.push_back({{"kind", r[0].as<std::string>()},
                            {"test", r[1].as<std::string>()},
                            {"key", r[2].as<std::string>()},
                            {"symbol", r[3].as<std::string>()},
                            {"unit", r[4].as<std::string>()},
                            {"points", json::parse(r[5].as<std::string>())}});
        return json{{"schema", "caldaq.fleet-machine.v1"},
                    {"id", machine_id},
                    {"name", m[0][0].as<std::string>()},
                    {"uuid", m[0][1].as<std::string>()},
                    {"points", "[run start unix ms, value, run, limit]"},
                    {"series", std::move(series)}}
            .dump(-1, ' ', false, json::error_handler_t::replace);
      });
}

}  // namespace cal::storage::pg
