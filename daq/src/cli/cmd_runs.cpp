// daq runs / show / export: stored runs.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <tuple>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "cal/daq/ballbar.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "compensation/compensation_check.hpp"
#include "database.hpp"
#include "iso230_2_output.hpp"
#include "json_input.hpp"
#include "progress.hpp"
#include "provenance.hpp"
#include "reading_times.hpp"
#include "result_rows.hpp"
#include "run_document.hpp"
#include "run_quality.hpp"
#include "run_version.hpp"
#include "running_decimal.hpp"
#include "shortest_number.hpp"
#include "stored_profile.hpp"
#include "terminal.hpp"
#include "verdict.hpp"

namespace daq {
namespace {

using nlohmann::json;
namespace st = cal::storage;

std::string iso_time(std::int64_t unix_ms) {
  return cal::text::utc_text(unix_ms / 1000, "%Y-%m-%dT%H:%M:%SZ");
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
  j["settings"] = cal::daq::parse_stored_json(r.settings_json);
  if (j["settings"].is_discarded()) j["settings"] = r.settings_json;
  return j;
}

st::RunRecord need_run(const st::RunReader& store, std::int64_t id) {
  auto r = store.run(id);
  if (!r) throw cal::InputError(fmt::format("{}: no run {} (see daq runs)", store.name(), id));
  return *r;
}

// From either store (RunReader): the local file or the central store (--db postgresql://...).
void cmd_runs(const std::string& db, bool as_json) {
  const auto store = open_run_reader(db);
  const auto runs = store->runs();
  if (as_json) {
    json j{{"schema", "caldaq.runs.v1"}, {"database", store->name()}, {"runs", json::array()}};
    for (const auto& r : runs) {
      json one = run_json(r);
      one["uuid"] = r.uuid.empty() ? json(nullptr) : json(r.uuid);
      one["readings"] = store->reading_count(r.id);
      j["runs"].push_back(one);
    }
    return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  }
  print_line("{} ({} runs)", store->name(), runs.size());
  print_line("{:>5}  {:<20}  {:<12} {:<5} {:<10} {:>10}  {}", "run", "started (UTC)", "kind",
             "axis", "status", "readings", "campaign");
  for (const auto& r : runs)
    print_line("{:>5}  {:<20}  {:<12} {:<5} {:<10} {:>10}  {}", r.id, iso_time(r.started_unix_ms),
               r.kind, r.axis, st::to_string(r.status), store->reading_count(r.id), r.campaign);
}

json missed_json(const st::MissedStop& m) {
  return {{"run", m.run_number},
          {"direction", m.direction == '+' ? "up" : "down"},
          {"target_index", m.target_index + 1},
          {"nominal_mm", m.nominal_mm}};
}

std::string missed_text(const st::MissedStop& m) {
  return fmt::format("run {} {} target {} ({:.3f} mm)", m.run_number,
                     m.direction == '+' ? "up" : "down", m.target_index + 1, m.nominal_mm);
}

// One line saying how a result was obtained, from its provenance.
std::string provenance_text(const json& p) {
  if (!p.is_object() || !p.contains("how")) return "provenance not recorded (stored before it was)";
  std::string s =
      p.value("how", "") + " " + p.value("created_utc", "") + " by " + p.value("software", "?");
  if (p.contains("of_result") && !p["of_result"].is_null())
    s += fmt::format(", of result {}", p["of_result"].get<std::int64_t>());
  if (p.contains("replay_of_run"))
    s += p["replay_of_run"].is_null()
             ? std::string(", replay of a run not in this database")
             : fmt::format(", replay of run {}", p["replay_of_run"].get<std::int64_t>());
  if (const auto c = p.find("coefficients"); c != p.end())
    s += fmt::format("; {}, {} ppm/K", c->value("equation", "?"),
                     c->value("expansion_ppm_per_k", 0.0));
  if (const auto o = p.find("sensor_offsets"); o != p.end()) {
    const auto off = sensor_offsets_from_json(*o);
    if (off.material_k || off.air_temperature_k || off.pressure_pa || off.humidity_pct)
      s += fmt::format("; offsets material {:+g} K, air {:+g} K, {:+g} Pa, {:+g} %RH",
                       off.material_k, off.air_temperature_k, off.pressure_pa, off.humidity_pct);
  }
  for (const auto& c : p.value("changed", json::array()))
    s += fmt::format("; {} {} -> {}", c.value("name", "?"), c["from"].dump(), c["to"].dump());
  return s;
}

}  // namespace

json approval_json(const st::Approval& a) {
  json j{{"result", a.result_id},
         {"approved_by", a.approved_by},
         {"approved", iso_time(a.approved_unix_ms)}};
  if (!a.result_fingerprint.empty()) {
    j["result_fingerprint"] = a.result_fingerprint;
    j["run_version"] = a.run_version;
  }
  // Made on the central server (read there, or brought by daq sync --from): which one.
  if (!a.central_server.empty()) j["central_server"] = a.central_server;
  return j;
}

json run_document(const st::RunReader& store, std::int64_t id) {
  const auto r = need_run(store, id);
  json j = run_json(r);
  j["schema"] = "caldaq.run.v1";
  j["readings"] = store.reading_count(id);
  j["instruments"] = json::array();
  const auto instruments = store.instruments(id);
  for (const auto& i : instruments)
    j["instruments"].push_back({{"device", i.device},
                                {"driver", i.driver},
                                {"transport", i.transport},
                                {"origin", i.origin},
                                {"origin_detail", i.origin_detail}});
  const std::string machine = [&] {
    const auto m = store.machine(r.machine_id);
    return m ? m->name : std::string{};
  }();
  j["origin"] = to_json(run_origin(r, instruments, machine));
  j["targets"] = store.targets(id).size();
  // The versions of the stops (issue 35): a central store keeps one per place that changed the
  // run (re-compensated on two laptops); named only when there is more than one.
  if (const auto versions = store.versions(id); versions.size() > 1) {
    j["versions"] = json::array();
    for (const auto& v : versions)
      j["versions"].push_back({{"version", v.version},
                               {"current", v.current},
                               {"status", v.status},
                               {"stops", v.stops},
                               {"sent", iso_time(v.sent_unix_ms)},
                               {"sent_by", v.sent_by},
                               {"sent_from", v.sent_from},
                               {"sent_store", v.sent_store}});
  }
  const auto missed = store.missed_stops(id);
  j["missed_stops"] = json::array();
  for (const auto& m : missed) j["missed_stops"].push_back(missed_json(m));
  j["quality"] = quality_json(run_quality(store, id));  // suspect stops (issue 26)
  // What the operator did during the run (issue 29): captures by hand, skips, pauses.
  j["operator_actions"] = json::array();
  for (const auto& a : store.operator_actions(id))
    j["operator_actions"].push_back({{"time", iso_time(a.time_unix_ms)},
                                     {"action", a.action},
                                     {"source", a.source},
                                     {"operator", a.operator_name},
                                     {"stop", a.stop ? missed_json(*a.stop) : json(nullptr)},
                                     {"detail", a.detail}});
  j["results"] = json::array();
  const json& settings = j["settings"];
  const auto approvals = store.approvals(id);  // sign-off (issue 35): named where given
  for (const auto& res : store.results(id)) {
    json doc = cal::daq::parse_stored_json(res.json);
    // A profile was stored without its values (kinds/ does not reach results/): as every output
    // lists them.
    if (doc.is_object() && is_profile_schema(doc.value("schema", "")) && !doc.contains("values"))
      doc["values"] = rows_json(result_rows(doc));
    json one{{"id", res.id},
             {"standard", res.standard},
             {"created", iso_time(res.created_unix_ms)},
             {"current", res.current()},
             {"superseded_by", res.superseded_by ? json(*res.superseded_by) : json(nullptr)},
             {"provenance", cal::daq::parse_stored_json(res.provenance_json)},
             {"result", doc.is_discarded() ? json(res.json) : doc}};
    if (one["provenance"].is_discarded()) one["provenance"] = json::object();
    if (!doc.is_discarded()) one["verdict"] = to_json(run_verdict(r.kind, r.axis, settings, doc));
    for (const auto& a : approvals)
      if (a.result_id == res.id) one["approval"] = approval_json(a);
    j["results"].push_back(std::move(one));
  }
  return j;
}

namespace {

void cmd_show(const std::string& db, std::int64_t id, bool as_json, int version) {
  const auto reader = open_run_reader(db);  // either store (--db postgresql://...)
  choose_version(*reader, db, id, version);
  const auto& store = *reader;
  const auto r = need_run(store, id);
  json j = run_document(store, id);
  // Which version's stops are counted: the chosen one, else the current one.
  if (j.contains("versions"))
    for (auto& v : j["versions"])
      v["shown"] = version != 0 ? v["version"].get<int>() == version : v["current"].get<bool>();
  const auto missed = store.missed_stops(id);
  if (as_json) return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  print_line("run {}: {} {} ({}), started {}{}", r.id, r.kind, r.axis, st::to_string(r.status),
             iso_time(r.started_unix_ms), r.note.empty() ? "" : " - " + r.note);
  print_line("  readings: {}, captured targets: {}", j["readings"].get<std::int64_t>(),
             j["targets"].get<std::size_t>());
  if (j.contains("versions")) {
    print_line("  versions ({}; the run was changed in more than one place, none overwritten):",
               j["versions"].size());
    for (const auto& v : j["versions"]) {
      const bool current = v["current"].get<bool>(), shown = v["shown"].get<bool>();
      print_line("    version {}{}: {} stops, sent {} by {} from {} ({})", v["version"].get<int>(),
                 current && shown ? " (current, shown)"
                 : current        ? " (current)"
                 : shown          ? " (shown)"
                                  : "",
                 v["stops"].get<std::int64_t>(), v["sent"].get<std::string>(),
                 v["sent_by"].get<std::string>(), v["sent_from"].get<std::string>(),
                 v["sent_store"].get<std::string>());
    }
    const auto& all = j["versions"];
    if (std::any_of(all.begin(), all.end(), [](const json& x) {
          return x["shown"].get<bool>() && !x["current"].get<bool>();
        }))
      print_line(
          "  the stops counted above are version {}'s, not the current version's; the results "
          "below are all the run's (daq export {} --version {} --what targets: that version's "
          "stops)",
          version, id, version);
  }
  if (!missed.empty()) {
    print_line("  missed stops ({}):", missed.size());
    for (const auto& m : missed) print_line("    {}", missed_text(m));
  }
  if (!j["operator_actions"].empty()) {
    print_line("  operator actions ({}):", j["operator_actions"].size());
    for (const auto& a : j["operator_actions"]) {
      const auto who = a["operator"].get<std::string>();
      print_line("    {} {} from the {}{}: {}", a["time"].get<std::string>(),
                 a["action"].get<std::string>(), a["source"].get<std::string>(),
                 who.empty() ? "" : " by " + who, a["detail"].get<std::string>());
    }
  }
  // The stop quality (run_quality.hpp): the verdict, each suspect stop by name.
  print_line("  stop quality: {}",
             quality_text({.state = j["quality"]["state"].get<std::string>(),
                           .summary = j["quality"]["summary"].get<std::string>()}));
  for (const auto& q : j["quality"]["suspect_stops"])
    print_line("    SUSPECT {}", q["reason"].get<std::string>());
  for (const auto& i : j["instruments"])
    print_line("  device {}: {} on {}", i["device"].get<int>(), i["driver"].get<std::string>(),
               i["transport"].get<std::string>());
  if (!r.capture_path.empty()) print_line("  capture: {}", r.capture_path);
  if (const auto& origin = j["origin"]; !origin["label"].get<std::string>().empty())
    print_line("  {}: {}", origin["label"].get<std::string>(), origin["text"].get<std::string>());
  else if (!origin["recorded"].get<bool>())
    print_line("  origin: {}", origin["text"].get<std::string>());
  if (r.kind == "linear" || r.kind == "straightness") {
    try {
      if (const auto check = check_run(store, id)) print_line("  {}", loop_text(*check));
    } catch (const cal::InputError& e) {
      print_line("  compensation check: {}", e.what());
    }
  }
  if (j["results"].empty()) print_line("  no results stored");
  for (const auto& res : j["results"]) {
    const bool current = res["current"].get<bool>();
    print_line(
        "  result {}: {} ({}){}", res["id"].get<std::int64_t>(), res["standard"].get<std::string>(),
        current ? "current"
                : fmt::format("superseded by result {}", res["superseded_by"].get<std::int64_t>()),
        "");
    print_line("    {}", provenance_text(res["provenance"]));
    if (res.contains("approval"))
      print_line("    approved by {} at {}{}", res["approval"]["approved_by"].get<std::string>(),
                 res["approval"]["approved"].get<std::string>(),
                 res["approval"].contains("central_server") ? " on the central server" : "");
    if (!current) continue;                 // the old values stay in --json
    print_result(res["result"], "      ");  // as daq run and daq analyse print it
    if (res.contains("verdict")) print_verdict(res["verdict"], "      ");
  }
}

// --- exports (columns documented in docs/cli.md, "daq export") -------------------------------

// Numbers in the shortest form that reads back to the same double (fmt's "{}").
std::string num(double v) { return fmt::format("{}", v); }

// An export's rows are formatted into one buffer with formats compiled in (no string per value,
// no format string parsed per row) and written 64 KiB at a time: per-value strings and a print
// per row were most of an export's time (issue 32). A row is written through a plain pointer
// into room reserved for it (`room`, then `commit`): fmt's appender checks the capacity at
// every character, which was a fifth of an export's time.
class RowBuffer {
 public:
  explicit RowBuffer(std::FILE* out) : out_(out) {}
  RowBuffer(const RowBuffer&) = delete;
  RowBuffer& operator=(const RowBuffer&) = delete;
  // On an exception's way out: what is held, without a word (the exception says what failed).
  ~RowBuffer() {
    if (size_ != 0) std::fwrite(text_.data(), 1, size_, out_);
  }
  // Where the next `n` characters go (at most n are written there before `commit`).
  char* room(std::size_t n) {
    if (size_ + n > text_.size()) text_.resize(std::max(kFlushAt, size_ + n) * 2);
    return text_.data() + size_;
  }
  void commit(const char* end) { size_ = static_cast<std::size_t>(end - text_.data()); }
  void add(std::string_view s) { commit(std::copy(s.begin(), s.end(), room(s.size()))); }
  // Called after each row: writes the buffer once it is full.
  void row_done() {
    if (size_ >= kFlushAt) write();
  }
  // Writes what is held; a failed write (a full disk) stops the export at once, as a print
  // per row did, rather than formatting the rest of the run for nothing.
  void write() {
    if (size_ != 0 && std::fwrite(text_.data(), 1, size_, out_) != size_)
      throw cal::InputError(fmt::format("export: cannot write: {}", std::strerror(errno)));
    size_ = 0;
  }

