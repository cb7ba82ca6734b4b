// daq sync --from: one machine's history brought from the central store into a local store
// (sync.hpp, sync_from).
#include <algorithm>
#include <filesystem>
#include <map>
#include <tuple>

#include "cal/analysis/text.hpp"
#include "cal/storage/chunk.hpp"
#include "cal/storage/pg/central.hpp"
#include "cal/storage/pg/sync.hpp"
#include "central_schema.hpp"

namespace cal::storage::pg {
namespace {

// The server's side of a pull: its connections and the machine asked for, found before anything
// is written here.
struct Source {
  std::string shown;  // the URI, password hidden
  std::unique_ptr<pqxx::connection> conn;
  std::unique_ptr<RunReader> reader;  // checks the central schema's version (never migrates)
  MachineRecord machine;
  std::vector<std::string> chosen;  // the UUIDs of the runs brought at a chosen version
};

// --version RUN:N: the run (the server's id or its UUID), of the machine, read at version N.
void choose_versions(Source& source, const std::vector<PullOptions::VersionChoice>& choices) {
  for (const auto& c : choices) {
    const auto rows = guarded(source.shown, "read the runs", [&] {
      pqxx::nontransaction n(*source.conn);
      return n.exec_params(
          "SELECT id, uuid, COALESCE(machine_id, 0) FROM caldaq.runs WHERE uuid::text = $1 OR "
          "id::text = $1",
          c.run);
    });
    if (rows.empty())
      throw StoreError(fmt::format("{}: no run {} in the central store (--version {}:{})",
                                   source.shown, text::terminal_safe(c.run),
                                   text::terminal_safe(c.run), c.version));
    const auto id = rows[0][0].as<std::int64_t>();
    if (rows[0][2].as<std::int64_t>() != source.machine.id)
      throw StoreError(fmt::format("{}: run {} is not of machine '{}' (--version {}:{})",
                                   source.shown, id, text::terminal_safe(source.machine.name),
                                   text::terminal_safe(c.run), c.version));
    read_version(*source.reader, id, c.version);
    source.chosen.push_back(rows[0][1].as<std::string>());
  }
}

// --machine: a machine's UUID, or a name only one machine on the server has.
MachineRecord find_machine(Source& source, const std::string& machine) {
  if (is_uuid(machine)) {
    const auto id = guarded(source.shown, "read the machines", [&] {
      pqxx::nontransaction n(*source.conn);
      const auto rows = n.exec_params("SELECT id FROM caldaq.machines WHERE uuid = $1", machine);
      return rows.empty() ? std::int64_t{0} : rows[0][0].as<std::int64_t>();
    });
    if (const auto m = id ? source.reader->machine(id) : std::nullopt) return *m;
  } else if (const auto m = source.reader->machine_by_name(machine)) {
    return *m;
  }
  throw StoreError(fmt::format("{}: no machine '{}' in the central store", source.shown,
                               text::terminal_safe(machine)));
}

Source open_source(std::string_view url, const std::string& machine,
                   const std::vector<PullOptions::VersionChoice>& versions) {
  Source source{.shown = redacted(url)};
  source.conn = connect(source.shown, url);
  source.reader = open_central(url);
  source.machine = find_machine(source, machine);
  choose_versions(source, versions);
  return source;
}

// A run brought at a chosen version must be new here: this store keeps one version of it.
void check_chosen_new(const Store& local, const Source& source) {
  for (const auto& uuid : source.chosen)
    if (const auto here = local.run_by_uuid(uuid))
      throw StoreError(fmt::format(
          "{}: run {} ({}) is here already, with its stops as they were brought or measured: a "
          "store keeps one version of a run; bring another version into another store (--db)",
          local.path().string(), here->id, uuid));
}

class Pull {
 public:
  Pull(Store& local, Source source, const PullOptions& options)
      : local_(local),
        shown_(std::move(source.shown)),
        options_(options),
        conn_(std::move(source.conn)),
        server_(std::move(source.reader)),
        machine_(std::move(source.machine)) {
    if (options_.chunks_per_transaction == 0) options_.chunks_per_transaction = 1;
  }

