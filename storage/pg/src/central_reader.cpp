// The central store read through RunReader (central.hpp).
#include <optional>

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

std::optional<std::int64_t> optional_int(const pqxx::field& f) {
  if (f.is_null()) return std::nullopt;
  return f.as<std::int64_t>();
}

class CentralReader final : public RunReader {
 public:
  explicit CentralReader(std::string_view url)
      : shown_(redacted(url)), conn_(guarded(shown_, "connect", [&] {
          return std::make_unique<pqxx::connection>(std::string(url));
        })) {
    guarded(shown_, "read the central schema version", [&] { check_schema(); });
  }

  std::string name() const override { return shown_; }

  std::vector<RunRecord> runs() const override {
    return guarded(shown_, "read the runs", [&] {
      pqxx::nontransaction n(*conn_);
      const auto rows = n.exec(
          "SELECT id, COALESCE(machine_id, 0), campaign, kind, axis, settings_json, capture_path, "
          "software_version, started_unix_ms, ended_unix_ms, status, note, origin_session_ns, "
          "origin_unix_ns, uuid FROM caldaq.runs ORDER BY id");
      std::vector<RunRecord> out;
      for (const auto& row : rows) {
        RunRecord r;
        r.id = row[0].as<std::int64_t>();
        r.machine_id = row[1].as<std::int64_t>();
        r.campaign = row[2].as<std::string>();
        r.kind = row[3].as<std::string>();
        r.axis = row[4].as<std::string>();
        r.settings_json = row[5].as<std::string>();
        r.capture_path = row[6].as<std::string>();
        r.software_version = row[7].as<std::string>();
        r.started_unix_ms = row[8].as<std::int64_t>();
        r.ended_unix_ms = optional_int(row[9]);
        r.status = status_from(row[10].as<std::string>());
        r.note = row[11].as<std::string>();
        r.origin_session_ns = optional_int(row[12]);
        r.origin_unix_ns = optional_int(row[13]);
        r.uuid = row[14].as<std::string>();
        out.push_back(std::move(r));
      }
      return out;
    });
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

 private:
  std::string shown_;
  std::unique_ptr<pqxx::connection> conn_;

  void check_schema() {
    pqxx::nontransaction n(*conn_);
    if (n.exec1("SELECT to_regclass('caldaq.schema_version') IS NULL")[0].as<bool>())
      throw StoreError(fmt::format(
          "{}: no caldaq central store in this database (daq sync --to creates it)", shown_));
    const auto rows = n.exec("SELECT version FROM caldaq.schema_version");
    const int version = rows.size() == 1 ? rows[0][0].as<int>() : -1;
    if (version < 1 || version > central_schema_version)
      throw StoreError(fmt::format(
          "{}: central schema version {} is not one this daq reads (1 to {}){}", shown_, version,
          central_schema_version, version > central_schema_version ? "; use a newer daq" : ""));
  }
};

}  // namespace

std::unique_ptr<RunReader> open_central(std::string_view url) {
  return std::make_unique<CentralReader>(url);
}

}  // namespace cal::storage::pg
