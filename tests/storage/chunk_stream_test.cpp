// Reading chunks and the reading stream: the encoding gives back every time and every bit of
// every value (NaN payloads, -0.0, extreme times), refuses a damaged BLOB of any length, and is
// as small as the hand estimate for a regular stream; the stream hands out a run in exactly
// the order of a stable sort of everything stored (time, device, channel, quantity; stored
// order within a series), whatever the batches, the series, the out-of-order times and the
// batch size asked for.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <tuple>

#include "../support/temp_dir.hpp"
#include "cal/storage/chunk.hpp"
#include "cal/storage/store.hpp"

namespace {

namespace fs = std::filesystem;
namespace chunk = cal::storage::chunk;
using cal::storage::RawReading;
using cal::storage::Store;

struct TempDir : cal::test::TempDir {
  TempDir() : cal::test::TempDir("caldaq-stream") {}
};

bool same(const RawReading& a, const RawReading& b) {
  return a.time_ns == b.time_ns && a.device == b.device && a.channel == b.channel &&
         a.quantity == b.quantity && a.status == b.status &&
         std::bit_cast<std::uint64_t>(a.value) == std::bit_cast<std::uint64_t>(b.value);
}

std::vector<RawReading> round_trip(const chunk::Columns& c) {
  std::vector<unsigned char> blob;
  chunk::encode(c, blob);
  std::vector<RawReading> out;
  chunk::decode(chunk::columns_v2, blob, c.size(), 7, 3, 5, out);
  return out;
}

void expect_round_trip(const chunk::Columns& c, const char* what) {
  const auto out = round_trip(c);
  ASSERT_EQ(out.size(), c.size()) << what;
  for (std::size_t i = 0; i < c.size(); ++i) {
    ASSERT_EQ(out[i].time_ns, c.time_ns[i]) << what << " " << i;
    ASSERT_EQ(out[i].status, c.status[i]) << what << " " << i;
    ASSERT_EQ(std::bit_cast<std::uint64_t>(out[i].value), std::bit_cast<std::uint64_t>(c.value[i]))
        << what << " " << i;
    ASSERT_EQ(out[i].device, 7);
    ASSERT_EQ(out[i].channel, 3);
    ASSERT_EQ(out[i].quantity, 5);
  }
}

TEST(Chunk, EveryTimeAndEveryBitOfEveryValueComesBack) {
  std::mt19937_64 rng(11);
  constexpr auto kMin = std::numeric_limits<std::int64_t>::min();
  constexpr auto kMax = std::numeric_limits<std::int64_t>::max();
  // Values that a careless coder loses: NaNs with payloads and sign, -0.0, infinities,
  // subnormals, the largest double.
  const double specials[] = {std::bit_cast<double>(std::uint64_t{0x7FF8000000000123}),
                             std::bit_cast<double>(std::uint64_t{0xFFF0000000000001}),
                             -0.0,
                             0.0,
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::denorm_min(),
                             std::numeric_limits<double>::max(),
                             0.1};
  for (int trial = 0; trial < 200; ++trial) {
    chunk::Columns c;
    const std::size_t n = 1 + rng() % 300;
    std::int64_t t = static_cast<std::int64_t>(rng());
    for (std::size_t i = 0; i < n; ++i) {
      switch (trial % 5) {
        case 0:  // regular 10 kHz
          t = static_cast<std::int64_t>(i) * 100'000;
          break;
        case 1:  // jittered, sometimes equal, sometimes backwards
          t += static_cast<std::int64_t>(rng() % 200'000) - 20'000;
          break;
        case 2:  // anything at all, including the extremes
          t = (i % 3 == 0) ? (i % 2 ? kMin : kMax) : static_cast<std::int64_t>(rng());
          break;
        default:  // a gauge: ten lines per read share a time
          t = static_cast<std::int64_t>(i / 10) * 1'000'000;
      }
      c.time_ns.push_back(t);
      c.status.push_back(trial % 2 ? static_cast<std::uint8_t>(rng() % 3) : 0);
      double v = 0.0;
      switch (trial % 3) {
        case 0:
          v = 0.1 + 1e-9 * static_cast<double>(rng() % 977);
          break;
        case 1:
          v = std::bit_cast<double>(rng());  // random bit patterns, NaNs included
          break;
        default:
          v = specials[rng() % std::size(specials)];
      }
      c.value.push_back(v);
    }
    expect_round_trip(c, "random");
  }
  chunk::Columns one;
  one.push({.time_ns = kMin, .status = 2, .value = -0.0});
  expect_round_trip(one, "a single reading");
}

TEST(Chunk, ARegularStreamTakesAboutSixBytesAReading) {
  // 10 kHz, values 0.1 m + k nm: by hand, the times are deltas of deltas of 0 (1 byte each);
  // 0.1 has an ulp of 2^-56 and 1 nm is 2^26 ulps, so consecutive values differ in their
  // lowest 27 bits or so: 4 bytes each, one more when the addition carries past bit 32 (1 in
  // 64) or k wraps from 976 to 0 (1 in 977, a change of 2^36 ulps), plus half a header byte:
  // 5.52 bytes a reading; the chunk header (flags, count, first time) adds 11 for 16384.
  chunk::Columns c;
  for (std::size_t i = 0; i < 16384; ++i)
    c.push({.time_ns = static_cast<std::int64_t>(i) * 100'000,
            .value = 0.1 + 1e-9 * static_cast<double>(i % 977)});
  std::vector<unsigned char> blob;
  chunk::encode(c, blob);
  EXPECT_LE(blob.size(), 16384 * 5.55 + 11);
  EXPECT_GT(blob.size(), 16384 * 4);  // no bits lost: not smaller than the changing bits
}

TEST(Chunk, ADamagedBlobIsRefusedAtEveryLength) {
  chunk::Columns c;
  for (std::size_t i = 0; i < 50; ++i)
    c.push({.time_ns = static_cast<std::int64_t>(i * i) * 7919,
            .status = static_cast<std::uint8_t>(i % 7 == 0),
            .value = std::sin(static_cast<double>(i))});
  std::vector<unsigned char> blob;
  chunk::encode(c, blob);
  std::vector<RawReading> out{RawReading{}};  // what was there before stays, nothing is added
  for (std::size_t cut = 0; cut < blob.size(); ++cut) {
    const auto part = std::span(blob).first(cut);
    EXPECT_THROW(chunk::decode(chunk::columns_v2, part, 50, 0, 0, 0, out), chunk::ChunkError)
        << cut;
    EXPECT_EQ(out.size(), 1u);
  }
  auto longer = blob;
  longer.push_back(0);
  EXPECT_THROW(chunk::decode(chunk::columns_v2, longer, 50, 0, 0, 0, out), chunk::ChunkError);
  EXPECT_THROW(chunk::decode(chunk::columns_v2, blob, 49, 0, 0, 0, out), chunk::ChunkError);
  EXPECT_THROW(chunk::decode(3, blob, 50, 0, 0, 0, out), chunk::ChunkError);
  EXPECT_THROW(chunk::decode(chunk::packed_v1, blob, 50, 0, 0, 0, out), chunk::ChunkError);
  // An empty chunk is never written: refused in either encoding (found by fuzz_chunk).
  EXPECT_THROW(chunk::decode(chunk::packed_v1, {}, 0, 0, 0, 0, out), chunk::ChunkError);
  EXPECT_THROW(chunk::decode(chunk::columns_v2, std::vector<unsigned char>{0, 0}, 0, 0, 0, 0, out),
               chunk::ChunkError);
  EXPECT_EQ(out.size(), 1u);
  chunk::decode(chunk::columns_v2, blob, 50, 0, 0, 0, out);
  EXPECT_EQ(out.size(), 51u);
}

TEST(Chunk, TheChecksumCoversTheRowAsWellAsTheBlob) {
  const std::vector<unsigned char> blob{1, 2, 3, 4};
  const chunk::Key k{
      .run_id = 3, .seq = 4, .device = 1, .quantity = 2, .first_ns = 10, .last_ns = 20, .count = 2};
  const auto crc = chunk::checksum(k, blob);
  for (int field = 0; field < 9; ++field) {
    auto other = k;
    std::int64_t* f[] = {&other.run_id,  &other.seq,      &other.device,
                         &other.channel, &other.quantity, &other.first_ns,
                         &other.last_ns, &other.count,    &other.encoding};
    *f[field] += 1;
    EXPECT_NE(chunk::checksum(other, blob), crc) << field;
  }
  auto flipped = blob;
  flipped[2] ^= 0x10;
  EXPECT_NE(chunk::checksum(k, flipped), crc);
}

// The reference order: a stable sort of every reading in stored order (batch by batch, and
// within a batch series by series as append_readings writes them, each in its given order).
std::vector<RawReading> reference_order(const std::vector<std::vector<RawReading>>& batches) {
  std::vector<RawReading> all;
  for (const auto& b : batches) {
    std::vector<std::tuple<int, int, int>> keys;  // series in the order first seen
    for (const auto& r : b)
      if (std::find(keys.begin(), keys.end(),
                    std::tuple<int, int, int>{r.device, r.channel, r.quantity}) == keys.end())
        keys.emplace_back(r.device, r.channel, r.quantity);
    for (const auto& k : keys)
      for (const auto& r : b)
        if (std::tuple<int, int, int>{r.device, r.channel, r.quantity} == k) all.push_back(r);
  }
  std::stable_sort(all.begin(), all.end(), [](const RawReading& a, const RawReading& b) {
    return std::tie(a.time_ns, a.device, a.channel, a.quantity) <
           std::tie(b.time_ns, b.device, b.channel, b.quantity);
  });
  return all;
}

TEST(ReadingStream, GivesTheOrderOfAStableSortOfEverythingStored) {
  TempDir dir;
  Store store(dir.path / "s.sqlite", {.full_sync = false});  // no power loss to survive here
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 6; ++trial) {
    const auto run = store.begin_run({.kind = "stream"});
    std::vector<std::vector<RawReading>> batches;
    std::int64_t t = 1'000'000;
    for (int b = 0; b < 12; ++b) {
      std::vector<RawReading> batch;
      const std::size_t n = 1 + rng() % 900;
      for (std::size_t i = 0; i < n; ++i) {
        // Mostly forward in time, with equal times across and within series, and (trials 3+)
        // some readings far back in time: chunks of one series then overlap.
        t += static_cast<std::int64_t>(rng() % 3) * 1000;
        std::int64_t ti = t;
        if (trial >= 3 && rng() % 50 == 0) ti -= static_cast<std::int64_t>(rng() % 2'000'000);
        batch.push_back({.time_ns = ti,
                         .device = static_cast<std::uint16_t>(rng() % 3),
                         .channel = static_cast<std::uint8_t>(rng() % 2),
                         .quantity = static_cast<std::uint8_t>(rng() % 3),
                         .status = static_cast<std::uint8_t>(rng() % 5 == 0),
                         .value = static_cast<double>(rng() % 1000) * 1e-6});
      }
      store.append_readings(run, batch);
      batches.push_back(std::move(batch));
    }
    const auto want = reference_order(batches);
    for (std::size_t max :
         {std::size_t{1}, std::size_t{7}, std::size_t{1000}, std::size_t{1} << 20}) {
      auto stream = store.stream_readings(run);
      std::vector<RawReading> got, part;
      while (stream.next(part, max)) {
        ASSERT_LE(part.size(), max);
        ASSERT_FALSE(part.empty());
        got.insert(got.end(), part.begin(), part.end());
      }
      ASSERT_EQ(got.size(), want.size()) << trial;
      for (std::size_t i = 0; i < want.size(); ++i)
        ASSERT_TRUE(same(got[i], want[i])) << trial << " " << i;
    }
    // The quantity filter keeps the same order for what it selects.
    const std::uint8_t q[] = {2, 0};
    const auto some = store.readings(run, q);
    std::vector<RawReading> want_some;
    for (const auto& r : want)
      if (r.quantity != 1) want_some.push_back(r);
    ASSERT_EQ(some.size(), want_some.size());
    for (std::size_t i = 0; i < some.size(); ++i) ASSERT_TRUE(same(some[i], want_some[i])) << i;
  }
}

TEST(ReadingStream, HoldsOneChunkPerSeriesOfALongRun) {
  // 400 batches of two series (a 10 kHz stream and a 1 Hz one): the stream reads them in
  // order of time and opens each chunk only when its time comes, so the readings handed out
  // after k chunks are at most k batches' worth.
  TempDir dir;
  Store store(dir.path / "s.sqlite", {.full_sync = false});  // no power loss to survive here
  const auto run = store.begin_run({.kind = "stream"});
  std::int64_t i = 0;
  for (int b = 0; b < 400; ++b) {
    std::vector<RawReading> batch;
    for (int k = 0; k < 500; ++k, ++i) {
      batch.push_back(
          {.time_ns = i * 100'000, .quantity = 1, .value = 1e-6 * static_cast<double>(i)});
      if (i % 100 == 0)
        batch.push_back({.time_ns = i * 100'000, .device = 1, .quantity = 2, .value = 20.0});
    }
    store.append_readings(run, batch);
  }
  auto stream = store.stream_readings(run);
  std::vector<RawReading> part;
  std::size_t total = 0;
  while (stream.next(part, 100)) {
    total += part.size();
    // Each batch is two chunks of 500 + 5 readings; the stream may be one batch ahead.
    ASSERT_LE(stream.chunks_read(), 2 * (total / 505 + 2)) << total;
  }
  EXPECT_EQ(total, 400u * 505u);
  EXPECT_EQ(stream.chunks_read(), 800u);
}

}  // namespace
