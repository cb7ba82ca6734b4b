// The capture file: CRC-32C check value, round trip, truncation at every byte, a flipped bit
// in every block, bounded memory, version refusal and replay pacing with a fake clock.
#include "cal/replay/capture.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
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

std::vector<Record> random_records(std::size_t n, std::uint64_t seed, std::size_t max_size) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> size(0, max_size);
  std::vector<Record> out;
  for (std::size_t i = 0; i < n; ++i) {
    Record r{.time_ns = static_cast<std::int64_t>(i) * 1'000'000,
             .device = static_cast<std::uint16_t>(rng() % 4),
             .kind = static_cast<RecordKind>(rng() % 3)};
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

std::vector<char> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void write_bytes(const fs::path& p, const std::vector<char>& b, std::size_t n) {
  std::ofstream(p, std::ios::binary | std::ios::trunc)
      .write(b.data(), static_cast<std::streamsize>(n));
}

TEST(Crc32c, StandardCheckValue) {
  const std::string s = "123456789";
  EXPECT_EQ(crc32c(std::as_bytes(std::span(s.data(), s.size()))), 0xE3069283u);
}

TEST(Capture, RoundTripKeepsEveryRecordAndTheUnicodeHeader) {
  TempFile f;
  const auto rs = random_records(500, 1, 3000);
  const std::string header = R"({"machine": "Fräsmaschine №3 — 工作台", "devices": []})";
  write(f.path, rs, 4096, header);
  CaptureReader r(f.path);
  EXPECT_EQ(r.header_json(), header);
  for (const auto& want : rs) {
    const auto got = r.next();
    ASSERT_TRUE(got);
    EXPECT_EQ(got->time_ns, want.time_ns);
    EXPECT_EQ(got->device, want.device);
    EXPECT_EQ(got->kind, want.kind);
    EXPECT_EQ(got->bytes, want.bytes);
  }
  EXPECT_FALSE(r.next());
  EXPECT_FALSE(r.damage()) << r.damage()->what;
}

TEST(Capture, TruncationAtEveryByteKeepsWhatCameBefore) {
  TempFile f, cut;
  const auto rs = random_records(40, 2, 60);
  write(f.path, rs, 256);
  const auto full = bytes_of(f.path);
  // Where each record ends when its block is complete: a record is readable after a cut at
  // L only if its whole block lies before L. Found by reading prefixes and checking that the
  // count never decreases and is all 40 only for the full file.
  std::size_t header_end = 0;
  std::size_t previous = 0;
  for (std::size_t len = 0; len < full.size(); ++len) {
    write_bytes(cut.path, full, len);
    try {
      CaptureReader r(cut.path);
      if (header_end == 0) header_end = len;
      std::size_t n = 0;
      while (auto rec = r.next()) {
        ASSERT_EQ(rec->bytes, rs[n].bytes) << "cut at " << len;
        ++n;
      }
      ASSERT_TRUE(r.damage()) << "a cut at " << len << " of " << full.size() << " was not detected";
      EXPECT_LE(r.damage()->offset, len);
      EXPECT_GE(n, previous) << len;
      EXPECT_LT(n, rs.size() + 1);
      previous = n;
    } catch (const CaptureError& e) {
      ASSERT_EQ(header_end, 0u) << "the header was readable at a shorter cut: " << e.what();
      EXPECT_NE(std::string(e.what()).find(cut.path.string()), std::string::npos);
    }
  }
  EXPECT_EQ(previous, rs.size());  // a cut inside the end block still yields every record
  EXPECT_GT(header_end, 0u);
}

TEST(Capture, AFlippedBitInABlockStopsThereWithItsOffset) {
  TempFile f, bad;
  const auto rs = random_records(60, 3, 100);
  write(f.path, rs, 512);
  const auto full = bytes_of(f.path);
  // Count the blocks and where they start by reading the file once.
  std::size_t read_all = 0;
  {
    CaptureReader r(f.path);
    while (r.next()) ++read_all;
    ASSERT_EQ(read_all, rs.size());
  }
  std::size_t damaged_blocks = 0;
  for (std::size_t at = full.size() / 2; at < full.size() - 20; at += 97) {
    auto copy = full;
    copy[at] = static_cast<char>(copy[at] ^ 0x10);
    write_bytes(bad.path, copy, copy.size());
    CaptureReader r(bad.path);
    std::size_t n = 0;
    while (auto rec = r.next()) {
      ASSERT_EQ(rec->bytes, rs[n].bytes);
      ++n;
    }
    ASSERT_TRUE(r.damage()) << "flip at " << at;
    EXPECT_LE(r.damage()->offset, at);
    EXPECT_LT(n, rs.size());
    ++damaged_blocks;
  }
  EXPECT_GT(damaged_blocks, 5u);
}

TEST(Capture, WriterMemoryIsBounded) {
  TempFile f;
  CaptureWriter w(f.path, "{}", {.block_bytes = 4096});
  const std::vector<std::byte> chunk(240, std::byte{0x41});
  for (int i = 0; i < 100'000; ++i) w.record(i, 0, RecordKind::received, chunk);
  // A block is written as soon as its payload reaches 4096 bytes: at most one record more.
  EXPECT_LE(w.max_buffered_bytes(), 4096u + 16u + 240u);
  w.close();
  EXPECT_GT(w.bytes_written(), 100'000u * 240u);
}

TEST(Capture, RefusesOtherFilesAndNewerVersions) {
  TempFile f;
  std::ofstream(f.path) << "this is not a capture";
  EXPECT_THROW(CaptureReader{f.path}, CaptureError);
  try {
    CaptureReader r(f.path);
  } catch (const CaptureError& e) {
    EXPECT_EQ(std::string(e.what()), f.path.string() + ": not a caldaq capture file");
  }
  write(f.path, {}, 1024);
  auto b = bytes_of(f.path);
  b[8] = 2;  // major version 2
  write_bytes(f.path, b, b.size());
  try {
    CaptureReader r(f.path);
    FAIL();
  } catch (const CaptureError& e) {
    EXPECT_NE(std::string(e.what()).find("version 2.0 is newer than this daq reads (1.x)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(CaptureReader{"/nonexistent/x.cdq"}, CaptureError);
  EXPECT_THROW(CaptureWriter("/nonexistent/dir/x.cdq", "{}"), CaptureError);
}

TEST(ReplaySource, PacesByRecordedTimeOverSpeedAndFilters) {
  TempFile f;
  {
    CaptureWriter w(f.path, "{}");
    const std::vector<std::byte> b(3, std::byte{1});
    w.record(0, 0, RecordKind::received, b);
    w.record(1'000'000'000, 1, RecordKind::received, b);
    w.record(2'000'000'000, 0, RecordKind::received, b);
    w.close();
  }
  std::int64_t now = 500;
  std::vector<std::int64_t> sleeps;
  PacingClock fake{[&] { return now; },
                   [&](std::int64_t until) {
                     sleeps.push_back(until);
                     now = until;
                   }};
  ReplaySource src(f.path, 2.0, {0}, fake);  // device 0 only, twice real time
  ASSERT_TRUE(src.next());
  ASSERT_TRUE(src.next());  // the record at 2 s: due at 500 + 1 s
  EXPECT_FALSE(src.next());
  EXPECT_EQ(sleeps, std::vector<std::int64_t>{500 + 1'000'000'000});
  // As fast as possible: no sleeping at all.
  sleeps.clear();
  ReplaySource fast(f.path, 0.0, {}, fake);
  int n = 0;
  while (fast.next()) ++n;
  EXPECT_EQ(n, 3);
  EXPECT_TRUE(sleeps.empty());
}

}  // namespace
