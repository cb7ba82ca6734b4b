// daq bench replay: `daq replay` of every device kind at its highest rate, beside the ingest
// bench's pipeline measured in the same run (issue 32: "replay at least 50x real time for every
// device at its highest rate, per reading within 5x of the bench's pipeline"; method in
// docs/benchmarks.md, "Replay speed of every device kind").
//
//   1. `daq sim --acquire --capture` (a child) records the two templates on simulated time: a
//      linear run with the position feed (IDS3010, PTU300, serial thermometer, SHDR) and a
//      1 kHz ballbar circle.
//   2. cal::replay::densify rewrites one device of a template at its highest rate per kind
//      (the other devices' records as they were: the same run, only denser).
//   3. Each round replays every capture, and each template itself, as a child `daq replay
//      CAPTURE --db COPY` (a copy of the template's store): wall time, CPU (user + system) and
//      peak RSS from wait4, so the replay is measured alone, start-up and end-of-run analysis
//      included; the stored run gives the readings and whether every stop was captured.
//   4. In each round, before the replays, the ingest bench's pipeline (the same code as
//      `daq bench ingest`) runs in this process: its CPU per reading with and without storage
//      is the peer the replays' CPU per added reading is divided by.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "cal/analysis/error.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/densify.hpp"
#include "cal/storage/store.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"

