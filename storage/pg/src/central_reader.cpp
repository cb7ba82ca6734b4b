// The central store read through RunReader (central.hpp): every read command's queries, on
// PostgreSQL, giving what the SQLite Store gives for the same runs (ids are the server's; a
// result keeps the id it had where it was made; text is ordered as SQLite orders it, by byte).
#include <algorithm>
#include <map>
#include <optional>

#include "cal/analysis/text.hpp"
#include "cal/storage/pg/central.hpp"
#include "cal/storage/pg/sync.hpp"
#include "central_schema.hpp"

namespace cal::storage::pg {
namespace {

RunStatus status_from(std::string_view s) {
  if (s == "complete") return RunStatus::complete;
  if (s == "incomplete") return RunStatus::incomplete;
  if (s == "aborted") return RunStatus::aborted;
  return RunStatus::running;
}

char direction_of(const pqxx::field& f) {
  const auto s = f.as<std::string>();
  return s.empty() ? '+' : s.front();
}

// A field into a record's member, as the SQLite store reads its rows (store_impl.hpp,
// read_value): an optional is empty where the field is NULL; a char is a stop's direction.
template <class T>
void read_field(const pqxx::field& f, T& v) {
  v = f.as<T>();
}
void read_field(const pqxx::field& f, char& v) { v = direction_of(f); }
void read_field(const pqxx::field& f, RunStatus& v) { v = status_from(f.as<std::string>()); }
template <class T>
void read_field(const pqxx::field& f, std::optional<T>& v) {
  v.reset();
  if (!f.is_null()) v = f.as<T>();
}
// Reads the fields 0, 1, ... of `row` into `fields`, in order (the SQLite store's read_all).
template <class... T>
void read_row(const pqxx::row& row, T&... fields) {
  pqxx::row::size_type i = 0;
  (read_field(row[i++], fields), ...);
}

constexpr const char* kRunColumns =
    "SELECT id, COALESCE(machine_id, 0), campaign, kind, axis, settings_json, capture_path, "
    "software_version, started_unix_ms, ended_unix_ms, status, note, origin_session_ns, "
    "origin_unix_ns, uuid FROM caldaq.runs";

RunRecord run_row(const pqxx::row& row) {
  RunRecord r;
  read_row(row, r.id, r.machine_id, r.campaign, r.kind, r.axis, r.settings_json, r.capture_path,
           r.software_version, r.started_unix_ms, r.ended_unix_ms, r.status, r.note,
           r.origin_session_ns, r.origin_unix_ns, r.uuid);
  return r;
}

MachineRecord machine_row(const pqxx::row& row) {
  MachineRecord m;
  read_row(row, m.id, m.name, m.description, m.config_json);
  // A machine a v2-4 server stored before schema 5 gave it one has no UUID yet.
  if (!row[4].is_null()) m.uuid = row[4].as<std::string>();
  return m;
}

constexpr const char* kCalibrationColumns =
    "SELECT id, bar, nominal_mm, extensions, calibrator, calibrator_length_mm, reading_mm, "
    "zero_length_mm, temperature_degc, calibrated_unix_ms, note FROM caldaq.bar_calibrations";

BarCalibration calibration_row(const pqxx::row& row) {
  BarCalibration c;
  read_row(row, c.id, c.bar, c.nominal_mm, c.extensions, c.calibrator, c.calibrator_length_mm,
           c.reading_mm, c.zero_length_mm, c.temperature_degc, c.calibrated_unix_ms, c.note);
  return c;
}

constexpr const char* kModelColumns =
    "SELECT id, uuid, machine_id, name, json, provenance_json, stored_by, stored_from, "
    "stored_unix_ms FROM caldaq.models";

ModelRecord model_row(const pqxx::row& row) {
  ModelRecord m;
  read_row(row, m.id, m.uuid, m.machine_id, m.name, m.json, m.provenance_json, m.stored_by,
           m.stored_from, m.stored_unix_ms);
  return m;
}

// " AND k.quantity IN (1, 2)": the quantities are small numbers, written into the SQL.
std::string quantity_filter(std::span<const std::uint8_t> quantities) {
  if (quantities.empty()) return {};
  std::string sql = " AND k.quantity IN (";
  for (std::size_t i = 0; i < quantities.size(); ++i)
    sql += fmt::format("{}{}", i ? ", " : "", static_cast<int>(quantities[i]));
  return sql + ")";
}

// The chunks of one run, a page at a time in the order of (first_ns, seq): the order written,
// as SQLite's row order (seq numbers a run's chunks as they were written).
class PgChunks final : public ChunkSource {
 public:
  PgChunks(pqxx::connection& conn, std::string shown, std::string uuid, std::int64_t run_id,
           std::span<const std::uint8_t> quantities)
      : conn_(conn),
        shown_(std::move(shown)),
        uuid_(std::move(uuid)),
        run_id_(run_id),
        filter_(quantity_filter(quantities)) {}

