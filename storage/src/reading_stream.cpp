// A run's readings in order, chunk by chunk (see store.hpp, ReadingStream).
//
// The order is that of a stable sort of every reading of the run, in the order the chunks were
// stored (rowid) and within each chunk, by (time, device, channel, quantity). The stream gets
// it by a merge: the chunks are opened in the order of their first times (the index
// reading_chunks_by_run, which also orders equal first times by rowid); each opened chunk is
// sorted by time (stably; a writer's chunk already is); the merge key is (time, device,
// channel, quantity, rowid). A chunk is opened before any reading at or after its first time
// is handed out, so no reading can come late, and only the chunks that overlap the current
// time are in memory.
//
// Integrity: the checksum of every chunk (schema 3) is verified before it is decoded; its
// first time must be its smallest; and at the end the chunks read must be exactly those the
// other index (reading_chunks_by_seq) numbers, so a chunk that a damaged index hides from the
// time-ordered query is reported as missing instead of silently left out.
#include <fmt/format.h>

#include <algorithm>
#include <tuple>

#include "store_impl.hpp"

namespace cal::storage {

struct ReadingStream::Impl {
  const Store::Impl& store;
  std::int64_t run_id = 0;
  std::vector<std::uint8_t> quantities;
  detail::Stmt chunks;
  bool have_next = false;  // `chunks` stands on the next chunk to open
  std::int64_t next_first_ns = 0;
  bool checked = false;

  struct Cursor {
    std::int64_t rowid = 0;
    std::vector<RawReading> readings;
    std::size_t pos = 0;
    const RawReading& front() const { return readings[pos]; }
  };
  std::vector<Cursor> open;
  std::vector<std::vector<RawReading>> spare;  // buffers of finished chunks, reused
  std::vector<std::int64_t> seqs;              // of the chunks read
  std::uint64_t chunks_read = 0;

  Impl(const Store::Impl& s, std::int64_t run, std::span<const std::uint8_t> q)
      : store(s), run_id(run), quantities(q.begin(), q.end()) {}

  std::string filter_sql() const {
    if (quantities.empty()) return {};
    std::string sql = " AND quantity IN (";
    for (std::size_t i = 0; i < quantities.size(); ++i) sql += i ? ", ?" : "?";
    return sql + ")";
  }
  void bind_filter(sqlite3_stmt* s) const {
    sqlite3_bind_int64(s, 1, run_id);
    for (std::size_t i = 0; i < quantities.size(); ++i)
      sqlite3_bind_int(s, static_cast<int>(i + 2), quantities[i]);
  }

  void start() {
    const std::string checks = store.chunk_checksums ? "encoding, seq, crc" : "1, NULL, NULL";
    const std::string sql =
        "SELECT id, device, channel, quantity, first_ns, last_ns, count, data, " + checks +
        " FROM reading_chunks INDEXED BY reading_chunks_by_run WHERE run_id = ?" + filter_sql() +
        " ORDER BY first_ns, id";
    chunks = store.prepare(sql.c_str());
    bind_filter(chunks.get());
    step();
  }

  void step() {
    const int rc = sqlite3_step(chunks.get());
    if (rc == SQLITE_ROW) {
      have_next = true;
      next_first_ns = sqlite3_column_int64(chunks.get(), 4);
    } else if (rc == SQLITE_DONE) {
      have_next = false;
    } else {
      store.fail(fmt::format("read the reading chunks of run {}", run_id));
    }
  }

  [[noreturn]] void damaged(sqlite3_stmt* s, std::string_view what) const {
    const bool numbered = sqlite3_column_type(s, 9) != SQLITE_NULL;
    throw StoreError(fmt::format(
        "{}: run {}: reading chunk {} (row {}; device {}, channel {}, quantity {}; {} readings "
        "from {} ns) is damaged: {}. The database file is corrupted; the run's other chunks "
        "and the other runs are not affected by this one",
        store.path.string(), run_id,
        numbered ? fmt::format("{}", sqlite3_column_int64(s, 9))
                 : std::string("(unnumbered: written before schema 3)"),
        sqlite3_column_int64(s, 0), sqlite3_column_int64(s, 1), sqlite3_column_int64(s, 2),
        sqlite3_column_int64(s, 3), sqlite3_column_int64(s, 6), sqlite3_column_int64(s, 4), what));
  }

  // Verifies and decodes the chunk `chunks` stands on, then steps to the next one.
  void open_next() {
    sqlite3_stmt* s = chunks.get();
    const auto* data = static_cast<const unsigned char*>(sqlite3_column_blob(s, 7));
    const auto blob =
        std::span<const unsigned char>(data, static_cast<std::size_t>(sqlite3_column_bytes(s, 7)));
    const std::int64_t count = sqlite3_column_int64(s, 6);
    const chunk::Key key{.run_id = run_id,
                         .seq = sqlite3_column_int64(s, 9),
                         .device = sqlite3_column_int64(s, 1),
                         .channel = sqlite3_column_int64(s, 2),
                         .quantity = sqlite3_column_int64(s, 3),
                         .first_ns = sqlite3_column_int64(s, 4),
                         .last_ns = sqlite3_column_int64(s, 5),
                         .count = count,
                         .encoding = sqlite3_column_int64(s, 8)};
    if (sqlite3_column_type(s, 10) != SQLITE_NULL) {
      if (static_cast<std::uint32_t>(sqlite3_column_int64(s, 10)) != chunk::checksum(key, blob))
        damaged(s, "its checksum does not match its contents");
      seqs.push_back(key.seq);
    } else if (key.encoding != chunk::packed_v1) {
      damaged(s, "it has no checksum");  // only the chunks written before schema 3 have none
    }
    if (count <= 0 || key.device < 0 || key.device > 0xffff || key.channel < 0 ||
        key.channel > 0xff || key.quantity < 0 || key.quantity > 0xff)
      damaged(s, "its row is out of range");
    Cursor c{.rowid = sqlite3_column_int64(s, 0)};
    if (!spare.empty()) {
      c.readings = std::move(spare.back());
      spare.pop_back();
      c.readings.clear();
    }
    try {
      chunk::decode(static_cast<int>(key.encoding), blob, static_cast<std::size_t>(count),
                    static_cast<std::uint16_t>(key.device), static_cast<std::uint8_t>(key.channel),
                    static_cast<std::uint8_t>(key.quantity), c.readings);
    } catch (const chunk::ChunkError& e) {
      damaged(s, e.what());
    }
    const auto by_time = [](const RawReading& a, const RawReading& b) {
      return a.time_ns < b.time_ns;
    };
    if (!std::is_sorted(c.readings.begin(), c.readings.end(), by_time))
      std::stable_sort(c.readings.begin(), c.readings.end(), by_time);
    if (c.readings.front().time_ns != key.first_ns || c.readings.back().time_ns > key.last_ns)
      damaged(s, "its readings lie outside its time range");
    ++chunks_read;
    open.push_back(std::move(c));
    step();
  }