namespace daq {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct ReplayBenchOptions {
  bool long_run = false;
  int runs = 2, targets = 3;
  double circle_feed_mm_per_min = 3000;
  double circle_vibration_um = 0, circle_vibration_hz = 0;  // the circle template's, of Y
  int rounds = 2;
  int bench_seconds = 60;
  std::string kinds;  // empty: all
  std::string dir;
  std::string json_out;
  bool keep = false;
};

// One capture replayed once.
struct Replayed {
  double wall_s = 0, cpu_s = 0;
  long peak_rss_kib = 0;
  std::int64_t readings = 0;
  bool complete = false;
  std::size_t stops = 0, missed = 0;  // a linear run's captured and missed stops
  std::string note;                   // why incomplete
};

// A capture and its rounds.
struct Subject {
  std::string name;  // the kind, or the template ("linear", "circle")
  std::string test;  // its template
  double rate_hz = 0;
  std::string what;
  fs::path capture;
  double recorded_s = 0;
  std::vector<Replayed> rounds;
};

// First to last record, seconds.
double recorded_seconds(const fs::path& capture) {
  cal::replay::CaptureReader reader(capture);
  std::optional<std::int64_t> first;
  std::int64_t last = 0;
  while (const auto r = reader.next_view()) {
    if (!first) first = r->time_ns;
    last = r->time_ns;
  }
  return first ? static_cast<double>(last - *first) * 1e-9 : 0.0;
}

std::string tail_of(const fs::path& file) {
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text.size() > 2000 ? text.substr(text.size() - 2000) : text;
}

void copy_db(const fs::path& from, const fs::path& to) {
  bench::remove_db(to);
  fs::copy_file(from, to);
  if (fs::exists(from.string() + "-wal"))
    fs::copy_file(from.string() + "-wal", to.string() + "-wal");
}

// `daq replay` of the subject into a copy of its template's store, and what it stored.
Replayed replay_once(const Subject& s, const fs::path& template_db, const fs::path& dir) {
  const fs::path db = dir / "replay.sqlite";
  const fs::path log = dir / "replay.log";
  copy_db(template_db, db);
  // Under GNU time when there is one: wait4's peak RSS of a child of this process is at least
  // this process's own (Linux keeps the larger of the image before and after exec; this one
  // holds the captures' figures and the ingest bench's heap), so the replay's own peak is
  // time's %M, the peak of its child, spawned from its small image. CPU and wall from wait4
  // (they include time's own, about a millisecond).
  const fs::path rss = dir / "replay.rss";
  fs::remove(rss);
  const bool gnu_time = fs::exists("/usr/bin/time");
  const std::vector<std::string> replay{"replay", s.capture.string(), "--db", db.string()};
  auto wrapped = std::vector<std::string>{"-f", "%M", "-o", rss.string(),
                                          fs::read_symlink("/proc/self/exe").string()};
  wrapped.insert(wrapped.end(), replay.begin(), replay.end());
  auto c = gnu_time ? bench::spawn_program("/usr/bin/time", wrapped, log.string())
                    : bench::spawn_child(replay, log.string());
  if (gnu_time) {
    // "%M" on the last line (a "Command exited with non-zero status 2" line may come first).
    std::ifstream in(rss);
    std::string line, last;
    while (std::getline(in, line))
      if (!line.empty()) last = line;
    char* end = nullptr;
    c.peak_rss_kib = std::strtol(last.c_str(), &end, 10);
    if (last.empty() || *end != '\0')
      throw cal::InputError(
          fmt::format("bench replay: /usr/bin/time gave no peak RSS ('{}')", last));
  }
  // 2: stored incomplete (or another error: then no run of this capture is found below).
  if (c.exit_code != 0 && c.exit_code != 2)
    throw cal::InputError(fmt::format("bench replay: daq replay {} failed (exit {}):\n{}",
                                      s.capture.string(), c.exit_code, tail_of(log)));
  Replayed r{.wall_s = c.seconds, .cpu_s = c.cpu_s, .peak_rss_kib = c.peak_rss_kib};
  {
    const cal::storage::Store store(db, {.read_only = true});
    const auto runs = store.runs();
    const auto newest = std::max_element(runs.begin(), runs.end(),
                                         [](const auto& a, const auto& b) { return a.id < b.id; });
    // The template's store holds the original run; the replay adds the newest.
    if (newest == runs.end() || newest->capture_path != fs::absolute(s.capture).string())
      throw cal::InputError(fmt::format("bench replay: daq replay {} stored no run:\n{}",
                                        s.capture.string(), tail_of(log)));
    r.readings = store.reading_count(newest->id);
    r.complete = newest->status == cal::storage::RunStatus::complete && c.exit_code == 0;
    r.stops = store.targets(newest->id).size();
    r.missed = store.missed_stops(newest->id).size();
    if (!r.complete) {
      const auto text = tail_of(log);
      const auto at = text.find("but incomplete: ");
      r.note = at == std::string::npos ? text : text.substr(at + 16);
      while (!r.note.empty() && (r.note.back() == '\n' || r.note.back() == ' ')) r.note.pop_back();
    }
  }
  bench::remove_db(db);
  return r;
}

// The peer: the ingest bench's pipeline, CPU per reading without and with storage.
struct Peer {
  std::vector<double> pipeline_us, ingest_us;
};

void measure_peer(const fs::path& capture, const fs::path& dir, Peer& peer) {
  const auto alone = bench::ingest(capture, {}, 16384);
  peer.pipeline_us.push_back(alone.cpu_s / static_cast<double>(alone.readings) * 1e6);
  const fs::path db = dir / "ingest.sqlite";
  bench::remove_db(db);
  const auto in = bench::ingest(capture, db, 16384);
  peer.ingest_us.push_back(in.cpu_s / static_cast<double>(in.readings) * 1e6);
  bench::remove_db(db);
}

std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return fmt::format("{} {} {}", a, b, c);
}

std::vector<std::string> split_kinds(const std::string& text) {
  std::vector<std::string> out;
  std::size_t from = 0;
  while (from <= text.size()) {
    const auto comma = std::min(text.find(',', from), text.size());
    if (comma > from) out.push_back(text.substr(from, comma - from));
    from = comma + 1;
  }
  return out;
}

std::vector<Subject> subjects_for(const ReplayBenchOptions& o, const fs::path& dir) {
  const auto wanted = split_kinds(o.kinds);
  std::vector<Subject> out;
  for (const auto& k : cal::replay::dense_kinds()) {
    if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), k.kind) == wanted.end())
      continue;
    out.push_back({.name = std::string(k.kind),
                   .test = std::string(k.test),
                   .rate_hz = k.rate_hz,
                   .what = std::string(k.what),
                   .capture = dir / (std::string(k.kind) + ".cdq")});
  }
  for (const auto& w : wanted)
    if (std::none_of(out.begin(), out.end(), [&](const Subject& s) { return s.name == w; })) {
      std::vector<std::string> names;
      for (const auto& k : cal::replay::dense_kinds()) names.emplace_back(k.kind);
      throw cal::InputError(
          fmt::format("bench replay: --kinds: '{}' is none of {}", w, fmt::join(names, ", ")));
    }
  return out;
}