  bool next(SourceChunk& out) override {
    if (pos_ == page_.size()) fetch();
    if (pos_ == page_.size()) return false;
    out = std::move(page_[pos_++]);
    return true;
  }

  std::optional<Numbered> numbered() override {
    return guarded(shown_, fmt::format("count the reading chunks of run {}", run_id_), [&] {
      pqxx::nontransaction n(conn_);
      const auto row = n.exec_params1(
          "SELECT count(*), COALESCE(MAX(seq), -1) FROM caldaq.reading_chunks AS k "
          "WHERE k.run_uuid = $1" +
              filter_,
          uuid_);
      return Numbered{row[0].as<std::int64_t>(), row[1].as<std::int64_t>()};
    });
  }

 private:
  static constexpr int kPage = 32;  // chunks per query: at most 32 x 16384 readings in memory
  pqxx::connection& conn_;
  std::string shown_, uuid_;
  std::int64_t run_id_ = 0;
  std::string filter_;
  std::vector<SourceChunk> page_;
  std::size_t pos_ = 0;
  bool started_ = false, done_ = false;
  std::int64_t last_first_ns_ = 0, last_seq_ = 0;

  void fetch() {
    page_.clear();
    pos_ = 0;
    if (done_) return;
    guarded(shown_, fmt::format("read the reading chunks of run {}", run_id_), [&] {
      pqxx::nontransaction n(conn_);
      const auto rows = n.exec_params(
          fmt::format("SELECT {} FROM caldaq.reading_chunks AS k WHERE k.run_uuid = $1 AND ($2 "
                      "OR (k.first_ns, k.seq) > ($3, $4)){} ORDER BY k.first_ns, k.seq LIMIT {}",
                      kChunkColumns, filter_, kPage),
          uuid_, !started_, last_first_ns_, last_seq_);
      for (const auto& row : rows) {
        SourceChunk c;
        read_chunk(row, c);
        c.order = *c.seq;
        page_.push_back(std::move(c));
      }
    });
    started_ = true;
    if (page_.size() < static_cast<std::size_t>(kPage)) done_ = true;
    if (!page_.empty()) {
      last_first_ns_ = page_.back().first_ns;
      last_seq_ = *page_.back().seq;
    }
  }
};

class CentralReader final : public RunReader {
 public:
  explicit CentralReader(std::string_view url)
      : shown_(redacted(url)), conn_(connect(shown_, url)) {
    guarded(shown_, "read the central schema version", [&] { check_schema(); });
  }

  std::string name() const override { return shown_; }

  std::optional<MachineRecord> machine_by_name(std::string_view name) const override {
    // Two sites may each have a machine of this name (machines are known by UUID): then the
    // name alone does not say which.
    const auto rows = all<MachineRecord>(
        fmt::format("read the machine '{}'", name),
        "SELECT id, name, description, config_json, uuid FROM caldaq.machines WHERE name = $1 "
        "ORDER BY id",
        machine_row, std::string(name));
    if (rows.size() > 1)
      throw StoreError(
          fmt::format("{}: {} machines are named '{}' (UUIDs {}, {}{}): name one by its UUID",
                      shown_, rows.size(), text::terminal_safe(name), rows[0].uuid, rows[1].uuid,
                      rows.size() > 2 ? ", ..." : ""));
    if (rows.empty()) return std::nullopt;
    return rows.front();
  }
  std::optional<MachineRecord> machine(std::int64_t id) const override {
    return one<MachineRecord>(
        fmt::format("read machine {}", id),
        "SELECT id, name, description, config_json, uuid FROM caldaq.machines WHERE id = $1",
        machine_row, id);
  }

