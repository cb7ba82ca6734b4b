// daq sync --to: the runs of a local store copied to the central store (sync.hpp).
#include "cal/storage/pg/sync.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <optional>

#include "cal/analysis/text.hpp"
#include "cal/storage/chunk.hpp"
#include "central_schema.hpp"

namespace cal::storage::pg {

bool is_postgresql_url(std::string_view text) {
  return text.starts_with("postgresql://") || text.starts_with("postgres://");
}

std::string redacted(std::string_view url) {
  // scheme://user:password@host...: the password is between the first ':' after the scheme and
  // the last '@' before the path (a password may hold '@' only percent-encoded, but be safe).
  const auto scheme = url.find("://");
  if (scheme == std::string_view::npos) return std::string(url);
  const auto auth_start = scheme + 3;
  const auto path = url.find('/', auth_start);
  const auto authority =
      url.substr(auth_start, path == std::string_view::npos ? url.npos : path - auth_start);
  const auto at = authority.rfind('@');
  if (at == std::string_view::npos) return std::string(url);
  const auto colon = authority.find(':');
  if (colon == std::string_view::npos || colon > at) return std::string(url);
  return std::string(url.substr(0, auth_start + colon + 1)) + "***" +
         std::string(url.substr(auth_start + at));
}

namespace {

std::int64_t unix_ms_now() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// libpqxx 6 has no std::optional parameters: a nullable number goes as text, '' for NULL, and
// the SQL says NULLIF($n, '')::type.
std::string nullable(const std::optional<std::int64_t>& v) {
  return v ? std::to_string(*v) : std::string();
}

std::string quality_json(const std::optional<RunQuality>& q) {
  if (!q) return {};
  // A small JSON document built by hand: storage/ does not depend on a JSON library.
  const auto quoted = [](std::string_view s) {
    std::string out = "\"";
    for (const char c : s) {
      if (c == '"' || c == '\\') {
        out += '\\';
        out += c;
      } else if (static_cast<unsigned char>(c) < 0x20) {
        out += fmt::format("\\u{:04x}", static_cast<int>(static_cast<unsigned char>(c)));
      } else {
        out += c;
      }
    }
    return out + "\"";
  };
  std::string out =
      "{\"state\":" + quoted(q->state) + ",\"summary\":" + quoted(q->summary) + ",\"suspects\":[";
  for (std::size_t i = 0; i < q->suspects.size(); ++i) {
    const auto& s = q->suspects[i];
    out += fmt::format(
        "{}{{\"run_number\":{},\"direction\":\"{}\",\"target_index\":{},\"reason\":{}}}",
        i ? "," : "", s.run_number, s.direction, s.target_index, quoted(s.reason));
  }
  return out + "]}";
}

// What the server holds of one chunk, without its bytes.
struct ServerChunk {
  std::int64_t device = 0, channel = 0, quantity = 0, first_ns = 0, last_ns = 0, count = 0,
               encoding = 0, length = 0;
  std::uint32_t crc = 0;
};

class Sync {
 public:
  Sync(const Store& local, std::string_view url, const SyncOptions& options)
      : local_(local), shown_(redacted(url)), options_(options), conn_(connect(shown_, url)) {
    if (options_.chunks_per_transaction == 0) options_.chunks_per_transaction = 1;
  }

  SyncReport run() {
    report_.server_schema = migrate_schema(*conn_, shown_);
    guarded(shown_, "prepare the statements", [&] { prepare(); });
    guarded(shown_, "read the sites this login may write", [&] { read_sites(); });
    guarded(shown_, "judge the results the server holds without a verdict",
            [&] { judge_unjudged(); });
    std::vector<RunRecord> runs;
    if (options_.run_ids.empty()) {
      runs = local_.runs();
    } else {
      for (const auto id : options_.run_ids) {
        auto r = local_.run(id);
        if (!r) throw StoreError(fmt::format("{}: no run {} to sync", local_.path().string(), id));
        runs.push_back(std::move(*r));
      }
    }
    for (const auto& r : runs) sync_run(r);
    guarded(shown_, "store the compensation tables and ballbar calibrations",
            [&] { send_records(); });
    guarded(shown_, "store the models", [&] { send_models(); });
    return report_;
  }

 private:
  const Store& local_;
  std::string shown_;
  SyncOptions options_;
  std::unique_ptr<pqxx::connection> conn_;
  SyncReport report_;
  std::vector<std::string> sites_;  // the sites this login may write (schema 7); "*": all

