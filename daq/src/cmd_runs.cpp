// daq runs / show / export: stored runs.
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <memory>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"
#include "commands.hpp"
#include "database.hpp"

namespace daq {
namespace {

using nlohmann::json;
namespace st = cal::storage;

std::string iso_time(std::int64_t unix_ms) {
  const std::time_t s = unix_ms / 1000;
  std::tm tm{};
  gmtime_r(&s, &tm);
  std::array<char, 32> buf{};
  std::strftime(buf.data(), buf.size(), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf.data();
}

json run_json(const st::RunRecord& r) {
  json j{{"id", r.id},
         {"campaign", r.campaign},
         {"kind", r.kind},
         {"axis", r.axis},
         {"status", st::to_string(r.status)},
         {"started", iso_time(r.started_unix_ms)},
         {"ended", r.ended_unix_ms ? json(iso_time(*r.ended_unix_ms)) : json(nullptr)},
         {"note", r.note},
         {"capture_path", r.capture_path},
         {"software_version", r.software_version}};
  j["settings"] = json::parse(r.settings_json, nullptr, false);
  if (j["settings"].is_discarded()) j["settings"] = r.settings_json;
  return j;
}

st::RunRecord need_run(const st::Store& store, std::int64_t id) {
  auto r = store.run(id);
  if (!r)
    throw cal::InputError(fmt::format("{}: no run {} (see daq runs)", store.path().string(), id));
  return *r;
}

void cmd_runs(const std::string& db, bool as_json) {
  const auto store = open_database_read_only(db);
  const auto runs = store.runs();
  if (as_json) {
    json j{
        {"schema", "caldaq.runs.v1"}, {"database", store.path().string()}, {"runs", json::array()}};
    for (const auto& r : runs) {
      json one = run_json(r);
      one["readings"] = store.reading_count(r.id);
      j["runs"].push_back(one);
    }
    return fmt::print("{}\n", j.dump(2));
  }
  fmt::print("{} ({} runs)\n", store.path().string(), runs.size());
  fmt::print("{:>5}  {:<20}  {:<12} {:<5} {:<10} {:>10}  {}\n", "run", "started (UTC)", "kind",
             "axis", "status", "readings", "campaign");
  for (const auto& r : runs)
    fmt::print("{:>5}  {:<20}  {:<12} {:<5} {:<10} {:>10}  {}\n", r.id, iso_time(r.started_unix_ms),
               r.kind, r.axis, st::to_string(r.status), store.reading_count(r.id), r.campaign);
}

void cmd_show(const std::string& db, std::int64_t id, bool as_json) {
  const auto store = open_database_read_only(db);
  const auto r = need_run(store, id);
  json j = run_json(r);
  j["schema"] = "caldaq.run.v1";
  j["readings"] = store.reading_count(id);
  j["instruments"] = json::array();
  for (const auto& i : store.instruments(id))
    j["instruments"].push_back(
        {{"device", i.device}, {"driver", i.driver}, {"transport", i.transport}});
  j["targets"] = store.targets(id).size();
  j["results"] = json::array();
  for (const auto& res : store.results(id)) {
    json doc = json::parse(res.json, nullptr, false);
    j["results"].push_back(
        {{"standard", res.standard}, {"result", doc.is_discarded() ? json(res.json) : doc}});
  }
  if (as_json) return fmt::print("{}\n", j.dump(2));
  fmt::print("run {}: {} {} ({}), started {}{}\n", r.id, r.kind, r.axis, st::to_string(r.status),
             iso_time(r.started_unix_ms), r.note.empty() ? "" : " - " + r.note);
  fmt::print("  readings: {}, captured targets: {}\n", j["readings"].get<std::int64_t>(),
             j["targets"].get<std::size_t>());
  for (const auto& i : j["instruments"])
    fmt::print("  device {}: {} on {}\n", i["device"].get<int>(), i["driver"].get<std::string>(),
               i["transport"].get<std::string>());
  for (const auto& res : j["results"])
    fmt::print("  result: {}\n", res["standard"].get<std::string>());
  if (!r.capture_path.empty()) fmt::print("  capture: {}\n", r.capture_path);
}

// CSV columns are documented in docs/cli.md ("daq export"); numbers are printed with 17
// significant digits so that a round trip through the CSV is exact.
void export_csv(const st::Store& store, std::int64_t id, const std::string& what, std::FILE* out) {
  if (what == "targets") {
    std::fputs(
        "run_number,direction,target_index,nominal_mm,deviation_um,time_ns,raw_m,"
        "refractive_index,material_temperature_degc\n",
        out);
    for (const auto& t : store.targets(id))
      fmt::print(out, "{},{},{},{:.17g},{:.17g},{},{:.17g},{:.17g},{:.17g}\n", t.run_number,
                 t.direction, t.target_index + 1, t.nominal_mm, t.deviation_um, t.time_ns, t.raw_m,
                 t.refractive_index, t.material_temperature_degc);
    return;
  }
  std::fputs("time_ns,device,channel,quantity,status,value\n", out);
  for (const auto& r : store.readings(id))
    fmt::print(out, "{},{},{},{},{},{:.17g}\n", r.time_ns, r.device, r.channel,
               cal::drivers::to_string(static_cast<cal::drivers::Quantity>(r.quantity)), r.status,
               r.value);
}

void export_json(const st::Store& store, std::int64_t id, std::FILE* out) {
  json j = run_json(need_run(store, id));
  j["schema"] = "caldaq.export.v1";
  json readings = json::array();
  for (const auto& r : store.readings(id))
    readings.push_back({r.time_ns, r.device, r.channel,
                        cal::drivers::to_string(static_cast<cal::drivers::Quantity>(r.quantity)),
                        r.status, r.value});
  j["reading_columns"] = {"time_ns", "device", "channel", "quantity", "status", "value"};
  j["readings"] = std::move(readings);
  json targets = json::array();
  for (const auto& t : store.targets(id))
    targets.push_back({{"run_number", t.run_number},
                       {"direction", std::string(1, t.direction)},
                       {"target_index", t.target_index + 1},
                       {"nominal_mm", t.nominal_mm},
                       {"deviation_um", t.deviation_um},
                       {"time_ns", t.time_ns},
                       {"raw_m", t.raw_m},
                       {"refractive_index", t.refractive_index},
                       {"material_temperature_degc", t.material_temperature_degc}});
  j["targets"] = std::move(targets);
  j["results"] = json::array();
  for (const auto& res : store.results(id))
    j["results"].push_back(
        {{"standard", res.standard}, {"result", json::parse(res.json, nullptr, false)}});
  fmt::print(out, "{}\n", j.dump(1));
}

struct ExportOptions {
  std::string db;
  std::int64_t run = 0;
  std::string format = "csv";
  std::string what = "readings";
  std::string output;
};

void cmd_export(const ExportOptions& o) {
  const auto store = open_database_read_only(o.db);
  need_run(store, o.run);
  std::FILE* out = stdout;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(nullptr, &std::fclose);
  if (!o.output.empty()) {
    file.reset(std::fopen(o.output.c_str(), "w"));
    if (!file)
      throw cal::InputError(fmt::format("{}: cannot write: {}", o.output, std::strerror(errno)));
    out = file.get();
  }
  if (o.format == "json")
    export_json(store, o.run, out);
  else
    export_csv(store, o.run, o.what, out);
  if (std::ferror(out))
    throw cal::InputError(fmt::format("{}: write failed", o.output.empty() ? "stdout" : o.output));
}

}  // namespace

void add_runs_commands(CLI::App& app) {
  auto db = std::make_shared<std::string>();
  auto as_json = std::make_shared<bool>(false);
  CLI::App* runs = app.add_subcommand("runs", "List the stored runs");
  add_db_option(*runs, *db);
  runs->add_flag("--json", *as_json, "Print caldaq.runs.v1 JSON");
  runs->callback([db, as_json] { cmd_runs(*db, *as_json); });

  auto show_db = std::make_shared<std::string>();
  auto show_json = std::make_shared<bool>(false);
  auto show_id = std::make_shared<std::int64_t>(0);
  CLI::App* show = app.add_subcommand("show", "Show one stored run: set-up, instruments, results");
  show->add_option("RUN", *show_id, "Run number (see daq runs)")->required();
  add_db_option(*show, *show_db);
  show->add_flag("--json", *show_json, "Print caldaq.run.v1 JSON");
  show->callback([=] { cmd_show(*show_db, *show_id, *show_json); });

  auto ex = std::make_shared<ExportOptions>();
  CLI::App* exp = app.add_subcommand("export", "Export a stored run as CSV or JSON");
  exp->add_option("RUN", ex->run, "Run number (see daq runs)")->required();
  add_db_option(*exp, ex->db);
  exp->add_option("--format", ex->format, "csv or json")->check(CLI::IsMember({"csv", "json"}));
  exp->add_option("--what", ex->what, "CSV only: readings (raw, uncompensated) or targets")
      ->check(CLI::IsMember({"readings", "targets"}));
  exp->add_option("-o,--output", ex->output, "Write to this file instead of stdout");
  exp->callback([ex] { cmd_export(*ex); });
}

}  // namespace daq