  std::vector<RunRecord> runs() const override {
    return all<RunRecord>("read the runs", std::string(kRunColumns) + " ORDER BY id", run_row);
  }
  std::optional<RunRecord> run(std::int64_t run_id) const override {
    return one<RunRecord>(fmt::format("read run {}", run_id),
                          std::string(kRunColumns) + " WHERE id = $1", run_row, run_id);
  }

  std::vector<InstrumentRecord> instruments(std::int64_t run_id) const override {
    return all<InstrumentRecord>(
        fmt::format("read the instruments of run {}", run_id),
        "SELECT i.device, i.driver, i.transport, i.settings_json, i.origin, i.origin_detail FROM "
        "caldaq.instruments AS i JOIN caldaq.runs AS r ON r.uuid = i.run_uuid WHERE r.id = $1 "
        "ORDER BY i.device",
        [&](const pqxx::row& row) {
          InstrumentRecord i{.run_id = run_id};
          read_row(row, i.device, i.driver, i.transport, i.settings_json, i.origin,
                   i.origin_detail);
          return i;
        },
        run_id);
  }

  std::int64_t reading_count(std::int64_t run_id) const override {
    return guarded(shown_, fmt::format("count the readings of run {}", run_id), [&] {
      pqxx::nontransaction n(*conn_);
      return n
          .exec_params1(
              "SELECT COALESCE(SUM(k.count), 0) FROM caldaq.reading_chunks AS k JOIN caldaq.runs "
              "AS r ON r.uuid = k.run_uuid WHERE r.id = $1",
              run_id)[0]
          .as<std::int64_t>();
    });
  }

  ReadingStream stream_readings(std::int64_t run_id,
                                std::span<const std::uint8_t> quantities = {}) const override {
    // The chunks' checksums cover the run's id in the store that wrote them.
    const auto ids = guarded(shown_, fmt::format("read run {}", run_id), [&] {
      pqxx::nontransaction n(*conn_);
      return n.exec_params("SELECT uuid, source_run_id FROM caldaq.runs WHERE id = $1", run_id);
    });
    std::string uuid;
    std::int64_t source_id = 0;
    if (!ids.empty()) {
      uuid = ids[0][0].as<std::string>();
      source_id = ids[0][1].as<std::int64_t>();
    }
    return ReadingStream::of(std::make_unique<PgChunks>(*conn_, shown_, uuid, run_id, quantities),
                             shown_, run_id, source_id, quantities.empty());
  }

  std::vector<SeriesInfo> series(std::int64_t run_id) const override {
    return all<SeriesInfo>(
        fmt::format("read the series of run {}", run_id),
        "SELECT k.device, k.channel, k.quantity, SUM(k.count), MIN(k.first_ns), MAX(k.last_ns) "
        "FROM caldaq.reading_chunks AS k JOIN caldaq.runs AS r ON r.uuid = k.run_uuid WHERE "
        "r.id = $1 GROUP BY k.device, k.channel, k.quantity ORDER BY k.device, k.channel, "
        "k.quantity",
        [](const pqxx::row& row) {
          return SeriesInfo{static_cast<std::uint16_t>(row[0].as<int>()),
                            static_cast<std::uint8_t>(row[1].as<int>()),
                            static_cast<std::uint8_t>(row[2].as<int>()),
                            row[3].as<std::int64_t>(),
                            row[4].as<std::int64_t>(),
                            row[5].as<std::int64_t>()};
        },
        run_id);
  }

  std::vector<CapturedTarget> targets(std::int64_t run_id) const override {
    return all<CapturedTarget>(
        fmt::format("read the captured stops of run {}", run_id),
        "SELECT t.target_index, t.run_number, t.direction, t.nominal_mm, t.time_ns, t.raw_m, "
        "t.deviation_um, t.refractive_index, t.material_temperature_degc FROM "
        "caldaq.captured_targets AS t JOIN caldaq.runs AS r ON r.uuid = t.run_uuid AND "
        "t.version = COALESCE(NULLIF($2, 0), r.current_version) WHERE r.id = $1 ORDER BY "
        "t.time_ns, t.run_number, t.target_index",
        [&](const pqxx::row& row) {
          CapturedTarget t{.run_id = run_id};
          read_row(row, t.target_index, t.run_number, t.direction, t.nominal_mm, t.time_ns, t.raw_m,
                   t.deviation_um, t.refractive_index, t.material_temperature_degc);
          return t;
        },
        run_id, chosen_version(run_id));
  }

