#pragma once
// Private to storage/: the store's connection and SQL helpers, shared by store.cpp and
// reading_stream.cpp. sqlite3.h stays in here and the .cpp files.
#include <fmt/format.h>
#include <sqlite3.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
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

// One column or parameter of a record, by the type of its field: the row mapper that every
// SELECT and INSERT of the store goes through, so that a record's columns are listed once per
// statement (in the SQL) and once in the call, in the same order. A char is a one-character
// text (a stop's direction: '+' where it is missing); an optional is NULL when empty.
inline void bind_value(sqlite3_stmt* s, int i, std::int64_t v) { sqlite3_bind_int64(s, i, v); }
inline void bind_value(sqlite3_stmt* s, int i, int v) { sqlite3_bind_int(s, i, v); }
inline void bind_value(sqlite3_stmt* s, int i, double v) { sqlite3_bind_double(s, i, v); }
inline void bind_value(sqlite3_stmt* s, int i, std::string_view v) {
  // An empty view may have a null data(), which SQLite would store as NULL, not ''.
  sqlite3_bind_text(s, i, v.empty() ? "" : v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
}
inline void bind_value(sqlite3_stmt* s, int i, char v) {
  bind_value(s, i, std::string_view(&v, 1));
}
// A BLOB is bound without a copy: its bytes must outlive the statement's step.
inline void bind_value(sqlite3_stmt* s, int i, std::span<const unsigned char> v) {
  sqlite3_bind_blob64(s, i, v.data(), v.size(), SQLITE_STATIC);
}
template <class T>
void bind_value(sqlite3_stmt* s, int i, const std::optional<T>& v) {
  if (v) bind_value(s, i, *v);  // unbound parameters are NULL
}

inline void read_value(sqlite3_stmt* s, int i, std::int64_t& v) { v = sqlite3_column_int64(s, i); }
inline void read_value(sqlite3_stmt* s, int i, int& v) { v = sqlite3_column_int(s, i); }
// A CRC-32C, stored as an integer.
inline void read_value(sqlite3_stmt* s, int i, std::uint32_t& v) {
  v = static_cast<std::uint32_t>(sqlite3_column_int64(s, i));
}
inline void read_value(sqlite3_stmt* s, int i, double& v) { v = sqlite3_column_double(s, i); }
inline void read_value(sqlite3_stmt* s, int i, std::string& v) {
  const auto* p = sqlite3_column_text(s, i);
  v = p ? reinterpret_cast<const char*>(p) : "";
}
inline void read_value(sqlite3_stmt* s, int i, char& v) {
  const auto* p = sqlite3_column_text(s, i);
  v = p && *p ? static_cast<char>(*p) : '+';
}
inline void read_value(sqlite3_stmt* s, int i, std::vector<unsigned char>& v) {
  const auto* p = static_cast<const unsigned char*>(sqlite3_column_blob(s, i));
  v.assign(p, p + sqlite3_column_bytes(s, i));
}
template <class T>
void read_value(sqlite3_stmt* s, int i, std::optional<T>& v) {
  v.reset();
  if (sqlite3_column_type(s, i) == SQLITE_NULL) return;
  read_value(s, i, v.emplace());
}

// Binds `values` to the parameters 1, 2, ... of `s`, in order.
template <class... T>
void bind_all([[maybe_unused]] sqlite3_stmt* s, const T&... values) {
  [[maybe_unused]] int i = 1;
  (bind_value(s, i++, values), ...);
}
// Reads the columns 0, 1, ... of the current row of `s` into `fields`, in order.
template <class... T>
void read_all([[maybe_unused]] sqlite3_stmt* s, T&... fields) {
  [[maybe_unused]] int i = 0;
  (read_value(s, i++, fields), ...);
}
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
  // Inside an outer one (Store::in_transaction) it is part of it: the outer one commits or
  // rolls back the whole (a failure here throws through it).
  struct Transaction {
    Impl& impl;
    bool done = false;
    bool outer = sqlite3_get_autocommit(impl.db.get()) != 0;
    explicit Transaction(Impl& i) : impl(i) {
      impl.need_writable("write");
      if (outer) impl.step_cached(impl.begin_tx, "BEGIN IMMEDIATE", "begin transaction");
    }
    void commit() {
      if (outer) impl.step_cached(impl.commit_tx, "COMMIT", "commit");
      done = true;
    }
    ~Transaction() {
      if (!done && outer) sqlite3_exec(impl.db.get(), "ROLLBACK", nullptr, nullptr, nullptr);
    }
    Transaction(const Transaction&) = delete;
    Transaction& operator=(const Transaction&) = delete;
  };
};

}  // namespace cal::storage