  static bool before(const RawReading& a, std::int64_t a_row, const RawReading& b,
                     std::int64_t b_row) {
    return std::tie(a.time_ns, a.device, a.channel, a.quantity, a_row) <
           std::tie(b.time_ns, b.device, b.channel, b.quantity, b_row);
  }

  // The chunks read must be those numbered in the other index (schema 3 chunks only).
  void check_complete() {
    checked = true;
    if (!store.chunk_checksums) return;
    const std::string sql =
        "SELECT count(*), IFNULL(MAX(seq), -1) FROM reading_chunks INDEXED BY "
        "reading_chunks_by_seq WHERE run_id = ? AND seq IS NOT NULL" +
        filter_sql();
    auto s = store.prepare(sql.c_str());
    bind_filter(s.get());
    if (sqlite3_step(s.get()) != SQLITE_ROW)
      store.fail(fmt::format("count the reading chunks of run {}", run_id));
    const auto numbered = static_cast<std::size_t>(sqlite3_column_int64(s.get(), 0));
    const auto max_seq = sqlite3_column_int64(s.get(), 1);
    std::sort(seqs.begin(), seqs.end());
    std::string missing;
    if (quantities.empty()) {  // all chunks: the numbers are 0 .. n - 1, each once
      for (std::size_t i = 0; i < seqs.size() && missing.empty(); ++i)
        if (seqs[i] != static_cast<std::int64_t>(i))
          missing = i > 0 && seqs[i] == seqs[i - 1] ? fmt::format("chunk {} appears twice", seqs[i])
                                                    : fmt::format("chunk {} is missing", i);
      if (missing.empty() && max_seq >= static_cast<std::int64_t>(seqs.size()))
        missing = fmt::format("chunk {} is missing", seqs.size());
    }
    if (missing.empty() && numbered != seqs.size())
      missing =
          fmt::format("{} chunks are numbered but {} were found by time", numbered, seqs.size());
    if (!missing.empty())
      throw StoreError(fmt::format(
          "{}: run {}: {}: the database file is corrupted (its indexes do not match its "
          "reading chunks)",
          store.path.string(), run_id, missing));
  }

  bool next(std::vector<RawReading>& out, std::size_t max) {
    out.clear();
    if (max == 0) throw std::invalid_argument("ReadingStream::next: max_readings must be > 0");
    while (out.size() < max) {
      // The best and second-best open chunk by their next reading.
      std::size_t best = open.size(), second = open.size();
      for (std::size_t i = 0; i < open.size(); ++i) {
        if (best == open.size() ||
            before(open[i].front(), open[i].rowid, open[best].front(), open[best].rowid)) {
          second = best;
          best = i;
        } else if (second == open.size() || before(open[i].front(), open[i].rowid,
                                                   open[second].front(), open[second].rowid)) {
          second = i;
        }
      }
      if (have_next && (best == open.size() || next_first_ns <= open[best].front().time_ns)) {
        open_next();
        continue;
      }
      if (best == open.size()) {
        if (!checked) check_complete();
        return !out.empty();
      }
      // Hand out the best chunk's readings while they stay ahead of the second's and of the
      // next chunk to open: long runs of one series go through without comparisons between
      // chunks.
      Cursor& c = open[best];
      while (c.pos < c.readings.size() && out.size() < max) {
        const RawReading& r = c.readings[c.pos];
        if (have_next && r.time_ns >= next_first_ns) break;
        if (second != open.size() && !before(r, c.rowid, open[second].front(), open[second].rowid))
          break;
        out.push_back(r);
        ++c.pos;
      }
      if (c.pos == c.readings.size()) {
        spare.push_back(std::move(c.readings));
        open.erase(open.begin() + static_cast<std::ptrdiff_t>(best));
      }
    }
    return true;
  }
};

ReadingStream::ReadingStream(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ReadingStream::~ReadingStream() = default;
ReadingStream::ReadingStream(ReadingStream&&) noexcept = default;
ReadingStream& ReadingStream::operator=(ReadingStream&&) noexcept = default;

bool ReadingStream::next(std::vector<RawReading>& out, std::size_t max_readings) {
  return impl_->next(out, max_readings);
}
std::uint64_t ReadingStream::chunks_read() const { return impl_->chunks_read; }

ReadingStream Store::stream_readings(std::int64_t run_id,
                                     std::span<const std::uint8_t> quantities) const {
  auto impl = std::make_unique<ReadingStream::Impl>(*impl_, run_id, quantities);
  impl->start();
  return ReadingStream(std::move(impl));
}

}  // namespace cal::storage