  // The results of the version read (schema 11, result_versions): those computed from its stops
  // and that version's history, with its supersessions; never another version's results.
  std::vector<ResultRecord> results(std::int64_t run_id) const override {
    return all<ResultRecord>(
        fmt::format("read the results of run {}", run_id),
        "SELECT s.standard, s.json, s.created_unix_ms, s.provenance_json, s.source_result_id, "
        "m.superseded_by FROM caldaq.results AS s JOIN caldaq.runs AS r ON r.uuid = s.run_uuid "
        "JOIN caldaq.result_versions AS m ON m.run_uuid = s.run_uuid AND m.source_result_id = "
        "s.source_result_id AND m.version = COALESCE(NULLIF($2, 0), r.current_version) WHERE "
        "r.id = $1 ORDER BY s.source_result_id",
        [&](const pqxx::row& row) {
          ResultRecord r{.run_id = run_id};
          read_row(row, r.standard, r.json, r.created_unix_ms, r.provenance_json, r.id,
                   r.superseded_by);
          return r;
        },
        run_id, chosen_version(run_id));
  }

  std::optional<RunQuality> quality(std::int64_t run_id) const override {
    const auto head = one<RunQuality>(
        fmt::format("read the stop quality of run {}", run_id),
        "SELECT quality_state, quality_summary FROM caldaq.runs WHERE id = $1 AND "
        "quality_state IS NOT NULL",
        [](const pqxx::row& row) {
          RunQuality q;
          read_row(row, q.state, q.summary);
          return q;
        },
        run_id);
    if (!head) return std::nullopt;
    RunQuality q = *head;
    q.suspects = all<StopMark>(
        fmt::format("read the suspect stops of run {}", run_id),
        "SELECT s.run_number, s.direction, s.target_index, s.reason FROM caldaq.suspect_stops AS "
        "s JOIN caldaq.runs AS r ON r.uuid = s.run_uuid WHERE r.id = $1 ORDER BY s.ordinal",
        [](const pqxx::row& row) {
          StopMark m;
          read_row(row, m.run_number, m.direction, m.target_index, m.reason);
          return m;
        },
        run_id);
    return q;
  }

  std::vector<MissedStop> missed_stops(std::int64_t run_id) const override {
    return all<MissedStop>(
        fmt::format("read the missed stops of run {}", run_id),
        "SELECT m.run_number, m.direction, m.target_index, m.nominal_mm FROM caldaq.missed_stops "
        "AS m JOIN caldaq.runs AS r ON r.uuid = m.run_uuid WHERE r.id = $1 ORDER BY "
        "m.run_number, m.direction COLLATE \"C\", m.target_index",
        [&](const pqxx::row& row) {
          MissedStop m{.run_id = run_id};
          read_row(row, m.run_number, m.direction, m.target_index, m.nominal_mm);
          return m;
        },
        run_id);
  }

  std::vector<OperatorAction> operator_actions(std::int64_t run_id) const override {
    return all<OperatorAction>(
        fmt::format("read the operator's actions of run {}", run_id),
        "SELECT a.time_unix_ms, a.action, a.source, a.operator, a.run_number, a.direction, "
        "a.target_index, a.nominal_mm, a.detail FROM caldaq.operator_actions AS a JOIN "
        "caldaq.runs AS r ON r.uuid = a.run_uuid WHERE r.id = $1 ORDER BY a.ordinal",
        [&](const pqxx::row& row) {
          OperatorAction a{.run_id = run_id,
                           .time_unix_ms = row[0].as<std::int64_t>(),
                           .action = row[1].as<std::string>(),
                           .source = row[2].as<std::string>(),
                           .operator_name = row[3].as<std::string>(),
                           .detail = row[8].as<std::string>()};
          if (!row[4].is_null())
            a.stop = MissedStop{.run_id = run_id,
                                .run_number = row[4].as<int>(),
                                .direction = direction_of(row[5]),
                                .target_index = row[6].as<int>(),
                                .nominal_mm = row[7].as<double>()};
          return a;
        },
        run_id);
  }