 private:
  static constexpr std::size_t kFlushAt = 1 << 16;
  std::vector<char> text_ = std::vector<char>(2 * kFlushAt);
  std::size_t size_ = 0;
  std::FILE* out_;
};

// The most a row's numbers and fixed text take (a double in the shortest form is at most 24
// characters, an int64 20, each with up to 8 bytes of no meaning written after it and then
// written over: kSpill in shortest_number.hpp; the value column's write_shortest_quantised up
// to 16); the names and the time of day are added to it.
constexpr std::size_t kRowNumbersMax = 256;

// Device names by device number (a handful, small numbers): a vector rather than a map lookup
// per row; a device without an instrument row has an empty name.
class DeviceNames {
 public:
  DeviceNames(const st::RunReader& store, std::int64_t run,
              const std::function<std::string(const std::string&)>& quote,
              std::string_view missing) {
    for (const auto& i : store.instruments(run)) {
      if (i.device < 0 || i.device > 0xffff) continue;  // no reading can name it
      const auto d = static_cast<std::size_t>(i.device);
      if (d >= names_.size()) names_.resize(d + 1, std::nullopt);
      names_[d] = quote(i.driver);
    }
    missing_ = missing;
  }
  std::string_view operator[](std::uint16_t device) const {
    return device < names_.size() && names_[device] ? std::string_view(*names_[device])
                                                    : std::string_view(missing_);
  }
  std::size_t longest() const {
    std::size_t n = missing_.size();
    for (const auto& s : names_)
      if (s) n = std::max(n, s->size());
    return n;
  }