  PullReport run() {
    report_.server_schema = central_schema_version;
    local_machine_ = local_machine(machine_);
    for (const auto& r : server_->runs())
      if (r.machine_id == machine_.id) pull_run(r);
    pull_compensations(machine_.id);
    pull_calibrations();
    pull_models(machine_.id);
    return report_;
  }

 private:
  Store& local_;
  std::string shown_;
  PullOptions options_;
  std::unique_ptr<pqxx::connection> conn_;
  std::unique_ptr<RunReader> server_;
  MachineRecord machine_;  // the server's
  std::int64_t local_machine_ = 0;
  PullReport report_;

  // The server's machine here: known by its UUID; added (with it) when this store has none of
  // its name. Another machine of its name here (another site's) is an error: they stay apart.
  std::int64_t local_machine(const MachineRecord& m) {
    if (!m.uuid.empty())
      if (const auto here = local_.machine_by_uuid(m.uuid)) return here->id;
    if (const auto here = local_.machine_by_name(m.name)) {
      if (m.uuid.empty()) return here->id;  // sent before machines had UUIDs: by name
      throw StoreError(fmt::format(
          "{}: this store's machine '{}' is another one (UUID {}) than the server's (UUID {}): "
          "bring its history into another store",
          local_.path().string(), text::terminal_safe(m.name), here->uuid, m.uuid));
    }
    return local_.add_machine({.name = m.name,
                               .description = m.description,
                               .config_json = m.config_json,
                               .uuid = m.uuid});
  }

  std::string run_name(const RunRecord& r) const {
    return fmt::format("run {} ({})", r.id, r.uuid);
  }

  void pull_run(const RunRecord& r) {
    const auto source_id = guarded(shown_, fmt::format("read {}", run_name(r)), [&] {
      pqxx::nontransaction n(*conn_);
      return n.exec_params1("SELECT source_run_id FROM caldaq.runs WHERE uuid = $1", r.uuid)[0]
          .as<std::int64_t>();
    });
    std::int64_t local_id = 0;
    local_.in_transaction([&] {
      const auto existing = local_.run_by_uuid(r.uuid);
      local_id = existing ? existing->id : import_metadata(r);
      if (existing && existing->status == RunStatus::running) update_running(r, local_id);
      if (existing) refresh_operator_actions(r, local_id);
      // A run here already: the results of the version its stops here are (none when they are
      // no version the server has: re-compensated here and not sent yet).
      pull_results(r, local_id, !existing || version_of_stops_here(r, local_id));
    });
    const auto received = report_.chunks_received, already = report_.chunks_already;
    pull_chunks(r, local_id, source_id);
    ++report_.runs;
    if (options_.run_done)
      options_.run_done(*local_.run(local_id), report_.chunks_received - received,
                        report_.chunks_already - already);
  }

  // A run this store does not have: its row and everything small of it (in the caller's
  // transaction, with its results).
  std::int64_t import_metadata(const RunRecord& r) {
    RunRecord copy = r;
    copy.machine_id = local_machine_;
    const auto id = local_.import_run(copy);
    ++report_.runs_new;
    for (auto i : server_->instruments(r.id)) {
      i.run_id = id;
      local_.add_instrument(i);
    }
    auto targets = server_->targets(r.id);
    for (auto& t : targets) t.run_id = id;
    local_.add_targets(targets);
    local_.set_missed_stops(id, server_->missed_stops(r.id));
    if (const auto q = server_->quality(r.id)) local_.set_quality(id, *q);
    for (auto a : server_->operator_actions(r.id)) {
      a.run_id = id;
      if (a.stop) a.stop->run_id = id;
      local_.add_operator_action(a);
    }
    return id;
  }

