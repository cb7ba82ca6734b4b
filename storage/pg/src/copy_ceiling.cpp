// The COPY ceiling of `daq bench sync` (copy_ceiling.hpp). libpq directly: libpqxx 6.4's
// stream_to writes COPY's text format, whose bytea escaping doubles every byte, which would make
// the ceiling slower than the sync's binary parameters and flatter the sync.
#include "cal/storage/pg/copy_ceiling.hpp"

#include <fmt/format.h>
#include <libpq-fe.h>

#include <chrono>
#include <memory>
#include <string>
#include <type_traits>

#include "cal/storage/pg/sync.hpp"

namespace cal::storage::pg {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct ConnDeleter {
  void operator()(PGconn* c) const { PQfinish(c); }
};
using Conn = std::unique_ptr<PGconn, ConnDeleter>;
struct ResultDeleter {
  void operator()(PGresult* r) const { PQclear(r); }
};
using Result = std::unique_ptr<PGresult, ResultDeleter>;

// libpq's last error without its trailing newline.
std::string_view error_of(const PGconn* c) {
  std::string_view m = PQerrorMessage(c);
  while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.remove_suffix(1);
  return m;
}

Conn connect(std::string_view url) {
  Conn c(PQconnectdb(std::string(url).c_str()));
  if (!c || PQstatus(c.get()) != CONNECTION_OK)
    throw StoreError(fmt::format("{}: connect: {}", redacted(url),
                                 c ? error_of(c.get()) : std::string_view("out of memory")));
  // The server's notices ("table ... does not exist, skipping") are not the bench's output.
  PQsetNoticeProcessor(c.get(), [](void*, const char*) {}, nullptr);
  return c;
}

void exec(PGconn* c, std::string_view url, const std::string& sql, ExecStatusType want) {
  const Result r(PQexec(c, sql.c_str()));
  if (!r || PQresultStatus(r.get()) != want)
    throw StoreError(fmt::format("{}: {}: {}", redacted(url), sql, error_of(c)));
}

// COPY's binary format is big-endian throughout.
template <typename T>
void put(std::string& out, T v) {
  const auto u = static_cast<std::make_unsigned_t<T>>(v);
  for (int shift = 8 * (static_cast<int>(sizeof(T)) - 1); shift >= 0; shift -= 8)
    out.push_back(static_cast<char>((u >> shift) & 0xff));
}

void field(std::string& out, std::int64_t v) {
  put<std::int32_t>(out, 8);
  put<std::int64_t>(out, v);
}
void field32(std::string& out, std::int64_t v) {
  put<std::int32_t>(out, 4);
  put<std::int32_t>(out, static_cast<std::int32_t>(v));
}

// A UUID's 16 bytes from its text (hex digits, dashes skipped).
void uuid_field(std::string& out, std::string_view text) {
  put<std::int32_t>(out, 16);
  const auto nibble = [](char h) { return h <= '9' ? h - '0' : (h | 0x20) - 'a' + 10; };
  int high = -1;
  for (const char h : text) {
    if (h == '-') continue;
    if (high < 0) {
      high = nibble(h);
    } else {
      out.push_back(static_cast<char>(high << 4 | nibble(h)));
      high = -1;
    }
  }
}

void chunk_row(std::string& out, const std::string& uuid, const Store::StoredChunk& c) {
  put<std::int16_t>(out, 12);  // the columns of caldaq.reading_chunks, in order
  uuid_field(out, uuid);
  field(out, c.seq);
  field32(out, c.device);
  field32(out, c.channel);
  field32(out, c.quantity);
  field(out, c.first_ns);
  field(out, c.last_ns);
  field(out, c.count);
  field32(out, c.encoding);
  field(out, c.crc);
  put<std::int32_t>(out, 1);
  out.push_back(c.stored_checksum ? 1 : 0);
  put<std::int32_t>(out, static_cast<std::int32_t>(c.data.size()));
  out.append(reinterpret_cast<const char*>(c.data.data()), c.data.size());
}

}  // namespace