 private:
  std::vector<std::optional<std::string>> names_;
  std::string missing_;
};

// Every reading of the run in time order, with its spread time (reading_times.hpp): the one
// place the export reads them. Streamed from the store a batch at a time, so an export's memory
// does not grow with the run (docs/benchmarks.md, daq bench export).
template <class F>
void each_export_row(const st::RunReader& store, std::int64_t run, ExportClock& clock, F&& f) {
  ExportRows rows(clock);
  auto stream = store.stream_readings(run);
  std::vector<st::RawReading> batch;
  while (stream.next(batch)) rows.add_batch(batch, f);
  rows.finish_each(f);
}

// A CSV field: quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

constexpr const char* kReadingColumns =
    "time_s,utc,device,device_name,channel,quantity,status,value,time_ns";
constexpr const char* kTargetColumns =
    "{},run,direction,{},target_index,time_s,utc,{},refractive_index,material_temperature_degc";

// The names of a stop's target, value and raw value: mm, the value's column and the laser's
// raw length in m; a rotary run's target in deg, its deviation in arcsec and its angular
// reference's raw angle in rad (kinds/rotary.cpp).
struct StopColumns {
  std::string target = "target_mm", value = "deviation_um", raw = "raw_m";
};

// The column of a stop's value: a positioning run's deviation (what `daq analyse iso230-2`
// reads); the other linear kinds' value in their unit (straightness um; angular and roll urad).
std::optional<std::string> stop_value_column(const st::RunRecord& run, const json& settings) {
  if (run.kind == "linear") return "deviation_um";
  if (run.kind == "rotary") return "deviation_arcsec";
  if (run.kind != "straightness" && run.kind != "angular" && run.kind != "roll")
    return std::nullopt;
  std::string unit = run.kind == "straightness" ? "um" : "urad";
  if (settings.is_object() && settings.contains("measure") && settings["measure"].is_object() &&
      settings["measure"].contains("unit") && settings["measure"]["unit"].is_string()) {
    const auto u = settings["measure"]["unit"].get<std::string>();
    if (u == "um" || u == "urad") unit = u;
  }
  return "value_" + unit;
}

// What a row copies or continues from the stream's row before it (device, channel, quantity):
// the fields between its UTC time and its status (device, device name, channel, quantity), as
// write_reading_fields writes them, made once per stream (formatting them per row was an
// eighth of an export, issue 32); and the digits of its last `time_ns` and `time_s`, which the
// next row's times continue by a decimal add (RunningDecimal: most rows are one period on).
// Looked up when the stream changes from the row before (a handful a second).
template <bool Json>
class StreamFields {
 public:
  struct Stream {
    std::string padded;  // the fields, then 16 bytes of no meaning
    std::size_t size = 0;
    RunningDecimal time_ns;   // the last row's stored time
    RunningDecimal since_ns;  // the last row's nanoseconds since the run's start (time_s)
    RunningReading value;     // the last row's value
  };
  explicit StreamFields(const DeviceNames& names) : names_(names) {}
  // r's stream, made if it is new.
  Stream& of(const st::RawReading& r) {
    if (last_ == nullptr || last_key_ != packed_key(r)) {
      auto [at, added] = streams_.try_emplace(key_of(r));
      if (added) {
        const auto quantity =
            cal::drivers::to_string(static_cast<cal::drivers::Quantity>(r.quantity));
        at->second.padded =
            Json ? fmt::format("\",{},{},{},\"{}\",", r.device, names_[r.device], r.channel,
                               quantity)
                 : fmt::format(",{},{},{},{},", r.device, names_[r.device], r.channel, quantity);
        at->second.size = at->second.padded.size();
        at->second.padded.resize(at->second.size + 16);
      }
      last_key_ = packed_key(r);
      last_ = &at->second;
    }
    return *last_;
  }
  // Writes the stream's fields at p and returns their end: in 16-byte pieces from a text padded
  // for them (up to 15 bytes of no meaning after the end), no library call per row (memcpy of a
  // varying length was 2 - 3 % of an export, issue 32).
  static char* write(char* p, const Stream& s) {
    const char* text = s.padded.data();
    for (std::size_t i = 0; i < s.size; i += 16) std::memcpy(p + i, text + i, 16);
    return p + s.size;
  }