  std::vector<BarCalibration> bar_calibrations(std::string_view bar = {}) const override {
    return all<BarCalibration>("read the ballbar calibrations",
                               std::string(kCalibrationColumns) +
                                   " WHERE $1 = '' OR bar = $1 ORDER BY calibrated_unix_ms, id",
                               calibration_row, std::string(bar));
  }
  std::optional<BarCalibration> bar_calibration(std::string_view bar, double nominal_mm,
                                                std::int64_t at_unix_ms) const override {
    return one<BarCalibration>(
        fmt::format("read the calibration of ballbar '{}'", bar),
        std::string(kCalibrationColumns) +
            " WHERE bar = $1 AND abs(nominal_mm - $2) < 1e-3 AND calibrated_unix_ms <= $3 ORDER "
            "BY calibrated_unix_ms DESC, id DESC LIMIT 1",
        calibration_row, std::string(bar), nominal_mm, at_unix_ms);
  }

  std::vector<CompensationRecord> compensations(std::int64_t machine_id = 0,
                                                std::string_view axis = {}) const override {
    return all<CompensationRecord>(
        "read the compensation tables",
        "SELECT c.id, COALESCE(c.machine_id, 0), COALESCE(r.id, 0), c.source, c.axis, c.format, "
        "c.created_unix_ms, c.json FROM caldaq.compensations AS c LEFT JOIN caldaq.runs AS r ON "
        "r.uuid = c.source_run_uuid WHERE ($1 = 0 OR c.machine_id = $1) AND ($2 = '' OR c.axis "
        "= $2) ORDER BY c.created_unix_ms, c.id",
        [](const pqxx::row& row) {
          CompensationRecord c;
          read_row(row, c.id, c.machine_id, c.source_run_id, c.source, c.axis, c.format,
                   c.created_unix_ms, c.json);
          return c;
        },
        machine_id, std::string(axis));
  }

  std::vector<ModelRecord> models(std::int64_t machine_id = 0) const override {
    return all<ModelRecord>(
        "read the models",
        std::string(kModelColumns) + " WHERE $1 = 0 OR machine_id = $1 ORDER BY id", model_row,
        machine_id);
  }
  std::optional<ModelRecord> model(std::int64_t id) const override {
    return one<ModelRecord>(fmt::format("read model {}", id),
                            std::string(kModelColumns) + " WHERE id = $1", model_row, id);
  }
  std::optional<ModelRecord> model_by_uuid(std::string_view uuid) const override {
    if (!is_uuid(uuid)) return std::nullopt;  // the server would refuse it as a uuid
    return one<ModelRecord>(fmt::format("read model {}", uuid),
                            std::string(kModelColumns) + " WHERE uuid = $1::uuid", model_row,
                            std::string(uuid));
  }

  std::vector<RunVersion> versions(std::int64_t run_id) const override {
    return all<RunVersion>(
        fmt::format("read the versions of run {}", run_id),
        "SELECT v.version, v.status, v.sent_by, v.sent_from, v.sent_store, v.sent_unix_ms, "
        "(SELECT count(*) FROM caldaq.captured_targets AS t WHERE t.run_uuid = v.run_uuid AND "
        "t.version = v.version), v.version = r.current_version FROM caldaq.run_versions AS v "
        "JOIN caldaq.runs AS r ON r.uuid = v.run_uuid WHERE r.id = $1 ORDER BY v.version",
        [](const pqxx::row& row) {
          RunVersion v;
          read_row(row, v.version, v.status, v.sent_by, v.sent_from, v.sent_store, v.sent_unix_ms,
                   v.stops, v.current);
          return v;
        },
        run_id);
  }

  // read_version (central.hpp).

  void read_version(std::int64_t run_id, int version) {
    if (!run(run_id)) throw StoreError(fmt::format("{}: no run {}", shown_, run_id));
    const auto there = versions(run_id);
    if (std::none_of(there.begin(), there.end(),
                     [&](const RunVersion& v) { return v.version == version; }))
      throw StoreError(fmt::format(
          "{}: run {} has no version {} (it has {}: daq show {} --db ... lists them)", shown_,
          run_id, version,
          there.size() == 1 ? std::string("one, 1")
                            : fmt::format("1 to {}", there.empty() ? 0 : there.back().version),
          run_id));
    chosen_[run_id] = version;
  }