  void prepare() {
    conn_->prepare("insert_chunk",
                   "INSERT INTO caldaq.reading_chunks(run_uuid, seq, device, channel, quantity, "
                   "first_ns, last_ns, count, encoding, crc, stored_checksum, data) "
                   "VALUES($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12)");
  }

  std::string run_name(const RunRecord& r) const {
    return fmt::format("run {} ({})", r.id, r.uuid);
  }

  void read_sites() {
    pqxx::nontransaction n(*conn_);
    for (const auto& row : n.exec("SELECT unnest(caldaq.session_sites())"))
      sites_.push_back(row[0].as<std::string>());
  }

  // The login's sites in words, for messages.
  std::string sites_text() const {
    if (std::find(sites_.begin(), sites_.end(), "*") != sites_.end()) return "every site";
    if (sites_.empty())
      return "none: the administrator grants sites in caldaq.site_grants (docs/storage.md, "
             "\"Sites\")";
    std::string out;
    for (const auto& s : sites_) out += (out.empty() ? "'" : ", '") + text::terminal_safe(s) + "'";
    return out;
  }

  // The results on the server without daq's verdict (central schema 12; those of a server
  // migrated from 11), judged by the run's settings there, a page at a time (each its own
  // transaction): all of them by the sync that migrates (the schema owner's login sees every
  // site), those of its sites by any other's. A page that judges nothing ends it.
  void judge_unjudged() {
    if (!options_.verdict) return;
    for (;;) {
      pqxx::work w(*conn_);
      const auto rows = w.exec(
          "SELECT s.run_uuid, s.source_result_id, r.settings_json, s.json FROM caldaq.results AS "
          "s JOIN caldaq.runs AS r ON r.uuid = s.run_uuid WHERE s.verdict IS NULL "
          "ORDER BY s.run_uuid, s.source_result_id LIMIT 500");
      std::int64_t judged = 0;
      for (const auto& row : rows) {
        const auto v = options_.verdict(row[2].c_str(), row[3].c_str());
        judged += static_cast<std::int64_t>(
            w.exec_params("UPDATE caldaq.results SET verdict = $3, verdict_failed = $4 WHERE "
                          "run_uuid = $1 AND source_result_id = $2 AND verdict IS NULL",
                          row[0].as<std::string>(), row[1].as<std::int64_t>(), v.verdict, v.failed)
                .affected_rows());
      }
      w.commit();
      report_.verdicts_judged += judged;
      if (rows.size() < 500 || judged == 0) return;
    }
  }

  // The site of something new to the server (`what`: a machine, a run without one): --site, else
  // the login's one site (all it may write), else the [customer] site of the configuration it
  // was measured with (a login of several sites or all, the administrator's).
  std::string new_site(pqxx::work& w, const std::string& what, std::string_view settings_json) {
    if (!options_.site.empty()) return options_.site;
    if (sites_.size() == 1 && sites_[0] != "*") return sites_[0];
    if (!settings_json.empty()) {
      const auto row = w.exec_params1("SELECT caldaq.context_site($1)", std::string(settings_json));
      if (!row[0].is_null()) return row[0].as<std::string>();
    }
    throw StoreError(fmt::format(
        "{}: {} is new to the server and no site is known for it (no --site, no [customer] site "
        "in its configuration; this login may write {}): give --site SITE",
        shown_, what, sites_text()));
  }

  // A row refused by the sites' policies (SQLSTATE 42501), or one of that key the server holds
  // under a site this login may not see (23505: the policies hide it, its key is taken), in words.
  [[noreturn]] void refused(const pqxx::sql_error& e, const std::string& what,
                            std::string_view site) const {
    const auto state = sqlstate(e);
    const bool by_policy = state == "42501";
    if (by_policy)
      throw StoreError(fmt::format(
          "{}: {} would be of site '{}', which this login may not write (it may write {}): give "
          "--site, or ask the administrator for a grant (docs/storage.md, \"Sites\")",
          shown_, what, text::terminal_safe(site), sites_text()));
    if (state == "23505")
      throw StoreError(
          fmt::format("{}: the server holds {} under a site this login may not read or write (it "
                      "may write {}); nothing of it was sent",
                      shown_, what, sites_text()));
    throw;
  }