double median_of(const std::vector<Replayed>& rs, double Replayed::*field) {
  std::vector<double> v;
  for (const auto& r : rs) v.push_back(r.*field);
  return bench::median(v);
}

long max_rss_kib(const std::vector<Replayed>& rs) {
  long m = 0;
  for (const auto& r : rs) m = std::max(m, r.peak_rss_kib);
  return m;
}

// A device's CPU per added reading in each round (its replay less the template's of the same
// round), and the peer's with storage, each as their least and median.
struct RoundFigures {
  std::vector<double> per_us;
  double per_min = 0, per_median = 0, ingest_min = 0, ingest_median = 0;
};
RoundFigures round_figures(const Subject& s, const Subject& tpl, const Peer& peer) {
  RoundFigures f;
  const auto added = s.rounds.front().readings - tpl.rounds.front().readings;
  for (std::size_t r = 0; r < s.rounds.size() && r < tpl.rounds.size(); ++r)
    f.per_us.push_back(added > 0 ? (s.rounds[r].cpu_s - tpl.rounds[r].cpu_s) /
                                       static_cast<double>(added) * 1e6
                                 : std::nan(""));
  f.per_min = *std::min_element(f.per_us.begin(), f.per_us.end());
  f.per_median = bench::median(f.per_us);
  f.ingest_min = *std::min_element(peer.ingest_us.begin(), peer.ingest_us.end());
  f.ingest_median = bench::median(peer.ingest_us);
  return f;
}

std::string run_text(const Replayed& r, bool linear) {
  if (!r.complete)
    return fmt::format("INCOMPLETE ({}{})", r.note,
                       linear ? fmt::format("; {} of {} stops", r.stops, r.stops + r.missed) : "");
  return linear ? fmt::format("complete, {} of {} stops", r.stops, r.stops + r.missed)
                : std::string("complete");
}

// The circle template's vibration, checked here rather than by the child `daq sim` (whose
// message would name its own options, after the linear template's minutes).
void check_circle_vibration(const ReplayBenchOptions& o) {
  if (o.circle_vibration_um <= 0 && o.circle_vibration_hz <= 0) return;
  if (!(o.circle_vibration_um > 0 && o.circle_vibration_hz > 0))
    throw cal::InputError(
        "bench replay: --circle-vibration-um and --circle-vibration-hz go together, both above 0");
  // The template's ballbar streams at daq sim's default 1000 Hz; the analysis looks below 0.45
  // of the sample rate, and a faster vibration would alias.
  if (o.circle_vibration_hz >= 450)
    throw cal::InputError(fmt::format(
        "bench replay: --circle-vibration-hz {} Hz: at or above 450 Hz, 0.45 x the circle "
        "template's 1000 Hz ballbar, where its samples would alias it",
        o.circle_vibration_hz));
  const auto wanted = split_kinds(o.kinds);
  const auto kinds = cal::replay::dense_kinds();
  const bool circle = std::any_of(kinds.begin(), kinds.end(), [&](const auto& k) {
    return k.test == std::string_view("circle") &&
           (wanted.empty() || std::find(wanted.begin(), wanted.end(), k.kind) != wanted.end());
  });
  if (!circle)
    throw cal::InputError(
        "bench replay: --circle-vibration-um/-hz shape the circle template, which none of "
        "--kinds is replayed from: add ballbar");
}

