// The capture file: CRC-32C check values, round trip of every record kind, truncation at
// every byte, a flipped bit in every block, bounded memory, write errors (full disk, file
// size limit), version refusal, determinism and replay pacing with a fake clock.
//
// Where a test needs to know where blocks start and end, it finds them with its own parser
// of the byte layout documented in docs/capture-format.md (`layout` below: manual
// little-endian decoding, no code shared with the reader), so the reader's reports are
// checked against the documented format, not against themselves.
#include "cal/replay/capture.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

namespace {

namespace fs = std::filesystem;
using namespace cal::replay;

struct TempFile {
  fs::path path =
      fs::temp_directory_path() / ("caldaq-capture-" + std::to_string(::getpid()) + "-" +
                                   std::to_string(std::random_device{}()) + ".cdq");
  ~TempFile() { fs::remove(path); }
};

std::vector<std::byte> as_bytes(std::string_view s) {
  const auto* p = reinterpret_cast<const std::byte*>(s.data());
  return {p, p + s.size()};
}

// Records of every kind with seeded random devices, sizes and (increasing) times.
std::vector<Record> random_records(std::size_t n, std::uint64_t seed, std::size_t max_size) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> size(0, max_size);
  std::uniform_int_distribution<std::int64_t> step(0, 5'000'000);
  std::vector<Record> out;
  std::int64_t t = 0;
  for (std::size_t i = 0; i < n; ++i) {
    t += step(rng);
    Record r{.time_ns = t,
             .device = static_cast<std::uint16_t>(rng() % 4 == 3 ? 65535 : rng() % 3),
             .kind = static_cast<RecordKind>(i % 3)};  // every kind, in turn
    r.bytes.resize(size(rng));
    for (auto& b : r.bytes) b = static_cast<std::byte>(rng());
    out.push_back(std::move(r));
  }
  return out;
}

void write(const fs::path& p, const std::vector<Record>& rs, std::size_t block,
           std::string_view header = "{}") {
  CaptureWriter w(p, header, {.block_bytes = block});
  for (const auto& r : rs) w.record(r.time_ns, r.device, r.kind, r.bytes);
  w.close();
}

std::vector<Record> read_all(CaptureReader& r) {
  std::vector<Record> out;
  while (auto rec = r.next()) out.push_back(std::move(*rec));
  return out;
}

std::vector<char> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void write_bytes(const fs::path& p, const std::vector<char>& b, std::size_t n) {
  std::ofstream(p, std::ios::binary | std::ios::trunc)
      .write(b.data(), static_cast<std::streamsize>(n));
}

void expect_same(const std::vector<Record>& got, const std::vector<Record>& want, std::size_t n) {
  ASSERT_EQ(got.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(got[i].time_ns, want[i].time_ns) << i;
    EXPECT_EQ(got[i].device, want[i].device) << i;
    EXPECT_EQ(got[i].kind, want[i].kind) << i;
    EXPECT_EQ(got[i].bytes, want[i].bytes) << i;
  }
}

// The documented layout: header = magic(8) major(2) minor(2) length(4) json(length) crc(4);
// then blocks = magic(4) length(4) count(4) crc(4) payload(length); the end block has
// magic "CEND", length 8, count 0 and an 8-byte payload.
struct Block {
  std::size_t start = 0, end = 0;
  std::uint32_t records = 0;
  bool is_end = false;
};
std::uint32_t le32(const std::vector<char>& f, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<std::uint8_t>(f[at + std::size_t(i)]);
  return v;
}
std::size_t header_end(const std::vector<char>& f) { return 20 + le32(f, 12); }
std::vector<Block> layout(const std::vector<char>& f) {
  std::vector<Block> out;
  for (std::size_t at = header_end(f); at < f.size();) {
    const bool is_end = std::string(&f[at], 4) == "CEND";
    EXPECT_TRUE(is_end || std::string(&f[at], 4) == "CBLK") << at;
    const std::size_t end = at + 16 + le32(f, at + 4);
    out.push_back({at, end, le32(f, at + 8), is_end});
    at = end;
  }
  return out;
}