  void sync_run(const RunRecord& r) {
    if (r.uuid.empty())
      throw StoreError(fmt::format(
          "{}: run {} has no UUID (the database was opened read-only at an older schema)",
          local_.path().string(), r.id));
    // A run brought here by daq sync --from has another id here than in the store that first
    // sent it, whose id the server's checksums cover: they are compared and sent for that id.
    const auto source_id =
        guarded(shown_, fmt::format("store {}", run_name(r)), [&] { return send_metadata(r); });
    const auto before = report_.chunks_sent;
    const auto already_before = report_.chunks_already;
    guarded(shown_, fmt::format("send the reading chunks of {}", run_name(r)),
            [&] { send_chunks(r, source_id); });
    ++report_.runs;
    if (options_.run_done)
      options_.run_done(r, report_.chunks_sent - before, report_.chunks_already - already_before);
  }

  struct ServerMachine {
    std::string id;    // "" for none
    std::string site;  // its site on the server (schema 7)
  };

  // The server's id and site of a local machine (none for no machine), adding it. Machines are
  // known by their UUID (schema 5); one sent before, known by name only, is adopted by the first
  // store that sends a machine of that name. A new machine's site: new_site (settings_json: the
  // configuration of a run of it); a machine's site on the server is the administrator's.
  ServerMachine server_machine(pqxx::work& w, std::int64_t local_id,
                               std::string_view settings_json) {
    if (local_id <= 0) return {};
    const auto m = local_.machine(local_id);
    if (!m) return {};
    const auto what = fmt::format("machine '{}' ({})", text::terminal_safe(m->name), m->uuid);
    auto rows = w.exec_params("SELECT id, site FROM caldaq.machines WHERE uuid = $1", m->uuid);
    if (rows.empty())
      rows = w.exec_params(
          "UPDATE caldaq.machines SET uuid = $1 WHERE id = (SELECT id FROM caldaq.machines WHERE "
          "uuid IS NULL AND name = $2 ORDER BY id LIMIT 1) RETURNING id, site",
          m->uuid, m->name);
    if (!rows.empty()) {
      ServerMachine there{rows[0][0].as<std::string>(), rows[0][1].as<std::string>()};
      if (!options_.site.empty() && options_.site != there.site)
        throw StoreError(fmt::format(
            "{}: {} is of site '{}' on the server, not '{}' (--site): which site a machine is of "
            "is the administrator's to change (docs/storage.md, \"Sites\")",
            shown_, what, text::terminal_safe(there.site), text::terminal_safe(options_.site)));
      return there;
    }
    const auto site = new_site(w, what, settings_json);
    try {
      rows = w.exec_params(
          "INSERT INTO caldaq.machines(uuid, name, description, config_json, site) "
          "VALUES($1, $2, $3, $4, $5) RETURNING id",
          m->uuid, m->name, m->description, m->config_json, site);
    } catch (const pqxx::sql_error& e) {
      refused(e, what, site);
    }
    return {rows[0][0].as<std::string>(), site};
  }

  // The compensation tables and ballbar calibrations of the local store, each stored once
  // (identified by a fingerprint of its content), in the local order (so a server filled from
  // one store numbers them as it does).
  void send_records() {
    pqxx::work w(*conn_);
    for (const auto& c : local_.compensations()) {
      std::string source_uuid, settings;
      if (c.source_run_id > 0)
        if (const auto run = local_.run(c.source_run_id)) {
          source_uuid = run->uuid;
          settings = run->settings_json;
        }
      const auto machine = server_machine(w, c.machine_id, settings);
      // Its machine's site; without one, its run's (or as for a new machine).
      auto site = machine.site;
      if (site.empty() && !source_uuid.empty())
        if (const auto rows =
                w.exec_params("SELECT site FROM caldaq.runs WHERE uuid = $1", source_uuid);
            !rows.empty())
          site = rows[0][0].as<std::string>();
      const auto what = fmt::format("compensation table {}", c.id);
      if (site.empty()) site = new_site(w, what, settings);
      try {
        w.exec_params(
            "INSERT INTO caldaq.compensations(machine_id, source_run_uuid, source, axis, format, "
            "created_unix_ms, json, fingerprint, site) VALUES(NULLIF($1::text, '')::bigint, "
            "NULLIF($2::text, '')::uuid, $3::text, $4::text, $5::text, $6::bigint, $7::text, "
            "md5(concat_ws('|', $1::text, $2::text, $3::text, $4::text, $5::text, "
            "$6::bigint::text, $7::text)), $8::text) ON CONFLICT (fingerprint) DO NOTHING",
            machine.id, source_uuid, c.source, c.axis, c.format, c.created_unix_ms, c.json, site);
      } catch (const pqxx::sql_error& e) {
        refused(e, what, site);
      }
    }
    for (const auto& c : local_.bar_calibrations())
      w.exec_params(
          "INSERT INTO caldaq.bar_calibrations(bar, nominal_mm, extensions, calibrator, "
          "calibrator_length_mm, reading_mm, zero_length_mm, temperature_degc, "
          "calibrated_unix_ms, note, fingerprint) VALUES($1::text, $2::float8, $3::text, "
          "$4::text, $5::float8, $6::float8, $7::float8, NULLIF($8::text, '')::float8, "
          "$9::bigint, $10::text, md5(concat_ws('|', $1::text, $2::float8::text, $3::text, "
          "$4::text, $5::float8::text, $6::float8::text, $9::bigint::text))) "
          "ON CONFLICT (fingerprint) DO NOTHING",
          c.bar, c.nominal_mm, c.extensions, c.calibrator, c.calibrator_length_mm, c.reading_mm,
          c.zero_length_mm, c.temperature_degc ? fmt::format("{}", *c.temperature_degc) : "",
          c.calibrated_unix_ms, c.note);
    w.commit();
  }

