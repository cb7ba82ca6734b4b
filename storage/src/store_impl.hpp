#pragma once
// Private to storage/: the store's connection and SQL helpers, shared by store.cpp and
// reading_stream.cpp. sqlite3.h stays in here and the .cpp files.
#include <fmt/format.h>
#include <sqlite3.h>

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cal/storage/chunk.hpp"
#include "cal/storage/store.hpp"

namespace cal::storage {

namespace detail {
struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
struct StmtFinalizer {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Stmt = std::unique_ptr<sqlite3_stmt, StmtFinalizer>;
}  // namespace detail

struct Store::Impl {
  std::filesystem::path path;
  std::unique_ptr<sqlite3, detail::DbCloser> db;
  int version = 0;
  bool read_only = false;
  // The chunk columns of schema 3 (encoding, seq, crc) are there: false only for an older
  // database opened read-only (read as it is, without checksums).
  bool chunk_checksums = true;
  // The stop-quality columns of schema 5 (runs.quality, captured_targets.suspect) are there:
  // false only for an older database opened read-only (its runs read as never checked).
  bool has_quality = true;

  // The writer's scratch, kept between batches so that a batch allocates nothing.
  PreparedBatch prepared;  // append_readings' scratch, reused between batches
  detail::Stmt insert_chunk, next_seq;
  // BEGIN IMMEDIATE and COMMIT, prepared once: a batch of a 10 kHz stream commits every 1.6 s,
  // and parsing the two statements each time cost about 2 % of the writer's time (issue 20).
  detail::Stmt begin_tx, commit_tx;

  [[noreturn]] void fail(std::string_view what) const {
    throw StoreError(fmt::format("{}: {}: {}", path.string(), what, sqlite3_errmsg(db.get())));
  }

  void exec(const char* sql, std::string_view what) {
    char* err = nullptr;
    if (sqlite3_exec(db.get(), sql, nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string text = err ? err : "unknown error";
      sqlite3_free(err);
      throw StoreError(fmt::format("{}: {}: {}", path.string(), what, text));
    }
  }

  detail::Stmt prepare(const char* sql, std::string_view what = "prepare") const {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db.get(), sql, -1, &s, nullptr) != SQLITE_OK) fail(what);
    return detail::Stmt(s);
  }

  // Steps a cached statement without bindings (prepared on first use) to its end; the
  // message of a failure is read before the statement is reset for its next use.
  void step_cached(detail::Stmt& s, const char* sql, std::string_view what) {
    if (!s) s = prepare(sql, what);  // a failure to prepare says what it was for
    if (sqlite3_step(s.get()) != SQLITE_DONE) {
      const std::string text = sqlite3_errmsg(db.get());
      sqlite3_reset(s.get());
      throw StoreError(fmt::format("{}: {}: {}", path.string(), what, text));
    }
    sqlite3_reset(s.get());
  }

  void step_done(sqlite3_stmt* s, std::string_view what) const {
    if (sqlite3_step(s) != SQLITE_DONE) fail(what);
    sqlite3_reset(s);
  }

  // Every writing method starts here: a read-only store refuses before touching the file.
  void need_writable(std::string_view what) const {
    if (read_only)
      throw StoreError(
          fmt::format("{}: {}: the database was opened read-only", path.string(), what));
  }

  void open_read_write(const StoreOptions& options);
  void open_read_only();
  void check_caldaq_database();
  void insert_targets(std::span<const CapturedTarget> targets);
  std::int64_t insert_result(const ResultRecord& r, Supersede how);

  // A transaction that rolls back unless committed (RAII), so a failed batch leaves the
  // database as it was before the batch, never half-written.
  struct Transaction {
    Impl& impl;
    bool done = false;
    explicit Transaction(Impl& i) : impl(i) {
      impl.need_writable("write");
      impl.step_cached(impl.begin_tx, "BEGIN IMMEDIATE", "begin transaction");
    }
    void commit() {
      impl.step_cached(impl.commit_tx, "COMMIT", "commit");
      done = true;
    }
    ~Transaction() {
      if (!done) sqlite3_exec(impl.db.get(), "ROLLBACK", nullptr, nullptr, nullptr);
    }
    Transaction(const Transaction&) = delete;
    Transaction& operator=(const Transaction&) = delete;
  };
};

}  // namespace cal::storage