CopyCeiling copy_ceiling(const Store& local, std::string_view url,
                         std::span<const std::int64_t> run_ids) {
  CopyCeiling out;
  // The COPY stream, built while reading: the read is timed alone, then the COPY.
  std::string stream("PGCOPY\n\377\r\n\0", 11);
  put<std::int32_t>(stream, 0);  // flags
  put<std::int32_t>(stream, 0);  // header extension length
  const auto t_read = Clock::now();
  for (const auto id : run_ids) {
    const auto run = local.run(id);
    if (!run) throw StoreError(fmt::format("{}: no run {}", local.path().string(), id));
    for (std::int64_t first = 0;;) {
      const auto page = local.stored_chunks(id, first, 64);
      if (page.empty()) break;
      first += static_cast<std::int64_t>(page.size());
      for (const auto& c : page) {
        chunk_row(stream, run->uuid, c);
        ++out.chunks;
        out.readings += c.count;
        out.bytes += static_cast<std::int64_t>(c.data.size());
      }
    }
  }
  put<std::int16_t>(stream, -1);
  out.read_s = seconds_since(t_read);

  const auto conn = connect(url);
  PGconn* c = conn.get();
  // A table like any other (a temporary one would skip the write-ahead log the sync pays for),
  // dropped again below; one left by a cut bench is dropped first.
  exec(c, url, "DROP TABLE IF EXISTS public.caldaq_bench_reading_chunks", PGRES_COMMAND_OK);
  exec(c, url,
       "CREATE TABLE public.caldaq_bench_reading_chunks (LIKE caldaq.reading_chunks INCLUDING ALL)",
       PGRES_COMMAND_OK);
  const auto t_copy = Clock::now();
  exec(c, url, "BEGIN", PGRES_COMMAND_OK);
  exec(c, url, "COPY public.caldaq_bench_reading_chunks FROM STDIN (FORMAT binary)", PGRES_COPY_IN);
  constexpr std::size_t block = 1 << 20;
  for (std::size_t at = 0; at < stream.size(); at += block) {
    const auto n = std::min(block, stream.size() - at);
    if (PQputCopyData(c, stream.data() + at, static_cast<int>(n)) != 1)
      throw StoreError(fmt::format("{}: COPY: {}", redacted(url), error_of(c)));
  }
  if (PQputCopyEnd(c, nullptr) != 1)
    throw StoreError(fmt::format("{}: COPY: {}", redacted(url), error_of(c)));
  for (Result r(PQgetResult(c)); r; r.reset(PQgetResult(c)))
    if (PQresultStatus(r.get()) != PGRES_COMMAND_OK)
      throw StoreError(fmt::format("{}: COPY: {}", redacted(url), error_of(c)));
  exec(c, url, "COMMIT", PGRES_COMMAND_OK);
  out.copy_s = seconds_since(t_copy);
  exec(c, url, "DROP TABLE public.caldaq_bench_reading_chunks", PGRES_COMMAND_OK);
  return out;
}

void delete_central_runs(std::string_view url, std::span<const std::string> uuids) {
  if (uuids.empty()) return;
  const auto conn = connect(url);
  const Result schema(PQexec(conn.get(), "SELECT to_regclass('caldaq.runs') IS NULL"));
  if (schema && PQresultStatus(schema.get()) == PGRES_TUPLES_OK &&
      std::string_view(PQgetvalue(schema.get(), 0, 0)) == "t")
    return;  // a server no sync has reached yet: no runs to delete
  for (const auto& u : uuids) {
    const char* values[] = {u.c_str()};
    const Result r(PQexecParams(conn.get(), "DELETE FROM caldaq.runs WHERE uuid = $1::uuid", 1,
                                nullptr, values, nullptr, nullptr, 0));
    if (!r || PQresultStatus(r.get()) != PGRES_COMMAND_OK)
      throw StoreError(
          fmt::format("{}: delete run {}: {}", redacted(url), u, error_of(conn.get())));
  }
}

}  // namespace cal::storage::pg