  // The local store's models (schema 11), each stored once by its UUID (a model is never changed,
  // so one the server has is left as it is), of its machine's server id and site.
  void send_models() {
    const auto models = local_.models();
    if (models.empty()) return;
    // A machine new to the server takes its site from its latest run, as when its runs are sent.
    std::map<std::int64_t, std::string> settings;  // machine -> its latest run's settings
    for (const auto& r : local_.runs()) settings[r.machine_id] = r.settings_json;
    pqxx::work w(*conn_);
    for (const auto& m : models) {
      const auto what = fmt::format("model {}", m.uuid);
      const auto machine = server_machine(w, m.machine_id, settings[m.machine_id]);
      try {
        const auto rows = w.exec_params(
            "INSERT INTO caldaq.models(uuid, machine_id, name, json, provenance_json, stored_by, "
            "stored_from, stored_unix_ms, synced_unix_ms) VALUES($1, $2, $3, $4, $5, $6, $7, $8, "
            "$9) ON CONFLICT (uuid) DO NOTHING RETURNING id",
            m.uuid, machine.id, m.name, m.json, m.provenance_json, m.stored_by, m.stored_from,
            m.stored_unix_ms, unix_ms_now());
        ++report_.models;
        if (!rows.empty()) ++report_.models_new;
      } catch (const pqxx::sql_error& e) {
        refused(e, what, machine.site);
      }
    }
    w.commit();
  }

  // The run's row and everything small of it, in one transaction; returns the run's id in the
  // store the server's copy came from (this one's unless a copy of this database synced it).
  std::int64_t send_metadata(const RunRecord& r) {
    pqxx::work w(*conn_);
    const auto machine = server_machine(w, r.machine_id, r.settings_json);
    const auto existing =
        w.exec_params("SELECT source_run_id FROM caldaq.runs WHERE uuid = $1 FOR UPDATE", r.uuid);
    if (existing.empty()) ++report_.runs_new;
    const std::int64_t source_id = existing.empty() ? r.id : existing[0][0].as<std::int64_t>();
    const auto quality = quality_json(local_.quality(r.id));
    // A run is of its machine's site; one without a machine, of a site as a new machine.
    const auto site = !machine.site.empty() ? machine.site
                      : existing.empty()    ? new_site(w, run_name(r), r.settings_json)
                                            : std::string();
    try {
      if (existing.empty())
        w.exec_params(
            "INSERT INTO caldaq.runs(uuid, source_run_id, kind, axis, software_version, "
            "started_unix_ms, machine_id, campaign, settings_json, capture_path, ended_unix_ms, "
            "status, note, origin_session_ns, origin_unix_ns, quality_json, synced_unix_ms, site) "
            "VALUES($1, $2, $3, $4, $5, $6, NULLIF($7, '')::bigint, $8, $9, $10, "
            "NULLIF($11, '')::bigint, $12, $13, NULLIF($14, '')::bigint, "
            "NULLIF($15, '')::bigint, NULLIF($16, ''), $17, $18)",
            r.uuid, r.id, r.kind, r.axis, r.software_version, r.started_unix_ms, machine.id,
            r.campaign, r.settings_json, r.capture_path, nullable(r.ended_unix_ms),
            std::string(to_string(r.status)), r.note, nullable(r.origin_session_ns),
            nullable(r.origin_unix_ns), quality, unix_ms_now(), site);
      else  // what can change at the machine after the run began (its identity cannot)
        w.exec_params(
            "UPDATE caldaq.runs SET machine_id = NULLIF($2, '')::bigint, campaign = $3, "
            "settings_json = $4, capture_path = $5, ended_unix_ms = NULLIF($6, '')::bigint, "
            "status = $7, note = $8, origin_session_ns = NULLIF($9, '')::bigint, "
            "origin_unix_ns = NULLIF($10, '')::bigint, quality_json = NULLIF($11, ''), "
            "synced_unix_ms = $12, site = COALESCE(NULLIF($13, ''), site) WHERE uuid = $1",
            r.uuid, machine.id, r.campaign, r.settings_json, r.capture_path,
            nullable(r.ended_unix_ms), std::string(to_string(r.status)), r.note,
            nullable(r.origin_session_ns), nullable(r.origin_unix_ns), quality, unix_ms_now(),
            site);
    } catch (const pqxx::sql_error& e) {
      refused(e, run_name(r), site);
    }
    const int version = send_children(w, r);
    send_results(w, r, source_id, version);
    w.commit();
    return source_id;
  }

