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
// The chunks come from a ChunkSource: this file's reads the SQLite store; storage/pg's reads the
// central store. The merge and the checks are the same for both.
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
namespace {

// The chunks of a run in the SQLite store, by the index reading_chunks_by_run.
class SqliteChunks final : public ChunkSource {
 public:
  SqliteChunks(const Store::Impl& s, std::int64_t run, std::span<const std::uint8_t> q)
      : store_(s), run_id_(run), quantities_(q.begin(), q.end()) {
    const std::string checks = store_.chunk_checksums ? "encoding, seq, crc" : "1, NULL, NULL";
    const std::string sql =
        "SELECT id, device, channel, quantity, first_ns, last_ns, count, data, " + checks +
        " FROM reading_chunks INDEXED BY reading_chunks_by_run WHERE run_id = ?" + filter_sql() +
        " ORDER BY first_ns, id";
    chunks_ = store_.prepare(sql.c_str());
    bind_filter(chunks_.get());
  }

  bool next(SourceChunk& out) override {
    sqlite3_stmt* s = chunks_.get();
    const int rc = sqlite3_step(s);
    if (rc == SQLITE_DONE) return false;
    if (rc != SQLITE_ROW) store_.fail(fmt::format("read the reading chunks of run {}", run_id_));
    detail::read_all(s, out.order, out.device, out.channel, out.quantity, out.first_ns, out.last_ns,
                     out.count, out.data, out.encoding, out.seq, out.crc);
    return true;
  }

  std::optional<Numbered> numbered() override {
    if (!store_.chunk_checksums) return std::nullopt;
    const std::string sql =
        "SELECT count(*), IFNULL(MAX(seq), -1) FROM reading_chunks INDEXED BY "
        "reading_chunks_by_seq WHERE run_id = ? AND seq IS NOT NULL" +
        filter_sql();
    auto s = store_.prepare(sql.c_str());
    bind_filter(s.get());
    if (sqlite3_step(s.get()) != SQLITE_ROW)
      store_.fail(fmt::format("count the reading chunks of run {}", run_id_));
    return Numbered{sqlite3_column_int64(s.get(), 0), sqlite3_column_int64(s.get(), 1)};
  }

 private:
  const Store::Impl& store_;
  std::int64_t run_id_ = 0;
  std::vector<std::uint8_t> quantities_;
  detail::Stmt chunks_;

  std::string filter_sql() const {
    if (quantities_.empty()) return {};
    std::string sql = " AND quantity IN (";
    for (std::size_t i = 0; i < quantities_.size(); ++i) sql += i ? ", ?" : "?";
    return sql + ")";
  }
  void bind_filter(sqlite3_stmt* s) const {
    sqlite3_bind_int64(s, 1, run_id_);
    for (std::size_t i = 0; i < quantities_.size(); ++i)
      sqlite3_bind_int(s, static_cast<int>(i + 2), quantities_[i]);
  }
};

}  // namespace

struct ReadingStream::Impl {
  std::unique_ptr<ChunkSource> source;
  std::string where;
  std::int64_t run_id = 0, checksum_run_id = 0;
  bool whole_run = true;  // no quantity filter: the numbers must be 0 .. n - 1
  SourceChunk pending;    // the next chunk to open, when have_next
  bool have_next = false;
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

  void step() { have_next = source->next(pending); }

  [[noreturn]] void damaged(const SourceChunk& c, std::string_view what) const {
    throw StoreError(fmt::format(
        "{}: run {}: reading chunk {} (row {}; device {}, channel {}, quantity {}; {} readings "
        "from {} ns) is damaged: {}. The database file is corrupted; the run's other chunks "
        "and the other runs are not affected by this one",
        where, run_id,
        c.seq ? fmt::format("{}", *c.seq) : std::string("(unnumbered: written before schema 3)"),
        c.order, c.device, c.channel, c.quantity, c.count, c.first_ns, what));
  }