void bench_replay(const ReplayBenchOptions& o) {
  if (o.rounds < 1 || o.bench_seconds < 1)
    throw cal::InputError("bench replay: --rounds and --bench-seconds must be at least 1");
  check_circle_vibration(o);
  const int runs = o.long_run ? 5 : o.runs;
  const int targets = o.long_run ? 11 : o.targets;
  const double feed = o.long_run ? 1000.0 : o.circle_feed_mm_per_min;
  const fs::path base = o.dir.empty() ? fs::temp_directory_path() : fs::path(o.dir);
  const fs::path dir = base / fmt::format("caldaq-bench-replay-{}", ::getpid());
  auto subjects = subjects_for(o, dir);
  fs::create_directories(dir);
  struct RemoveDir {
    fs::path dir;
    bool keep;
    ~RemoveDir() {
      std::error_code ec;
      if (!keep) fs::remove_all(dir, ec);
    }
  } const remove_dir{dir, o.keep};
  if (o.keep) fmt::print("captures and stores in {} (kept)\n", dir.string());

  // 1. The templates, on simulated time.
  std::vector<Subject> templates;
  for (const char* test : {"linear", "circle"}) {
    if (std::none_of(subjects.begin(), subjects.end(),
                     [&](const Subject& s) { return s.test == test; }))
      continue;
    const std::string name = test;
    std::vector<std::string> args{"sim",       "--acquire",
                                  "--test",    name,
                                  "--capture", (dir / (name + ".cdq")).string(),
                                  "--db",      (dir / (name + ".sqlite")).string(),
                                  "-o",        (dir / (name + ".toml")).string()};
    if (name == "linear")
      args.insert(args.end(), {"--position-feed", "--runs", std::to_string(runs), "--targets",
                               std::to_string(targets)});
    else
      args.insert(args.end(), {"--feed-mm-per-min", fmt::format("{}", feed)});
    if (name == "circle" && (o.circle_vibration_um > 0 || o.circle_vibration_hz > 0))
      args.insert(args.end(), {"--vibration-y-um", fmt::format("{}", o.circle_vibration_um),
                               "--vibration-y-hz", fmt::format("{}", o.circle_vibration_hz)});
    const auto log = dir / (name + ".log");
    const auto c = bench::spawn_child(args, log.string());
    if (c.exit_code != 0)
      throw cal::InputError(fmt::format("bench replay: daq {} failed (exit {}):\n{}",
                                        fmt::join(args, " "), c.exit_code, tail_of(log)));
    templates.push_back({.name = name, .test = name, .capture = dir / (name + ".cdq")});
  }
  // 2. One device at its highest rate per kind.
  for (auto& s : subjects)
    cal::replay::densify(dir / (s.test + ".cdq"), s.capture, s.name, s.rate_hz);
  for (auto* group : {&templates, &subjects})
    for (auto& s : *group) s.recorded_s = recorded_seconds(s.capture);

  // 3, 4. Rounds: the peer, then every replay.
  const fs::path peer_capture = dir / "ingest.cdq";
  bench::write_capture(peer_capture, o.bench_seconds);
  Peer peer;
  const auto load_before = load_average();
  for (int round = 0; round < o.rounds; ++round) {
    measure_peer(peer_capture, dir, peer);
    for (auto* group : {&templates, &subjects})
      for (auto& s : *group) s.rounds.push_back(replay_once(s, dir / (s.test + ".sqlite"), dir));
  }
  const auto load_after = load_average();
  const double pipeline_us = bench::median(peer.pipeline_us);
  const double ingest_us = bench::median(peer.ingest_us);

  fmt::print(
      "load average {} before, {} after; {} round(s); templates: linear {} runs x {} targets "
      "with the position feed, circle at {} mm/min\n",
      load_before, load_after, o.rounds, runs, targets, feed);
  fmt::print(
      "peer (the ingest bench's pipeline, {} s of a 10 kHz gauge stream, median of the rounds): "
      "{:.3f} us CPU per reading without storage ({:.3f}), {:.3f} us with storage ({:.3f})\n",
      o.bench_seconds, pipeline_us, fmt::join(peer.pipeline_us, ", "), ingest_us,
      fmt::join(peer.ingest_us, ", "));
  for (const auto& t : templates)
    fmt::print(
        "template {}: {} readings, {:.1f} s recorded, CPU {:.3f} s (median), peak RSS "
        "{:.1f} MB, {}\n",
        t.name, t.rounds.front().readings, t.recorded_s, median_of(t.rounds, &Replayed::cpu_s),
        static_cast<double>(max_rss_kib(t.rounds)) / 1024,
        run_text(t.rounds.front(), t.name == "linear"));
  fmt::print(
      "\n| device | rate | readings | recorded | wall | CPU | x real time (CPU) | us CPU per "
      "added reading | x pipeline | x ingest | peak RSS | run |\n"
      "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  json doc{
      {"schema", "caldaq.bench-replay.v1"},
      {"load_average", {{"before", load_before}, {"after", load_after}}},
      {"rounds", o.rounds},
      {"peer", {{"pipeline_us_per_reading", pipeline_us}, {"ingest_us_per_reading", ingest_us}}},
      {"templates", json::array()},
      {"devices", json::array()}};
  const auto round_json = [](const Replayed& r) {
    return json{
        {"wall_s", r.wall_s},       {"cpu_s", r.cpu_s},       {"peak_rss_kib", r.peak_rss_kib},
        {"readings", r.readings},   {"complete", r.complete}, {"stops", r.stops},
        {"missed_stops", r.missed}, {"note", r.note}};
  };
  for (const auto& t : templates) {
    json rs = json::array();
    for (const auto& r : t.rounds) rs.push_back(round_json(r));
    doc["templates"].push_back({{"test", t.name}, {"recorded_s", t.recorded_s}, {"rounds", rs}});
  }
  bool all_complete = true;
  std::vector<std::string> summaries;
  for (const auto& s : subjects) {
    const auto& tpl = *std::find_if(templates.begin(), templates.end(),
                                    [&](const Subject& t) { return t.name == s.test; });
    const double cpu = median_of(s.rounds, &Replayed::cpu_s);
    const double wall = median_of(s.rounds, &Replayed::wall_s);
    const auto readings = s.rounds.front().readings;
    const auto added = readings - tpl.rounds.front().readings;
    // The device's readings without the run's fixed start-up and analysis (the ballbar's
    // analysis grows with its samples and is in).
    const double above_s = cpu - median_of(tpl.rounds, &Replayed::cpu_s);
    const double per_us = added > 0 ? above_s / static_cast<double>(added) * 1e6 : std::nan("");
    // The same replay's CPU scatters by some 10 ms between rounds on a loaded machine: a device
    // adding less than 20 ms to its template's replay has no per-reading figure to speak of.
    const char* noise = above_s < 0.02 ? " (noise: < 20 ms above the template)" : "";
    const bool complete =
        std::all_of(s.rounds.begin(), s.rounds.end(), [](const Replayed& r) { return r.complete; });
    all_complete = all_complete && complete;
    std::vector<std::string> cpus;
    for (const auto& r : s.rounds) cpus.push_back(fmt::format("{:.3f}", r.cpu_s));
    fmt::print(
        "| {} | {:g} Hz | {} | {:.1f} s | {:.2f} s | {:.3f} s ({}) | {:.0f}x | {:.3f}{} | {:.1f} | "
        "{:.1f} | {:.1f} MB | {} |\n",
        s.what, s.rate_hz, readings, s.recorded_s, wall, cpu, fmt::join(cpus, ", "),
        s.recorded_s / cpu, per_us, noise, per_us / pipeline_us, per_us / ingest_us,
        static_cast<double>(max_rss_kib(s.rounds)) / 1024,
        run_text(complete ? s.rounds.front()
                          : *std::find_if(s.rounds.begin(), s.rounds.end(),
                                          [](const Replayed& r) { return !r.complete; }),
                 s.test == "linear"));
    json rs = json::array();
    for (const auto& r : s.rounds) rs.push_back(round_json(r));
    const RoundFigures f = round_figures(s, tpl, peer);
    summaries.push_back(fmt::format(
        "{}: us CPU per added reading min {:.3f}, median {:.3f} ({:.3f}); ingest peer min "
        "{:.3f}, median {:.3f}; x ingest from the mins {:.1f}, from the medians {:.1f}",
        s.name, f.per_min, f.per_median, fmt::join(f.per_us, ", "), f.ingest_min, f.ingest_median,
        f.per_min / f.ingest_min, f.per_median / f.ingest_median));
    doc["devices"].push_back({{"kind", s.name},
                              {"template", s.test},
                              {"rate_hz", s.rate_hz},
                              {"recorded_s", s.recorded_s},
                              {"readings", readings},
                              {"added_readings", added},
                              {"cpu_s", cpu},
                              {"wall_s", wall},
                              {"real_time_factor_cpu", s.recorded_s / cpu},
                              {"us_cpu_per_added_reading", per_us},
                              {"cpu_above_template_s", above_s},
                              {"x_pipeline", per_us / pipeline_us},
                              {"x_ingest", per_us / ingest_us},
                              {"peak_rss_kib", max_rss_kib(s.rounds)},
                              {"complete", complete},
                              {"rounds", rs},
                              {"over_rounds",
                               {{"us_cpu_per_added_reading", f.per_us},
                                {"us_cpu_per_added_reading_min", f.per_min},
                                {"us_cpu_per_added_reading_median", f.per_median},
                                {"ingest_us_per_reading_min", f.ingest_min},
                                {"ingest_us_per_reading_median", f.ingest_median},
                                {"x_ingest_from_mins", f.per_min / f.ingest_min},
                                {"x_ingest_from_medians", f.per_median / f.ingest_median}}}});
  }
  fmt::print(
      "\n(wall, CPU (user + system) and peak RSS of each `daq replay` child, medians of the rounds "
      "and the largest RSS; x real time: recorded seconds per CPU second; us CPU per added "
      "reading: (CPU - the template's) / (readings - the template's); x pipeline, x ingest: that "
      "against the peer's CPU per reading without and with storage. Goals (issue 32): 50x real "
      "time; per reading within 5x of the pipeline, read for a replay (which stores every "
      "reading) as within 5x of ingest with storage, the x ingest column: 5x the pipeline alone "
      "is less than storing one reading costs the ingest bench (docs/benchmarks.md, \"The "
      "IDS3010 replay's goal, restated\").)\n");
  fmt::print(
      "\nOver the {} round(s) (each round's replay less the same round's template, per added "
      "reading, and that round's ingest peer; the host's speed swings between rounds, so the "
      "least of each is its figure on the quietest machine):\n{}\n",
      o.rounds, fmt::join(summaries, "\n"));
  if (!o.json_out.empty()) {
    std::ofstream out(o.json_out);
    out << doc.dump(2) << '\n';
    if (!out) throw cal::InputError(fmt::format("bench replay: cannot write {}", o.json_out));
  }
  if (!all_complete)
    throw cal::InputError(
        "bench replay: a replayed run was stored incomplete (the table's last column says which "
        "and why)");
}

}  // namespace