 private:
  const DeviceNames& names_;
  std::map<StreamKey, Stream> streams_;
  std::uint32_t last_key_ = 0;  // packed_key of the last row's stream
  Stream* last_ = nullptr;
};

// A small unsigned integer (a status) as fmt's "{}" writes it.
char* write_small(char* p, std::uint8_t v) {
  if (v >= 100) *p++ = static_cast<char>('0' + v / 100);
  if (v >= 10) *p++ = static_cast<char>('0' + v / 10 % 10);
  *p++ = static_cast<char>('0' + v % 10);
  return p;
}

// One reading's fields in kReadingColumns order: a CSV line's (Json false; names as CSV fields),
// or the items of a JSON array (Json true; names as JSON strings, the UTC time and the
// quantity quoted, what a JSON number cannot hold, inf and nan, as null as nlohmann writes
// it). Both exports write their rows through this; a template, so that each one's loop stays
// as fast as a hand-written one (daq bench export).
template <bool Json>
char* write_reading_fields(char* p, const ExportClock& clock, StreamFields<Json>& fields,
                           const ExportRow& x) {
  const auto number = [](char* q, double v) {
    if (!Json || std::isfinite(v)) return write_shortest(q, v);
    return std::copy_n("null", 4, q);
  };
  auto& stream = fields.of(x.r);
  // The time in seconds: its nanoseconds / 10^9, correctly rounded, in the shortest form (as
  // clock.seconds(), fmt's "{}"). A reading's own time (most rows: whole nanoseconds) is the
  // exact decimal of its integer: the stream's last one's digits with the step added
  // (RunningDecimal), or written from the integer's digits (write_seconds_of_ns) where those
  // cannot be continued; a time spread inside a group (fractional nanoseconds) goes through
  // the digit search.
  const double since_ns = clock.since_origin_ns(x.session_ns);
  const auto whole_ns = std::abs(since_ns) < 0x1p62 ? static_cast<std::int64_t>(since_ns) : 0;
  if (static_cast<double>(whole_ns) != since_ns)
    p = number(p, clock.seconds(x.session_ns));  // the same division, in its one place
  else if (char* end = stream.since_ns.set(whole_ns) ? stream.since_ns.write_decimal(p) : nullptr)
    p = end;
  else
    p = write_seconds_of_ns(p, whole_ns);
  p = Json ? std::copy_n(",\"", 2, p) : std::copy_n(",", 1, p);
  if (clock.has_utc()) {  // (a run without a time origin leaves it empty: no call per row)
    const auto utc = clock.utc_view(x.session_ns);
    p = std::copy(utc.begin(), utc.end(), p);
  }
  p = StreamFields<Json>::write(p, stream);
  p = write_small(p, x.r.status);
  *p++ = ',';
  // The reading as its instrument gave it (a gauge's printed digits, an interferometer's
  // picometres, in SI): where it is its decimal's own double, written without the digit search
  // (write_shortest_quantised), and from the stream's last reading's digits where it is near
  // it (RunningReading); the same text every way.
  p = !Json || std::isfinite(x.r.value) ? stream.value.write(p, x.r.value)
                                        : std::copy_n("null", 4, p);
  *p++ = ',';
  // The stored time's integer: the stream's last one continued where it can be (as time_s).
  return stream.time_ns.set(x.r.time_ns) ? stream.time_ns.write_integer(p)
                                         : write_integer(p, x.r.time_ns);
}

void export_readings_csv(const st::RunReader& store, const st::RunRecord& run, const json& settings,
                         std::FILE* out, TerminalProgress& progress) {
  ExportClock clock(store, run, settings);
  const DeviceNames names(store, run.id, csv_field, "");  // CSV fields, quoted where needed
  const std::size_t row_max = kRowNumbersMax + names.longest() + 40;
  fmt::print(out, "{}\n", kReadingColumns);
  StreamFields<false> fields(names);
  RowBuffer b(out);
  each_export_row(store, run.id, clock, [&](const ExportRow& x) {
    char* p = write_reading_fields<false>(b.room(row_max), clock, fields, x);
    *p++ = '\n';
    b.commit(p);
    b.row_done();
    progress.add();
  });
  b.write();
}

StopColumns stop_columns(const st::RunRecord& run) {
  if (run.kind == "rotary") return {"target_deg", "deviation_arcsec", "raw_rad"};
  return {};
}

void export_targets_csv(const st::RunReader& store, const st::RunRecord& run, const json& settings,
                        std::FILE* out) {
  const auto value_column = stop_value_column(run, settings);
  if (!value_column)
    throw cal::InputError(
        fmt::format("run {} is a {} test and has no captured stops: use --what {} (or readings)",
                    run.id, run.kind, run.kind == "circle" ? "circle" : "readings"));
  const ExportClock clock(store, run, settings);
  // The header of a positioning run is what `daq analyse iso230-2 --input` reads (target_mm,
  // run, direction, deviation_um); the rest it ignores.
  const auto names = stop_columns(run);
  fmt::print(out, "{}\n",
             fmt::format(fmt::runtime(kTargetColumns), names.target, *value_column, names.raw));
  std::string note;  // a rotary run stored the old way: its stops' angles read as deviations
  const auto targets = stored_targets(store, run, &note);
  if (!note.empty()) fmt::print(stderr, "daq export: note: {}\n", cal::text::terminal_safe(note));
  for (const auto& t : targets) {
    const auto at = static_cast<double>(t.time_ns);
    fmt::print(out, "{},{},{},{},{},{},{},{},{},{}\n", num(t.nominal_mm), t.run_number,
               t.direction == '+' ? "up" : "down", num(t.deviation_um), t.target_index + 1,
               num(clock.seconds(at)), clock.utc(at), num(t.raw_m), num(t.refractive_index),
               num(t.material_temperature_degc));
  }
}

// The two traces of a ballbar run as `daq analyse circle --input` reads them: direction,
// angle_deg, deviation_um (from the bar's calibrated length), segmented by the run's program.
void export_circle_csv(const st::RunReader& store, const st::RunRecord& run, const json& settings,
                       std::FILE* out) {
  if (run.kind != "circle")
    throw cal::InputError(fmt::format(
        "run {} is a {} test, not a circle: use --what targets or readings", run.id, run.kind));
  if (!settings.is_object() || !settings.contains("radius_mm"))
    throw cal::InputError(fmt::format("run {}: its circle settings are missing", run.id));
  const auto [program, analysis] = circle_settings_from_json(settings);
  // The paged segmenter's sources, read in place: a held copy of both traces took 475 MB for
  // an hour at 10 kHz (issue 32); the angles and deviations are the same numbers either way.
  const auto segmenter = segment_stored_run(store, run.id, program);
  const auto traces = segmenter.sources();
  if (traces.empty())
    throw cal::InputError(
        fmt::format("run {}: the stored bar readings hold no complete arc", run.id));
  std::string options =
      fmt::format("--radius-mm {} --feed-mm-min {} --plane {}", num(program.radius_mm),
                  num(program.feed_mm_per_min), analysis.plane);
  if (analysis.calibrated_radius_mm)
    options += fmt::format(" --calibrated-radius-mm {}", num(*analysis.calibrated_radius_mm));
  if (analysis.uncalibrated) options += " --uncalibrated";
  if (analysis.cyclic_period_mm)
    options += fmt::format(" --cyclic-period-mm {}", num(*analysis.cyclic_period_mm));
  fmt::print(out,
             "# caldaq run {}: ballbar circle, analyse with: daq analyse circle --input FILE {}\n",
             run.id, options);
  fmt::print(out, "direction,angle_deg,deviation_um\n");
  for (const auto& t : traces) {
    const char* dir = t.direction() == cal::circle::Direction::ccw ? "ccw" : "cw";
    for (std::size_t i = 0; i < t.size(); ++i)
      fmt::print(out, "{},{},{}\n", dir, num(t.angle_deg(i)), num(t.deviation_um(i)));
  }
}

// caldaq.export.v1. Everything but the readings is built as one document; the readings, which
// grow with the run, are written row by row into its place as they stream from the store.
void export_json(const st::RunReader& store, const st::RunRecord& run, const json& settings,
                 std::FILE* out, TerminalProgress& progress) {
  json j = run_json(run);
  j["schema"] = "caldaq.export.v1";
  {
    const auto m = store.machine(run.machine_id);
    j["origin"] = to_json(run_origin(run, store.instruments(run.id), m ? m->name : ""));
  }
  ExportClock clock(store, run, settings);
  const DeviceNames names(  // JSON strings, quoted and escaped
      store, run.id, [](const std::string& name) { return json(name).dump(); }, "\"\"");
  const std::size_t row_max = kRowNumbersMax + names.longest() + 40;
  j["reading_columns"] = {"time_s",   "utc",    "device", "device_name", "channel",
                          "quantity", "status", "value",  "time_ns"};
  j["readings"] = nullptr;  // the place of the rows, found in the text below
  json targets = json::array();
  const auto columns = stop_columns(run);
  std::string note;  // a rotary run stored the old way: its stops' angles read as deviations
  for (const auto& t : stored_targets(store, run, &note))
    targets.push_back({{columns.target, t.nominal_mm},
                       {"run", t.run_number},
                       {"direction", t.direction == '+' ? "up" : "down"},
                       {columns.value, t.deviation_um},
                       {"target_index", t.target_index + 1},
                       {"time_s", clock.seconds(static_cast<double>(t.time_ns))},
                       {"utc", clock.utc(static_cast<double>(t.time_ns))},
                       {columns.raw, t.raw_m},
                       {"refractive_index", t.refractive_index},
                       {"material_temperature_degc", t.material_temperature_degc}});
  j["targets"] = std::move(targets);
  if (!note.empty()) j["notes"] = json::array({note});
  j["missed_stops"] = json::array();
  for (const auto& m : store.missed_stops(run.id)) j["missed_stops"].push_back(missed_json(m));
  j["quality"] = quality_json(run_quality(store, run.id));  // suspect stops (issue 26)
  j["results"] = json::array();
  for (const auto& res : store.results(run.id))
    j["results"].push_back({{"id", res.id},
                            {"standard", res.standard},
                            {"current", res.current()},
                            {"provenance", cal::daq::parse_stored_json(res.provenance_json)},
                            {"result", cal::daq::parse_stored_json(res.json)}});
  const std::string text = cal::daq::dump_output(j, 1);
  // Top-level keys are indented by one space; nothing nested is.
  const std::string marker = "\n \"readings\": null";
  const auto at = text.find(marker);
  if (at == std::string::npos) throw std::logic_error("export_json: no place for the readings");
  fmt::print(out, "{}\n \"readings\": [", std::string_view(text).substr(0, at));
  bool first = true;
  {
    StreamFields<true> fields(names);
    RowBuffer b(out);
    each_export_row(store, run.id, clock, [&](const ExportRow& x) {
      char* p = b.room(row_max);
      p = std::copy_n(first ? "\n  [" : ",\n  [", first ? 4 : 5, p);
      p = write_reading_fields<true>(p, clock, fields, x);
      *p++ = ']';
      b.commit(p);
      b.row_done();
      first = false;
      progress.add();
    });
    b.write();
  }
  fmt::print(out, "{}]{}\n", first ? "" : "\n ", std::string_view(text).substr(at + marker.size()));
}

struct ExportOptions {
  std::string db;
  std::int64_t run = 0;
  std::string format = "csv";
  std::string what = "readings";
  std::string output;
  int version = 0;  // 0: the current version of the run's stops
};

void cmd_export(const ExportOptions& o) {
  const auto reader = open_run_reader(o.db);  // either store (--db postgresql://...)
  choose_version(*reader, o.db, o.run, o.version);
  const auto& store = *reader;
  need_run(store, o.run);  // before a file is created
  std::FILE* out = stdout;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(nullptr, &std::fclose);
  if (!o.output.empty()) {
    file.reset(std::fopen(o.output.c_str(), "w"));
    if (!file)
      throw cal::InputError(fmt::format("{}: cannot write: {}", o.output, std::strerror(errno)));
    out = file.get();
  }
  const auto run = need_run(store, o.run);
  const json settings = cal::daq::parse_stored_json(run.settings_json);
  const bool readings = o.format == "json" || o.what == "readings";
  {
    // A long export shows how far it is on the terminal, unless its rows go to that terminal.
    TerminalProgress progress(
        fmt::format("export run {}", run.id), "readings",
        readings ? static_cast<std::uint64_t>(store.reading_count(run.id)) : 0,
        readings && ::isatty(::fileno(out)) == 0);
    if (o.format == "json")
      export_json(store, run, settings, out, progress);
    else if (o.what == "targets")
      export_targets_csv(store, run, settings, out);
    else if (o.what == "circle")
      export_circle_csv(store, run, settings, out);
    else
      export_readings_csv(store, run, settings, out, progress);
  }
  if (std::fflush(out) != 0 || std::ferror(out))
    throw cal::InputError(fmt::format("{}: write failed", o.output.empty() ? "stdout" : o.output));
  // Into a file: say what was written; on stderr when the file is a stream (-o /dev/stdout).
  if (o.output.empty()) return;
  const long bytes = std::ftell(out);
  std::error_code ec;
  std::FILE* status = std::filesystem::is_regular_file(o.output, ec) ? stdout : stderr;
  fmt::print(status, "{} of run {} written to {}{}\n",
             o.format == "json"     ? "JSON export"
             : o.what == "readings" ? "readings"
                                    : "CSV of the " + o.what,
             run.id, o.output, bytes >= 0 ? fmt::format(" ({} bytes)", bytes) : "");
}

}  // namespace

void add_runs_commands(CLI::App& app) {
  auto db = std::make_shared<std::string>();
  auto as_json = std::make_shared<bool>(false);
  CLI::App* runs = app.add_subcommand("runs", "List the stored runs");
  add_read_db_option(*runs, *db);
  runs->add_flag("--json", *as_json, "Print caldaq.runs.v1 JSON");
  runs->callback([db, as_json] { cmd_runs(*db, *as_json); });

  auto show_db = std::make_shared<std::string>();
  auto show_json = std::make_shared<bool>(false);
  auto show_id = std::make_shared<std::int64_t>(0);
  auto show_version = std::make_shared<int>(0);
  CLI::App* show = app.add_subcommand("show", "Show one stored run: set-up, instruments, results");
  show->add_option("RUN", *show_id, "Run number (see daq runs)")->required();
  add_read_db_option(*show, *show_db);
  show->add_flag("--json", *show_json, "Print caldaq.run.v1 JSON");
  add_version_option(*show, *show_version);
  show->callback([=] { cmd_show(*show_db, *show_id, *show_json, *show_version); });

  const auto [exp, ex] =
      add_command<ExportOptions>(app, "export", cmd_export, "Export a stored run as CSV or JSON");
  exp->add_option("RUN", ex->run, "Run number (see daq runs)")->required();
  add_read_db_option(*exp, ex->db);
  exp->add_option("--format", ex->format, "csv or json")->check(CLI::IsMember({"csv", "json"}));
  exp->add_option("--what", ex->what,
                  "CSV only: readings (raw, uncompensated), targets (a linear run's stops, as daq "
                  "analyse iso230-2 reads them) or circle (a circle run's traces, as daq analyse "
                  "circle reads them)")
      ->check(CLI::IsMember({"readings", "targets", "circle"}));
  exp->add_option("-o,--output", ex->output, "Write to this file instead of stdout");
  add_version_option(*exp, ex->version);
}

}  // namespace daq