  // A run brought while it was still running: what the server holds of it now (its status, end
  // and note; its stops, missed stops and quality, which grow as it runs). A run acquired here
  // is left as it is (its own acquisition writes it).
  void update_running(const RunRecord& r, std::int64_t local_id) {
    RunRecord now = r;
    now.id = local_id;
    if (!local_.update_imported_run(now)) return;
    auto targets = server_->targets(r.id);
    for (auto& t : targets) t.run_id = local_id;
    local_.replace_targets(local_id, targets);
    local_.set_missed_stops(local_id, server_->missed_stops(r.id));
    if (const auto q = server_->quality(r.id)) local_.set_quality(local_id, *q);
  }

  // The operator's actions of a run brought here before, as the server has them now (a manual
  // capture or skip made after the last pull, sent from the machine since). A run acquired here
  // keeps its own (its acquisition wrote them).
  void refresh_operator_actions(const RunRecord& r, std::int64_t local_id) {
    const auto theirs = server_->operator_actions(r.id);
    const auto here = local_.operator_actions(local_id);
    const auto same = [](const OperatorAction& a, const OperatorAction& b) {
      const bool stops_same = a.stop.has_value() == b.stop.has_value() &&
                              (!a.stop || (a.stop->run_number == b.stop->run_number &&
                                           a.stop->direction == b.stop->direction &&
                                           a.stop->target_index == b.stop->target_index &&
                                           a.stop->nominal_mm == b.stop->nominal_mm));
      return stops_same && a.time_unix_ms == b.time_unix_ms && a.action == b.action &&
             a.source == b.source && a.operator_name == b.operator_name && a.detail == b.detail;
    };
    if (std::equal(theirs.begin(), theirs.end(), here.begin(), here.end(), same)) return;
    if (local_.replace_imported_operator_actions(local_id, theirs))
      ++report_.operator_actions_refreshed;
  }

  // The server's results this store lacks (known by their content's fingerprint, as the server
  // knows them), the supersessions the server records between results this store has, and the
  // server's approvals of them (read-only here: a report here is issued as the server's).
  // Only the results of the version read (the server's reader reads one version's), and none
  // when `bring` is false: results are brought only beside the stops they were computed from.
  void pull_results(const RunRecord& r, std::int64_t local_id, bool bring) {
    const auto theirs = bring ? server_->results(r.id) : std::vector<ResultRecord>{};
    std::map<std::string, std::int64_t> local_by_fp;  // fingerprint -> local id
    std::map<std::int64_t, bool> local_current;       // local id -> not superseded
    std::map<std::int64_t, std::string> fp_of;        // server id -> fingerprint
    guarded(shown_, fmt::format("fingerprint the results of {}", run_name(r)), [&] {
      pqxx::nontransaction n(*conn_);
      for (const auto& res : local_.results(local_id)) {
        local_by_fp[result_fingerprint(n, res)] = res.id;
        local_current[res.id] = res.current();
      }
      for (const auto& row : n.exec_params(
               "SELECT source_result_id, fingerprint FROM caldaq.results WHERE run_uuid = $1",
               r.uuid))
        fp_of[row[0].as<std::int64_t>()] = row[1].as<std::string>();
    });
    for (const auto& res : theirs) {
      if (local_by_fp.contains(fp_of[res.id])) continue;
      ResultRecord copy = res;
      copy.run_id = local_id;
      copy.superseded_by.reset();
      const auto id = local_.add_result(copy, Supersede::none);
      local_by_fp[fp_of[res.id]] = id;
      local_current[id] = true;
      ++report_.results_new;
    }
    for (const auto& res : theirs) {
      if (!res.superseded_by || !fp_of.contains(*res.superseded_by)) continue;
      const auto id = local_by_fp.at(fp_of[res.id]);
      if (local_current[id]) local_.set_superseded(id, local_by_fp.at(fp_of[*res.superseded_by]));
    }
    for (auto a : server_->approvals(r.id)) {
      const auto here = local_by_fp.find(a.result_fingerprint);
      if (here == local_by_fp.end()) continue;  // every result of the run was brought above
      a.result_id = here->second;
      a.central_server = shown_;
      if (local_.add_central_approval(a)) ++report_.approvals_new;
    }
  }