  // Verifies and decodes the pending chunk, then steps to the next one.
  void open_next() {
    const SourceChunk& c = pending;
    const std::span<const unsigned char> blob(c.data);
    const auto key = chunk::key_of(checksum_run_id, c.seq.value_or(0), c);
    if (c.crc) {
      if (*c.crc != chunk::checksum(key, blob))
        damaged(c, "its checksum does not match its contents");
      seqs.push_back(key.seq);
    } else if (key.encoding != chunk::packed_v1) {
      damaged(c, "it has no checksum");  // only the chunks written before schema 3 have none
    }
    if (c.count <= 0 || key.device < 0 || key.device > 0xffff || key.channel < 0 ||
        key.channel > 0xff || key.quantity < 0 || key.quantity > 0xff)
      damaged(c, "its row is out of range");
    Cursor cursor{.rowid = c.order};
    if (!spare.empty()) {
      cursor.readings = std::move(spare.back());
      spare.pop_back();
      cursor.readings.clear();
    }
    try {
      chunk::decode(static_cast<int>(key.encoding), blob, static_cast<std::size_t>(c.count),
                    static_cast<std::uint16_t>(key.device), static_cast<std::uint8_t>(key.channel),
                    static_cast<std::uint8_t>(key.quantity), cursor.readings);
    } catch (const chunk::ChunkError& e) {
      damaged(c, e.what());
    }
    const auto by_time = [](const RawReading& a, const RawReading& b) {
      return a.time_ns < b.time_ns;
    };
    if (!std::is_sorted(cursor.readings.begin(), cursor.readings.end(), by_time))
      std::stable_sort(cursor.readings.begin(), cursor.readings.end(), by_time);
    if (cursor.readings.front().time_ns != key.first_ns ||
        cursor.readings.back().time_ns > key.last_ns)
      damaged(c, "its readings lie outside its time range");
    ++chunks_read;
    open.push_back(std::move(cursor));
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
    const auto numbered = source->numbered();
    if (!numbered) return;
    std::sort(seqs.begin(), seqs.end());
    std::string missing;
    if (whole_run) {  // all chunks: the numbers are 0 .. n - 1, each once
      for (std::size_t i = 0; i < seqs.size() && missing.empty(); ++i)
        if (seqs[i] != static_cast<std::int64_t>(i))
          missing = i > 0 && seqs[i] == seqs[i - 1] ? fmt::format("chunk {} appears twice", seqs[i])
                                                    : fmt::format("chunk {} is missing", i);
      if (missing.empty() && numbered->max_seq >= static_cast<std::int64_t>(seqs.size()))
        missing = fmt::format("chunk {} is missing", seqs.size());
    }
    if (missing.empty() && static_cast<std::size_t>(numbered->count) != seqs.size())
      missing = fmt::format("{} chunks are numbered but {} were found by time", numbered->count,
                            seqs.size());
    if (!missing.empty())
      throw StoreError(fmt::format(
          "{}: run {}: {}: the database file is corrupted (its indexes do not match its "
          "reading chunks)",
          where, run_id, missing));
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
      if (have_next && (best == open.size() || pending.first_ns <= open[best].front().time_ns)) {
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
        if (have_next && r.time_ns >= pending.first_ns) break;
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

ReadingStream ReadingStream::of(std::unique_ptr<ChunkSource> source, std::string where,
                                std::int64_t run_id, std::int64_t checksum_run_id, bool whole_run) {
  auto impl = std::make_unique<Impl>();
  impl->whole_run = whole_run;
  impl->source = std::move(source);
  impl->where = std::move(where);
  impl->run_id = run_id;
  impl->checksum_run_id = checksum_run_id;
  impl->step();
  return ReadingStream(std::move(impl));
}

ReadingStream Store::stream_readings(std::int64_t run_id,
                                     std::span<const std::uint8_t> quantities) const {
  return ReadingStream::of(std::make_unique<SqliteChunks>(*impl_, run_id, quantities),
                           impl_->path.string(), run_id, run_id, quantities.empty());
}

std::vector<RawReading> RunReader::readings(std::int64_t run_id) const {
  return readings(run_id, {});
}

std::vector<RawReading> RunReader::readings(std::int64_t run_id,
                                            std::span<const std::uint8_t> quantities) const {
  std::vector<RawReading> out, batch;
  auto stream = stream_readings(run_id, quantities);
  while (stream.next(batch, std::size_t{1} << 20))
    out.insert(out.end(), batch.begin(), batch.end());
  return out;
}

}  // namespace cal::storage