  // The approvals of the version's results (results()).
  std::vector<Approval> approvals(std::int64_t run_id) const override {
    return all<Approval>(
        fmt::format("read the approvals of run {}", run_id),
        "SELECT s.source_result_id, a.result_fingerprint, a.run_version, a.approved_by, "
        "a.approved_unix_ms FROM caldaq.approvals AS a JOIN caldaq.runs AS r ON r.uuid = "
        "a.run_uuid JOIN caldaq.results AS s ON s.run_uuid = a.run_uuid AND s.fingerprint = "
        "a.result_fingerprint JOIN caldaq.result_versions AS m ON m.run_uuid = s.run_uuid AND "
        "m.source_result_id = s.source_result_id AND m.version = COALESCE(NULLIF($2, 0), "
        "r.current_version) WHERE r.id = $1 ORDER BY a.approved_unix_ms, s.source_result_id",
        [&](const pqxx::row& row) {
          Approval a{.central_server = shown_};
          read_row(row, a.result_id, a.result_fingerprint, a.run_version, a.approved_by,
                   a.approved_unix_ms);
          return a;
        },
        run_id, chosen_version(run_id));
  }

 private:
  std::string shown_;
  std::unique_ptr<pqxx::connection> conn_;
  std::map<std::int64_t, int> chosen_;  // run id -> the version read_version chose

  // The version of the run's stops to read; 0: the current one.
  int chosen_version(std::int64_t run_id) const {
    const auto it = chosen_.find(run_id);
    return it == chosen_.end() ? 0 : it->second;
  }

  // The rows of a query, each made into a T; errors name the server and `what`.
  template <class T, class F, class... Args>
  std::vector<T> all(const std::string& what, const std::string& sql, F&& make,
                     Args&&... args) const {
    return guarded(shown_, what, [&] {
      pqxx::nontransaction n(*conn_);
      const auto rows = n.exec_params(sql, std::forward<Args>(args)...);
      std::vector<T> out;
      out.reserve(rows.size());
      for (const auto& row : rows) out.push_back(make(row));
      return out;
    });
  }
  template <class T, class F, class... Args>
  std::optional<T> one(const std::string& what, const std::string& sql, F&& make,
                       Args&&... args) const {
    auto rows = all<T>(what, sql, std::forward<F>(make), std::forward<Args>(args)...);
    if (rows.empty()) return std::nullopt;
    return std::move(rows.front());
  }

  void check_schema() { check_reader_schema(*conn_, shown_); }
};

}  // namespace

std::unique_ptr<RunReader> open_central(std::string_view url) {
  return std::make_unique<CentralReader>(url);
}

void read_version(RunReader& central, std::int64_t run_id, int version) {
  auto* reader = dynamic_cast<CentralReader*>(&central);
  if (reader == nullptr)
    throw StoreError(
        fmt::format("{}: not a central store: it keeps one version of each run", central.name()));
  reader->read_version(run_id, version);
}

Approval approve_central(std::string_view url, std::int64_t run_id, std::int64_t result_id) {
  const std::string shown = redacted(url);
  const auto conn = connect(shown, url);
  return guarded(shown, fmt::format("approve result {} of run {}", result_id, run_id), [&] {
    pqxx::work w(*conn);
    const auto found = w.exec_params(
        "SELECT r.uuid, s.fingerprint FROM caldaq.runs AS r LEFT JOIN caldaq.results AS s ON "
        "s.run_uuid = r.uuid AND s.source_result_id = $2 WHERE r.id = $1",
        run_id, result_id);
    if (found.empty()) throw StoreError(fmt::format("{}: no run {}", shown, run_id));
    if (found[0][1].is_null())
      throw StoreError(fmt::format("{}: run {} has no result {}", shown, run_id, result_id));
    Approval a{.result_id = result_id,
               .result_fingerprint = found[0][1].as<std::string>(),
               .central_server = shown};
    // The server checks the rest (a reviewer's login; the result current, not approved yet) and
    // names the reviewer: nothing the client says is taken for who approved.
    const auto row = w.exec_params1(
        "SELECT approved_by, approved_unix_ms, run_version FROM "
        "caldaq.approve($1::uuid, $2::text)",
        found[0][0].as<std::string>(), a.result_fingerprint);
    read_row(row, a.approved_by, a.approved_unix_ms, a.run_version);
    w.commit();
    return a;
  });
}

}  // namespace cal::storage::pg