  // Whether this store's stops of the run are one of the server's versions; if so the server's
  // reader reads that version from now on.
  bool version_of_stops_here(const RunRecord& r, std::int64_t local_id) {
    const auto sorted = [](std::vector<CapturedTarget> v) {
      const auto key = [](const CapturedTarget& t) {
        return std::tuple(t.run_number, t.direction, t.target_index, t.nominal_mm, t.time_ns,
                          t.raw_m, t.deviation_um, t.refractive_index, t.material_temperature_degc);
      };
      std::sort(v.begin(), v.end(),
                [&](const CapturedTarget& a, const CapturedTarget& b) { return key(a) < key(b); });
      std::vector<decltype(key(v.front()))> keys;
      for (const auto& t : v) keys.push_back(key(t));
      return keys;
    };
    const auto here = sorted(local_.targets(local_id));
    auto versions = server_->versions(r.id);
    // The current version first (the usual case), then the others in order.
    std::stable_partition(versions.begin(), versions.end(),
                          [](const RunVersion& v) { return v.current; });
    for (const auto& v : versions) {
      read_version(*server_, r.id, v.version);
      if (sorted(server_->targets(r.id)) == here) return true;
    }
    return false;
  }

  // The checksums the server holds for the run's chunks, by number.
  std::map<std::int64_t, std::uint32_t> server_crcs(const RunRecord& r) {
    return guarded(shown_, fmt::format("read the chunk checksums of {}", run_name(r)), [&] {
      pqxx::nontransaction n(*conn_);
      std::map<std::int64_t, std::uint32_t> out;
      for (const auto& row :
           n.exec_params("SELECT seq, crc FROM caldaq.reading_chunks WHERE run_uuid = $1", r.uuid))
        out[row[0].as<std::int64_t>()] = static_cast<std::uint32_t>(row[1].as<std::int64_t>());
      return out;
    });
  }

  [[noreturn]] void differs(const RunRecord& r, std::int64_t seq, std::string_view how) const {
    throw StoreError(fmt::format(
        "{}: {}: the local reading chunk {} differs from the server's ({}); nothing of it was "
        "overwritten",
        local_.path().string(), run_name(r), seq, how));
  }

  // The chunks here are checked against the server's checksums (for the run's id in the store
  // that sent it, which the checksums cover); the rest are received a page at a time, each
  // checked over the bytes received before it is stored.
  void pull_chunks(const RunRecord& r, std::int64_t local_id, std::int64_t source_id) {
    const auto crcs = server_crcs(r);
    const auto have = local_.chunk_count(local_id);
    for (std::int64_t first = 0; first < have;) {
      const auto page = local_.stored_chunks(local_id, first, options_.chunks_per_transaction);
      if (page.empty()) break;
      first += static_cast<std::int64_t>(page.size());
      for (const auto& c : page) {
        const auto it = crcs.find(c.seq);
        if (it == crcs.end()) continue;  // sent from here and not yet synced
        const auto crc = chunk::checksum(chunk::key_of(source_id, c.seq, c), c.data);
        if (crc != it->second)
          differs(r, c.seq, fmt::format("checksum {:08x} there, {:08x} here", it->second, crc));
        ++report_.chunks_already;
      }
    }
    const auto page_size = static_cast<std::int64_t>(options_.chunks_per_transaction);
    for (std::int64_t first = have;; first += page_size) {
      auto page = receive_page(r, source_id, first, page_size);
      if (page.empty()) break;
      local_.in_transaction([&] {
        local_.add_stored_chunks(local_id, page);
        for (const auto& c : page) {
          ++report_.chunks_received;
          report_.bytes_received += static_cast<std::int64_t>(c.data.size());
          if (options_.after_chunk) options_.after_chunk(report_.chunks_received);
        }
      });
    }
  }