  // The run's instruments, missed stops, suspect stops and operator's actions are replaced as a
  // whole (they are small; the last sender's are kept); its stops become a version (send_stops),
  // never replaced, since a re-compensation elsewhere rewrites them. Returns that version.
  int send_children(pqxx::work& w, const RunRecord& r) {
    for (const char* table : {"instruments", "missed_stops", "operator_actions", "suspect_stops"})
      w.exec_params(fmt::format("DELETE FROM caldaq.{} WHERE run_uuid = $1", table), r.uuid);
    for (const auto& i : local_.instruments(r.id))
      w.exec_params(
          "INSERT INTO caldaq.instruments(run_uuid, device, driver, transport, settings_json, "
          "origin, origin_detail) VALUES($1, $2, $3, $4, $5, $6, $7)",
          r.uuid, i.device, i.driver, i.transport, i.settings_json, i.origin, i.origin_detail);
    const int version = send_stops(w, r);
    for (const auto& m : local_.missed_stops(r.id))
      w.exec_params(
          "INSERT INTO caldaq.missed_stops(run_uuid, run_number, direction, target_index, "
          "nominal_mm) VALUES($1, $2, $3, $4, $5)",
          r.uuid, m.run_number, std::string(1, m.direction), m.target_index, m.nominal_mm);
    const auto quality = local_.quality(r.id);
    w.exec_params(
        "UPDATE caldaq.runs SET quality_state = NULLIF($2, ''), quality_summary = $3 "
        "WHERE uuid = $1",
        r.uuid, quality ? quality->state : "", quality ? quality->summary : "");
    int ordinal = 0;
    if (quality)
      for (const auto& m : quality->suspects)
        w.exec_params(
            "INSERT INTO caldaq.suspect_stops(run_uuid, ordinal, run_number, direction, "
            "target_index, reason) VALUES($1, $2, $3, $4, $5, $6)",
            r.uuid, ordinal++, m.run_number, std::string(1, m.direction), m.target_index, m.reason);
    ordinal = 0;
    for (const auto& a : local_.operator_actions(r.id)) {
      const bool has_stop = a.stop.has_value();
      w.exec_params(
          "INSERT INTO caldaq.operator_actions(run_uuid, ordinal, time_unix_ms, action, source, "
          "operator, run_number, direction, target_index, nominal_mm, detail) "
          "VALUES($1, $2, $3, $4, $5, $6, NULLIF($7, '')::integer, NULLIF($8, ''), "
          "NULLIF($9, '')::integer, NULLIF($10, '')::double precision, $11)",
          r.uuid, ordinal++, a.time_unix_ms, a.action, a.source, a.operator_name,
          has_stop ? std::to_string(a.stop->run_number) : std::string(),
          has_stop ? std::string(1, a.stop->direction) : std::string(),
          has_stop ? std::to_string(a.stop->target_index) : std::string(),
          has_stop ? fmt::format("{}", a.stop->nominal_mm) : std::string(), a.detail);
    }
    return version;
  }