TEST(Crc32c, StandardCheckValues) {
  // The CRC catalogue's check value of CRC-32/ISCSI (CRC-32C) for "123456789" is 0xE3069283;
  // RFC 3720 appendix B.4 gives 32 zero bytes -> 0x8A9136AA, 32 0xFF bytes -> 0x62A8AB43 and
  // the bytes 0..31 -> 0x46DD794E.
  EXPECT_EQ(crc32c(as_bytes("123456789")), 0xE3069283u);
  EXPECT_EQ(crc32c(std::vector<std::byte>(32, std::byte{0})), 0x8A9136AAu);
  EXPECT_EQ(crc32c(std::vector<std::byte>(32, std::byte{0xFF})), 0x62A8AB43u);
  std::vector<std::byte> ramp(32);
  for (std::size_t i = 0; i < 32; ++i) ramp[i] = static_cast<std::byte>(i);
  EXPECT_EQ(crc32c(ramp), 0x46DD794Eu);
  EXPECT_EQ(crc32c({}), 0u);
  // Chaining: the CRC of a whole equals the CRC of its tail continued from its head's.
  EXPECT_EQ(crc32c(as_bytes("6789"), crc32c(as_bytes("12345"))), 0xE3069283u);
}

TEST(Capture, RoundTripKeepsEveryRecordAndTheUnicodeHeader) {
  const auto rs = random_records(600, 1, 3000);
  const std::string header =
      R"({"machine": "Fräsmaschine №3 — 工作台 🛠", "operator": "Zoë Ørsted", "devices": []})";
  for (const std::size_t block : {std::size_t{0}, std::size_t{4096}, std::size_t{1} << 20}) {
    TempFile f;
    write(f.path, rs, block, header);
    CaptureReader r(f.path);
    EXPECT_EQ(r.header_json(), header);
    EXPECT_EQ(r.minor_version(), capture_minor_version);
    expect_same(read_all(r), rs, rs.size());
    EXPECT_FALSE(r.damage()) << describe(*r.damage());
    EXPECT_EQ(r.records_read(), rs.size());
    // The blocks hold every record, and each block but the last data block reached the
    // block size (a block is written as soon as its payload reaches block_bytes).
    const auto file = bytes_of(f.path);
    const auto blocks = layout(file);
    ASSERT_TRUE(blocks.back().is_end);
    std::size_t n = 0;
    for (std::size_t i = 0; i + 1 < blocks.size(); ++i) {
      n += blocks[i].records;
      if (i + 2 < blocks.size()) {
        EXPECT_GE(blocks[i].end - blocks[i].start - 16, block);
      }
    }
    EXPECT_EQ(n, rs.size());
    EXPECT_EQ(blocks.back().end, file.size());
  }
}

TEST(Capture, EventsAreText) {
  TempFile f;
  {
    CaptureWriter w(f.path, "{}");
    w.event(5, 2, "opened");
    w.event(7, 2, "error: read: Input/output error — ünïcode");
    w.close();
  }
  CaptureReader r(f.path);
  const auto rs = read_all(r);
  ASSERT_EQ(rs.size(), 2u);
  EXPECT_EQ(rs[0].kind, RecordKind::event);
  EXPECT_EQ(rs[0].text(), "opened");
  EXPECT_EQ(rs[1].time_ns, 7);
  EXPECT_EQ(rs[1].device, 2);
  EXPECT_EQ(rs[1].text(), "error: read: Input/output error — ünïcode");
}