  std::vector<Store::StoredChunk> receive_page(const RunRecord& r, std::int64_t source_id,
                                               std::int64_t first, std::int64_t count) {
    return guarded(shown_, fmt::format("receive the reading chunks of {}", run_name(r)), [&] {
      pqxx::nontransaction n(*conn_);
      const auto rows = n.exec_params(
          fmt::format("SELECT {} FROM caldaq.reading_chunks WHERE run_uuid = $1 AND seq >= $2 "
                      "ORDER BY seq LIMIT $3",
                      kChunkColumns),
          r.uuid, first, count);
      std::vector<Store::StoredChunk> out;
      for (const auto& row : rows) {
        Store::StoredChunk c;
        read_chunk(row, c);
        const auto crc = chunk::checksum(chunk::key_of(source_id, c.seq, c), c.data);
        if (c.seq != first + static_cast<std::int64_t>(out.size()))
          throw StoreError(fmt::format("{}: {}: the server lacks reading chunk {}", shown_,
                                       run_name(r), first + static_cast<std::int64_t>(out.size())));
        if (crc != c.crc)
          throw StoreError(fmt::format(
              "{}: {}: the server's reading chunk {} does not match its checksum (its bytes or "
              "row were damaged there); nothing of it was stored",
              shown_, run_name(r), c.seq));
        out.push_back(std::move(c));
      }
      return out;
    });
  }

  // The machine's compensation tables this store lacks (the same source, axis, format, time and
  // table), their source run found here by its UUID.
  void pull_compensations(std::int64_t server_machine) {
    const auto here = local_.compensations(local_machine_);
    for (auto c : server_->compensations(server_machine)) {
      const auto same = [&](const CompensationRecord& h) {
        return h.source == c.source && h.axis == c.axis && h.format == c.format &&
               h.created_unix_ms == c.created_unix_ms && h.json == c.json;
      };
      if (std::any_of(here.begin(), here.end(), same)) continue;
      c.machine_id = local_machine_;
      const auto source = c.source_run_id ? server_->run(c.source_run_id) : std::nullopt;
      const auto source_here = source ? local_.run_by_uuid(source->uuid) : std::nullopt;
      c.source_run_id = source_here ? source_here->id : 0;
      local_.add_compensation(c);
      ++report_.compensations_new;
    }
  }

  // The machine's models this store lacks (by UUID), as stored where they were made: their
  // text, provenance, who stored them, from where and when.
  void pull_models(std::int64_t server_machine) {
    for (auto m : server_->models(server_machine)) {
      if (local_.model_by_uuid(m.uuid)) continue;
      m.machine_id = local_machine_;
      local_.add_model(m);
      ++report_.models_new;
    }
  }

  // The ballbar calibrations this store lacks (the same bar, length, calibrator, reading, time).
  void pull_calibrations() {
    const auto here = local_.bar_calibrations();
    for (const auto& c : server_->bar_calibrations()) {
      const auto same = [&](const BarCalibration& h) {
        return h.bar == c.bar && h.nominal_mm == c.nominal_mm && h.calibrator == c.calibrator &&
               h.reading_mm == c.reading_mm && h.calibrated_unix_ms == c.calibrated_unix_ms;
      };
      if (std::any_of(here.begin(), here.end(), same)) continue;
      local_.add_bar_calibration(c);
      ++report_.calibrations_new;
    }
  }
};

}  // namespace

PullReport sync_from(const std::filesystem::path& local_path, std::string_view url,
                     const PullOptions& options) {
  auto source = open_source(url, options.machine, options.versions);
  Store local(local_path);  // created only now: a refused pull leaves nothing behind
  check_chosen_new(local, source);
  return Pull(local, std::move(source), options).run();
}

}  // namespace cal::storage::pg