  // The run's stops as a version (schema 4): stops the server has as a version already add
  // nothing; others become a new version, the current one, with who sent them, from where and
  // when, the earlier versions kept. Only a run this store sent while it was still running grows
  // its version in place (the acquisition went on; nothing was changed elsewhere). Returns the
  // version the stops are (found or new).
  int send_stops(pqxx::work& w, const RunRecord& r) {
    const auto fresh =
        w.exec_params1(
             "SELECT COALESCE(MAX(version), 0) + 1 FROM caldaq.run_versions WHERE run_uuid = $1",
             r.uuid)[0]
            .as<int>();
    for (const auto& t : local_.targets(r.id))
      w.exec_params(
          "INSERT INTO caldaq.captured_targets(run_uuid, version, target_index, run_number, "
          "direction, nominal_mm, time_ns, raw_m, deviation_um, refractive_index, "
          "material_temperature_degc) VALUES($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11)",
          r.uuid, fresh, t.target_index, t.run_number, std::string(1, t.direction), t.nominal_mm,
          t.time_ns, t.raw_m, t.deviation_um, t.refractive_index, t.material_temperature_degc);
    const auto fp = w.exec_params1("SELECT caldaq.stops_fingerprint($1, $2)", r.uuid, fresh)[0]
                        .as<std::string>();
    const auto drop_fresh = [&] {
      w.exec_params("DELETE FROM caldaq.captured_targets WHERE run_uuid = $1 AND version = $2",
                    r.uuid, fresh);
    };
    const auto same = w.exec_params(
        "SELECT version FROM caldaq.run_versions WHERE run_uuid = $1 AND fingerprint = $2", r.uuid,
        fp);
    if (!same.empty()) {
      drop_fresh();
      return same[0][0].as<int>();
    }
    const auto store = std::filesystem::absolute(local_.path()).string();
    const auto growing = w.exec_params(
        "SELECT v.version FROM caldaq.run_versions AS v JOIN caldaq.runs AS r ON r.uuid = "
        "v.run_uuid AND v.version = r.current_version WHERE v.run_uuid = $1 AND v.status = "
        "'running' AND v.sent_store = $2 AND v.sent_from = $3",
        r.uuid, store, options_.sent_from);
    int version = fresh;
    if (!growing.empty()) {
      version = growing[0][0].as<int>();
      w.exec_params("DELETE FROM caldaq.captured_targets WHERE run_uuid = $1 AND version = $2",
                    r.uuid, version);
      w.exec_params(
          "UPDATE caldaq.captured_targets SET version = $3 WHERE run_uuid = $1 AND version = $2",
          r.uuid, fresh, version);
      w.exec_params("DELETE FROM caldaq.run_versions WHERE run_uuid = $1 AND version = $2", r.uuid,
                    version);
    } else if (fresh > 1) {
      ++report_.versions_new;
    }
    w.exec_params(
        "INSERT INTO caldaq.run_versions(run_uuid, version, fingerprint, status, sent_by, "
        "sent_from, sent_store, sent_unix_ms) VALUES($1, $2, $3, $4, $5, $6, $7, $8)",
        r.uuid, version, fp, std::string(to_string(r.status)), options_.sent_by, options_.sent_from,
        store, unix_ms_now());
    w.exec_params("UPDATE caldaq.runs SET current_version = $2 WHERE uuid = $1", r.uuid, version);
    return version;
  }