TEST(Capture, TruncationAtEveryByteKeepsEveryBlockBeforeIt) {
  TempFile f, cut;
  const auto rs = random_records(40, 2, 60);
  write(f.path, rs, 256, R"({"session": "cut"})");
  const auto full = bytes_of(f.path);
  const auto blocks = layout(full);
  ASSERT_GE(blocks.size(), 5u);  // several data blocks and the end block
  const std::size_t head = header_end(full);
  for (std::size_t len = 0; len <= full.size(); ++len) {
    write_bytes(cut.path, full, len);
    if (len < head) {
      try {
        CaptureReader r(cut.path);
        FAIL() << "a header cut at " << len << " was accepted";
      } catch (const CaptureError& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.find(cut.path.string() + ": "), 0u) << m;
        const std::string want = len < 8 ? std::string("not a caldaq capture file")
                                         : fmt::format("truncated header at byte {}", len);
        EXPECT_NE(m.find(want), std::string::npos) << m;
      }
      continue;
    }
    // Expected: the records of the blocks wholly inside the cut; the damage at the first
    // block that is not (its start offset and its number).
    std::size_t want = 0, k = 0;
    while (k < blocks.size() && blocks[k].end <= len) want += blocks[k++].records;
    CaptureReader r(cut.path);
    const auto got = read_all(r);
    expect_same(got, rs, want);
    if (len == full.size()) {
      EXPECT_FALSE(r.damage()) << describe(*r.damage());
      continue;
    }
    ASSERT_TRUE(r.damage()) << "a cut at " << len << " of " << full.size() << " was missed";
    EXPECT_EQ(r.damage()->offset, blocks[k].start) << len;
    EXPECT_EQ(r.damage()->block, k) << len;
    const std::string what = r.damage()->what;
    const std::string kind = len == blocks[k].start ? "no end block" : "truncated";
    EXPECT_NE(what.find(kind), std::string::npos) << what;
  }
}

TEST(Capture, AFlippedBitInEachBlockStopsThereWithItsOffset) {
  TempFile f, bad;
  const auto rs = random_records(60, 3, 100);
  write(f.path, rs, 512);
  const auto full = bytes_of(f.path);
  const auto blocks = layout(full);
  ASSERT_GE(blocks.size(), 6u);
  std::size_t before = 0;  // records in the blocks before block k
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const auto& b = blocks[k];
    // Every field of the block header, and the first, middle and last payload byte.
    for (const std::size_t at : {b.start, b.start + 5, b.start + 8, b.start + 13, b.start + 16,
                                 (b.start + 16 + b.end) / 2, b.end - 1}) {
      for (const int bit : {0, 7}) {
        auto copy = full;
        copy[at] = static_cast<char>(copy[at] ^ (1 << bit));
        write_bytes(bad.path, copy, copy.size());
        CaptureReader r(bad.path);
        expect_same(read_all(r), rs, before);
        ASSERT_TRUE(r.damage()) << "flip of bit " << bit << " at " << at;
        EXPECT_EQ(r.damage()->offset, b.start) << at;
        EXPECT_EQ(r.damage()->block, k) << at;
      }
    }
    before += b.records;
  }
  // A flipped bit in the header is refused with the header's CRC.
  auto copy = full;
  copy[18] = static_cast<char>(copy[18] ^ 1);
  write_bytes(bad.path, copy, copy.size());
  try {
    CaptureReader r(bad.path);
    FAIL();
  } catch (const CaptureError& e) {
    EXPECT_NE(std::string(e.what()).find("header CRC mismatch at byte 18"), std::string::npos)
        << e.what();
  }
}