void add_bench_replay_command(CLI::App& bench) {
  const auto [cmd, o] = add_command<ReplayBenchOptions>(
      bench, "replay", bench_replay,
      "Make a capture of every device kind at its highest rate from the simulated shop, replay "
      "each as a child daq replay (wall, CPU, peak RSS) and compare its CPU per reading with the "
      "ingest bench's pipeline measured in the same run");
  cmd->add_flag("--long", o->long_run,
                "The templates at full length: the ISO 230-2 plan (5 runs, 11 targets: 390 s "
                "recorded) and the circle at 1000 mm/min (107 s)");
  cmd->add_option("--runs", o->runs, "Runs of the linear template (without --long)")
      ->capture_default_str()
      ->check(whole_in(2, 10));
  cmd->add_option("--targets", o->targets, "Targets of the linear template (without --long)")
      ->capture_default_str()
      ->check(whole_in(2, 11));
  cmd->add_option("--circle-feed-mm-per-min", o->circle_feed_mm_per_min,
                  "The circle template's feed (without --long; 26 mm/min: a 1-hour circle)")
      ->capture_default_str()
      ->check(finite_in(10.0, 10000.0));
  cmd->add_option("--circle-vibration-um", o->circle_vibration_um,
                  "A vibration of Y in the circle template (peak, um; with "
                  "--circle-vibration-hz): the analysis then finds it and fits its lines")
      ->check(finite_in(0.0, 1000.0));
  cmd->add_option("--circle-vibration-hz", o->circle_vibration_hz,
                  "The circle template's vibration's frequency (Hz)")
      ->check(finite_in(0.0, 100000.0));
  cmd->add_option("--rounds", o->rounds, "Rounds (the peer, then every replay); medians reported")
      ->capture_default_str();
  cmd->add_option("--bench-seconds", o->bench_seconds,
                  "Recorded seconds of the peer's 10 kHz stream")
      ->capture_default_str();
  cmd->add_option("--kinds", o->kinds,
                  "Only these device kinds (comma-separated: ids3010, ptu300, gauge, ballbar, "
                  "shdr, halsampler, temper)");
  cmd->add_option("--dir", o->dir, "Directory for the captures and stores (default: $TMPDIR)");
  cmd->add_option("--json", o->json_out, "Also write the figures as JSON to this file");
  cmd->add_flag("--keep", o->keep, "Keep the captures and stores (their directory is printed)");
}

}  // namespace daq