  // Results are known on the server by their content's fingerprint: one already there is not
  // stored again (whatever its id here: a run brought by daq sync --from numbers them anew); a
  // new one keeps its local id when this store first sent the run (source_id), else takes the
  // next free number. A supersession is added, never changed: a result superseded there stays
  // superseded by what superseded it there (results made apart are all kept).
  // Every result here is also one of `version`'s (schema 11): the version of the stops this store
  // holds, from which its current results were computed (a re-compensation supersedes every
  // current result with the new stops); its superseded ones are that version's history, as here.
  void send_results(pqxx::work& w, const RunRecord& r, std::int64_t source_id, int version) {
    const auto local = local_.results(r.id);
    std::map<std::int64_t, std::int64_t> server_id;  // local id -> the server's
    for (const auto& res : local) {
      const auto fp = result_fingerprint(w, res);
      // daq's verdict by the run's settings as sent (schema 12); NULL without a judge.
      const auto v =
          options_.verdict ? options_.verdict(r.settings_json, res.json) : StoredVerdict{};
      const bool judged = static_cast<bool>(options_.verdict);
      const auto there = w.exec_params(
          "SELECT source_result_id FROM caldaq.results WHERE run_uuid = $1 AND fingerprint = $2",
          r.uuid, fp);
      if (!there.empty()) {
        server_id[res.id] = there[0][0].as<std::int64_t>();
        // Judged again: the run's tolerances may have changed since it was sent.
        if (judged)
          w.exec_params(
              "UPDATE caldaq.results SET verdict = $3, verdict_failed = $4 WHERE run_uuid = $1 "
              "AND source_result_id = $2 AND (verdict, verdict_failed) IS DISTINCT FROM ($3, $4)",
              r.uuid, server_id[res.id], v.verdict, v.failed);
        continue;
      }
      server_id[res.id] =
          w.exec_params1(
               "INSERT INTO caldaq.results(run_uuid, source_result_id, standard, json, "
               "created_unix_ms, provenance_json, fingerprint, verdict, verdict_failed) "
               "VALUES($1::uuid, CASE WHEN $2 AND NOT EXISTS (SELECT 1 FROM caldaq.results WHERE "
               "run_uuid = $1::uuid AND source_result_id = $3) THEN $3 ELSE (SELECT "
               "COALESCE(MAX(source_result_id), 0) + 1 FROM caldaq.results WHERE run_uuid = "
               "$1::uuid) END, $4, $5, $6, $7, $8, CASE WHEN $9::boolean THEN $10::text END, CASE "
               "WHEN $9::boolean THEN "
               "$11::text END) RETURNING source_result_id",
               r.uuid, source_id == r.id, res.id, res.standard, res.json, res.created_unix_ms,
               res.provenance_json, fp, judged, v.verdict, v.failed)[0]
              .as<std::int64_t>();
    }
    for (const auto& res : local) {
      const bool superseded = res.superseded_by && server_id.contains(*res.superseded_by);
      if (superseded)
        w.exec_params(
            "UPDATE caldaq.results SET superseded_by = $3 WHERE run_uuid = $1 AND "
            "source_result_id = $2 AND superseded_by IS NULL",
            r.uuid, server_id[res.id], server_id[*res.superseded_by]);
      // In the version too, added and never cleared: another store of the same stops may have
      // superseded it there (a re-analysis), which this store's copy does not undo.
      w.exec_params(
          "INSERT INTO caldaq.result_versions(run_uuid, version, source_result_id, superseded_by) "
          "VALUES($1, $2, $3, NULLIF($4, '')::bigint) ON CONFLICT (run_uuid, version, "
          "source_result_id) DO UPDATE SET superseded_by = COALESCE("
          "caldaq.result_versions.superseded_by, EXCLUDED.superseded_by)",
          r.uuid, version, server_id[res.id],
          superseded ? std::to_string(server_id[*res.superseded_by]) : std::string());
    }
  }

  std::map<std::int64_t, ServerChunk> server_chunks(const RunRecord& r) {
    pqxx::nontransaction n(*conn_);
    const auto rows = n.exec_params(
        "SELECT seq, device, channel, quantity, first_ns, last_ns, count, encoding, crc, "
        "octet_length(data) FROM caldaq.reading_chunks WHERE run_uuid = $1 ORDER BY seq",
        r.uuid);
    std::map<std::int64_t, ServerChunk> out;
    for (const auto& row : rows)
      out[row[0].as<std::int64_t>()] = {row[1].as<std::int64_t>(),
                                        row[2].as<std::int64_t>(),
                                        row[3].as<std::int64_t>(),
                                        row[4].as<std::int64_t>(),
                                        row[5].as<std::int64_t>(),
                                        row[6].as<std::int64_t>(),
                                        row[7].as<std::int64_t>(),
                                        row[9].as<std::int64_t>(),
                                        static_cast<std::uint32_t>(row[8].as<std::int64_t>())};
    return out;
  }

  [[noreturn]] void differs(const RunRecord& r, std::int64_t seq, std::string_view how) const {
    throw StoreError(fmt::format(
        "{}: {}: the server's reading chunk {} differs from the local one ({}); nothing of it was "
        "overwritten",
        shown_, run_name(r), seq, how));
  }

  // The local chunk's checksum as the server holds it: for the run's id in its source store.
  static std::uint32_t crc_for(const Store::StoredChunk& c, std::int64_t local_id,
                               std::int64_t source_id) {
    return source_id == local_id ? c.crc
                                 : chunk::checksum(chunk::key_of(source_id, c.seq, c), c.data);
  }

  void check_same(const RunRecord& r, const Store::StoredChunk& c, std::uint32_t crc,
                  const ServerChunk& s) const {
    if (s.crc != crc)
      differs(r, c.seq, fmt::format("checksum {:08x} there, {:08x} here", s.crc, crc));
    if (s.device != c.device || s.channel != c.channel || s.quantity != c.quantity ||
        s.first_ns != c.first_ns || s.last_ns != c.last_ns || s.count != c.count ||
        s.encoding != c.encoding)
      differs(r, c.seq, "its series, times, count or encoding");
    if (s.length != static_cast<std::int64_t>(c.data.size()))
      differs(r, c.seq, fmt::format("{} bytes there, {} here", s.length, c.data.size()));
  }