TEST(Capture, AFileNotClosedKeepsEverythingFlushed) {
  TempFile f, copy;
  const auto rs = random_records(30, 4, 200);
  CaptureWriter w(f.path, "{}", {.block_bytes = 1 << 20});
  for (std::size_t i = 0; i < 20; ++i)
    w.record(rs[i].time_ns, rs[i].device, rs[i].kind, rs[i].bytes);
  w.flush();
  for (std::size_t i = 20; i < 30; ++i)
    w.record(rs[i].time_ns, rs[i].device, rs[i].kind, rs[i].bytes);
  // A crash now: the file holds what was flushed (20 records in one block), no end block.
  fs::copy_file(f.path, copy.path, fs::copy_options::overwrite_existing);
  w.close();
  CaptureReader r(copy.path);
  expect_same(read_all(r), rs, 20);
  ASSERT_TRUE(r.damage());
  EXPECT_EQ(r.damage()->block, 1u);
  EXPECT_EQ(r.damage()->offset, fs::file_size(copy.path));
  EXPECT_NE(r.damage()->what.find("not closed"), std::string::npos);
  EXPECT_EQ(describe(*r.damage()),
            fmt::format("block 1 at byte {}: {}", r.damage()->offset, r.damage()->what));
}

TEST(Capture, WriterMemoryIsBounded) {
  TempFile f;
  CaptureWriter w(f.path, "{}", {.block_bytes = 4096});
  std::mt19937_64 rng(5);
  std::size_t peak = 0;
  for (int i = 0; i < 100'000; ++i) {
    const std::vector<std::byte> chunk(rng() % 241, std::byte{0x41});
    w.record(i, 0, RecordKind::received, chunk);
    // After each call less than one block is held: a block is written when it reaches 4096.
    ASSERT_LT(w.buffered_bytes(), 4096u);
    peak = std::max(peak, w.buffered_bytes());
    // Nothing is held elsewhere either (no stdio buffer): the file has every written byte.
    if (i % 997 == 0) {
      ASSERT_EQ(fs::file_size(f.path), w.bytes_written());
    }
  }
  // The peak, counted inside the record that completes a block: under 4096 + the 16-byte
  // record header + the largest record (240 bytes).
  EXPECT_LT(w.max_buffered_bytes(), 4096u + 16u + 240u);
  EXPECT_GE(w.max_buffered_bytes(), 4096u);
  EXPECT_LT(peak, 4096u);
  w.close();
  EXPECT_EQ(fs::file_size(f.path), w.bytes_written());
}

TEST(Capture, AFullDiskIsReportedWithThePathAndErrno) {
  ASSERT_TRUE(fs::exists("/dev/full")) << "the test writes to /dev/full";
  try {
    CaptureWriter w("/dev/full", "{}");
    FAIL() << "writing to /dev/full succeeded";
  } catch (const CaptureError& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/full: write failed at byte 0: No space left on device");
  }
}