  // Pages of the local chunks: those the server has are checked, the others sent, one
  // transaction per page (a cut loses at most that page, sent again next time).
  void send_chunks(const RunRecord& r, std::int64_t source_id) {
    const auto on_server = server_chunks(r);
    const std::int64_t local_count = local_.chunk_count(r.id);
    if (!on_server.empty() && on_server.rbegin()->first >= local_count)
      differs(r, on_server.rbegin()->first,
              fmt::format("the server has it, this store has {} chunks", local_count));
    std::vector<std::uint32_t> local_crcs;
    for (std::int64_t first = 0; first < local_count;) {
      const auto page = local_.stored_chunks(r.id, first, options_.chunks_per_transaction);
      if (page.empty()) break;
      first += static_cast<std::int64_t>(page.size());
      std::vector<const Store::StoredChunk*> missing;
      for (const auto& c : page) {
        local_crcs.push_back(crc_for(c, r.id, source_id));
        if (const auto it = on_server.find(c.seq); it != on_server.end()) {
          check_same(r, c, local_crcs.back(), it->second);
          ++report_.chunks_already;
        } else {
          missing.push_back(&c);
        }
      }
      if (missing.empty()) continue;
      pqxx::work w(*conn_);
      for (const auto* c : missing) {
        w.exec_prepared("insert_chunk", r.uuid, c->seq, c->device, c->channel, c->quantity,
                        c->first_ns, c->last_ns, c->count, c->encoding,
                        static_cast<std::int64_t>(crc_for(*c, r.id, source_id)), c->stored_checksum,
                        pqxx::binarystring(c->data.data(), c->data.size()));
        ++report_.chunks_sent;
        report_.bytes_sent += static_cast<std::int64_t>(c->data.size());
        if (options_.after_chunk) options_.after_chunk(report_.chunks_sent);
      }
      w.commit();
    }
    if (options_.verify_bytes) verify_bytes(r, source_id, local_crcs);
  }

  // Every chunk of the run read back from the server and its checksum recomputed over the
  // server's bytes (with the run's id in its source store, which the checksum covers).
  void verify_bytes(const RunRecord& r, std::int64_t source_id,
                    const std::vector<std::uint32_t>& local_crcs) {
    const auto page_size = static_cast<std::int64_t>(options_.chunks_per_transaction);
    std::int64_t seen = 0;
    for (std::int64_t first = 0;; first += page_size) {
      pqxx::nontransaction n(*conn_);
      const auto rows = n.exec_params(
          "SELECT seq, device, channel, quantity, first_ns, last_ns, count, encoding, crc, data "
          "FROM caldaq.reading_chunks WHERE run_uuid = $1 AND seq >= $2 ORDER BY seq LIMIT $3",
          r.uuid, first, page_size);
      if (rows.empty()) break;
      for (const auto& row : rows) {
        const chunk::Key key{.run_id = source_id,
                             .seq = row[0].as<std::int64_t>(),
                             .device = row[1].as<std::int64_t>(),
                             .channel = row[2].as<std::int64_t>(),
                             .quantity = row[3].as<std::int64_t>(),
                             .first_ns = row[4].as<std::int64_t>(),
                             .last_ns = row[5].as<std::int64_t>(),
                             .count = row[6].as<std::int64_t>(),
                             .encoding = row[7].as<std::int64_t>()};
        const pqxx::binarystring data(row[9]);
        const auto crc = chunk::checksum(key, {data.data(), data.size()});
        if (key.seq != seen) differs(r, seen, "the server does not have it");
        if (crc != static_cast<std::uint32_t>(row[8].as<std::int64_t>()))
          differs(r, key.seq, "its bytes on the server do not match its checksum");
        if (static_cast<std::size_t>(key.seq) >= local_crcs.size() || crc != local_crcs[key.seq])
          differs(r, key.seq, "its checksum is not the local chunk's");
        ++seen;
        ++report_.chunks_verified_bytes;
      }
    }
    if (seen != static_cast<std::int64_t>(local_crcs.size()))
      differs(r, seen, "the server does not have it");
  }
};

}  // namespace

SyncReport sync_to(const Store& local, std::string_view url, const SyncOptions& options) {
  return Sync(local, url, options).run();
}

int migrate(std::string_view url) {
  const auto shown = redacted(url);
  auto conn = connect(shown, url);
  return migrate_schema(*conn, shown);
}

}  // namespace cal::storage::pg