// A file size limit (RLIMIT_FSIZE) makes write() fail part-way, as a full disk does. Records
// of 100 bytes are 116 bytes with their header; with block_bytes = 1000 a block closes after
// 9 records (8 x 116 = 928 < 1000 <= 1044), so a block is 16 + 1044 = 1060 bytes. The header
// "{}" takes 8 + 8 + 2 + 4 = 22 bytes. With a 10000-byte limit, 9 blocks fit (22 + 9 x 1060 =
// 9562), the 10th is cut after 438 bytes (16 of header, 422 of payload): the 90th record's call
// throws, naming byte 9562, and the reader returns the 81 records of the 9 whole blocks.
TEST(Capture, AWriteErrorKeepsWhatWasWrittenBeforeIt) {
  TempFile f;
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG instead of the signal
  rlimit small = old;
  small.rlim_cur = 10000;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string message;
  std::size_t failed_at = 0;
  {
    CaptureWriter w(f.path, "{}", {.block_bytes = 1000});
    const std::vector<std::byte> chunk(100, std::byte{0x5A});
    for (std::size_t i = 0; i < 200 && message.empty(); ++i) {
      try {
        w.record(static_cast<std::int64_t>(i), 1, RecordKind::received, chunk);
      } catch (const CaptureError& e) {
        message = e.what();
        failed_at = i;
      }
    }
    // Every later call refuses at once, with the first error.
    EXPECT_THROW(w.record(0, 1, RecordKind::received, chunk), CaptureError);
    EXPECT_THROW(w.flush(), CaptureError);
    EXPECT_THROW(w.close(), CaptureError);
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(failed_at, 89u);
  EXPECT_EQ(message, f.path.string() + ": write failed at byte 9562: File too large");
  EXPECT_EQ(fs::file_size(f.path), 10000u);
  CaptureReader r(f.path);
  EXPECT_EQ(read_all(r).size(), 81u);
  ASSERT_TRUE(r.damage());
  EXPECT_EQ(r.damage()->offset, 9562u);
  EXPECT_EQ(r.damage()->block, 9u);
  EXPECT_NE(r.damage()->what.find("truncated block (422 of 1044 payload bytes)"), std::string::npos)
      << r.damage()->what;
}

TEST(Capture, RefusesBadInputWithTheFileNamed) {
  TempFile f;
  std::ofstream(f.path) << "this is not a capture";
  try {
    CaptureReader r(f.path);
    FAIL();
  } catch (const CaptureError& e) {
    EXPECT_EQ(std::string(e.what()),
              f.path.string() + ": not a caldaq capture file (no CALDAQCP magic at byte 0)");
  }
  try {
    CaptureReader r("/nonexistent/x.cdq");
    FAIL();
  } catch (const CaptureError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/x.cdq: cannot open: No such file or directory");
  }
  EXPECT_THROW(CaptureWriter("/nonexistent/dir/x.cdq", "{}"), CaptureError);
  EXPECT_THROW(CaptureWriter(f.path, "{}", {.block_bytes = max_block_bytes + 1}), CaptureError);
  CaptureWriter w(f.path, "{}");
  const std::vector<std::byte> huge(max_record_bytes + 1);
  EXPECT_THROW(w.record(0, 0, RecordKind::received, huge), CaptureError);
  w.close();
  EXPECT_THROW(w.event(0, 0, "late"), CaptureError);
}

TEST(Capture, RefusesANewerMajorVersionAndReadsANewerMinor) {
  TempFile f;
  write(f.path, random_records(3, 6, 10), 1024, R"({"a": 1})");
  auto b = bytes_of(f.path);
  b[8] = 2;  // major version 2
  write_bytes(f.path, b, b.size());
  try {
    CaptureReader r(f.path);
    FAIL();
  } catch (const CaptureError& e) {
    EXPECT_EQ(std::string(e.what()),
              f.path.string() +
                  ": capture format version 2.0 (byte 8) is newer than this daq reads (1.x)");
  }
  // Minor version 1.7: read, as minor versions only add what old readers may ignore. The
  // header CRC covers the version, so it is recomputed over bytes 8 .. 16 + length.
  b[8] = 1;
  b[10] = 7;
  const std::size_t crc_at = header_end(b) - 4;
  std::vector<std::byte> covered(crc_at - 8);
  for (std::size_t i = 8; i < crc_at; ++i) covered[i - 8] = static_cast<std::byte>(b[i]);
  const std::uint32_t crc = crc32c(covered);
  for (std::size_t i = 0; i < 4; ++i) b[crc_at + i] = static_cast<char>((crc >> (8 * i)) & 0xFF);
  write_bytes(f.path, b, b.size());
  CaptureReader r(f.path);
  EXPECT_EQ(r.minor_version(), 7);
  EXPECT_EQ(read_all(r).size(), 3u);
  EXPECT_FALSE(r.damage());
}

TEST(Capture, TwoReadsAreIdentical) {
  TempFile f;
  write(f.path, random_records(300, 7, 500), 2048);
  CaptureReader a(f.path), b(f.path);
  const auto ra = read_all(a), rb = read_all(b);
  expect_same(rb, ra, ra.size());
  EXPECT_EQ(ra.size(), 300u);
}

struct FakeClock {
  std::int64_t now = 500;
  std::vector<std::int64_t> sleeps;
  PacingClock clock() {
    return {[this] { return now; },
            [this](std::int64_t until) {
              sleeps.push_back(until);
              now = until;
            }};
  }
};

void write_paced(const fs::path& p) {
  CaptureWriter w(p, "{}");
  const std::vector<std::byte> b(3, std::byte{1});
  w.record(1'000'000'000, 0, RecordKind::received, b);
  w.record(2'000'000'000, 1, RecordKind::received, b);
  w.event(2'500'000'000, 1, "closed");
  w.record(3'000'000'000, 0, RecordKind::sent, b);
}

TEST(ReplaySource, PacesByRecordedTimeOverSpeedAndFilters) {
  TempFile f;
  write_paced(f.path);
  // Device 0 only, twice real time: the first record at once (t = 500); the one recorded
  // 2 s later is due (3 s - 1 s) / 2 = 1 s after it.
  FakeClock c;
  ReplaySource src(f.path, 2.0, {0}, c.clock());
  ASSERT_TRUE(src.next());
  const auto second = src.next();
  ASSERT_TRUE(second);
  EXPECT_EQ(second->time_ns, 3'000'000'000);
  EXPECT_FALSE(src.next());
  EXPECT_EQ(c.sleeps, std::vector<std::int64_t>{500 + 1'000'000'000});
  // Half speed, every device: due at 500 + 2 x (1 s, 1.5 s, 2 s).
  FakeClock h;
  ReplaySource slow(f.path, 0.5, {}, h.clock());
  int n = 0;
  while (slow.next()) ++n;
  EXPECT_EQ(n, 4);
  EXPECT_EQ(h.sleeps, (std::vector<std::int64_t>{2'000'000'500, 3'000'000'500, 4'000'000'500}));
  // As fast as possible: no sleeping at all.
  FakeClock z;
  ReplaySource fast(f.path, 0.0, {}, z.clock());
  n = 0;
  while (fast.next()) ++n;
  EXPECT_EQ(n, 4);
  EXPECT_TRUE(z.sleeps.empty());
}

TEST(ReplaySource, DoesNotSleepWhenAlreadyLate) {
  TempFile f;
  write_paced(f.path);
  // A consumer slower than the recording: the clock jumps 5 s on every read, past every due
  // time (the last is due 2 s after the first), so nothing sleeps and order is kept.
  std::int64_t now = 0;
  std::vector<std::int64_t> sleeps;
  ReplaySource src(
      f.path, 1.0, {},
      {[&] { return now += 5'000'000'000; }, [&](std::int64_t until) { sleeps.push_back(until); }});
  std::vector<std::int64_t> times;
  while (auto r = src.next()) times.push_back(r->time_ns);
  EXPECT_EQ(times, (std::vector<std::int64_t>{1'000'000'000, 2'000'000'000, 2'500'000'000,
                                              3'000'000'000}));
  EXPECT_TRUE(sleeps.empty());
}

TEST(ReplaySource, TwoReplaysAreIdentical) {
  TempFile f;
  write(f.path, random_records(200, 8, 100), 1024);
  FakeClock a, b;
  ReplaySource ra(f.path, 3.0, {0, 65535}, a.clock()), rb(f.path, 3.0, {0, 65535}, b.clock());
  std::vector<Record> xa, xb;
  while (auto r = ra.next()) xa.push_back(*r);
  while (auto r = rb.next()) xb.push_back(*r);
  ASSERT_GT(xa.size(), 50u);
  expect_same(xb, xa, xa.size());
  EXPECT_EQ(a.sleeps, b.sleeps);
  for (const auto& r : xa) EXPECT_TRUE(r.device == 0 || r.device == 65535);
}

TEST(ReplaySource, RefusesABadSpeed) {
  TempFile f;
  write_paced(f.path);
  for (const double s :
       {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    try {
      ReplaySource r(f.path, s);
      FAIL() << s;
    } catch (const CaptureError& e) {
      EXPECT_EQ(std::string(e.what()).find(f.path.string() + ": replay speed "), 0u) << e.what();
    }
  }
}

}  // namespace
