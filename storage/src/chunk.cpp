// Reading chunk encodings (see chunk.hpp; layouts in docs/storage.md).
#include "cal/storage/chunk.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>

#include "cal/analysis/crc32c.hpp"

namespace cal::storage::chunk {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the chunk layouts are little-endian, as the host is (x86-64, arm64)");

// Encoding-2 flags (byte 0); the other bits are zero.
constexpr unsigned char kDeltaOfDelta = 1;  // times: deltas of deltas, else deltas
constexpr unsigned char kStatuses = 2;      // a status byte per reading, else all ok (0)
constexpr unsigned char kXorValues = 4;     // values XOR-coded, else 8 raw bytes each
constexpr unsigned char kKnownFlags = kDeltaOfDelta | kStatuses | kXorValues;

constexpr std::size_t kV1RecordBytes = 17;

// Signed differences are taken modulo 2^64 (unsigned arithmetic cannot overflow), then
// zigzag-mapped so that small negative and positive differences both give short varints.
std::uint64_t zigzag(std::uint64_t d) {
  return (d << 1) ^ static_cast<std::uint64_t>(static_cast<std::int64_t>(d) >> 63);
}
std::uint64_t unzigzag(std::uint64_t z) { return (z >> 1) ^ (0 - (z & 1)); }

std::size_t varint_size(std::uint64_t v) {
  return (static_cast<std::size_t>(std::bit_width(v | 1)) + 6) / 7;
}
unsigned char* put_varint(unsigned char* w, std::uint64_t v) {
  while (v >= 0x80) {
    *w++ = static_cast<unsigned char>(v | 0x80);
    v >>= 7;
  }
  *w++ = static_cast<unsigned char>(v);
  return w;
}

std::uint64_t bits_of(double v) { return std::bit_cast<std::uint64_t>(v); }
// Bytes of x that must be stored: 8 minus its leading zero bytes (0 for x == 0).
unsigned significant_bytes(std::uint64_t x) {
  return 8 - static_cast<unsigned>(std::countl_zero(x)) / 8;
}

// A bounds-checked reader over a BLOB: every read that would pass the end is a ChunkError.
class Reader {
 public:
  explicit Reader(std::span<const unsigned char> b) : p_(b.data()), end_(b.data() + b.size()) {}
  std::size_t left() const { return static_cast<std::size_t>(end_ - p_); }
  void need(std::size_t n, const char* what) const {
    if (left() < n)
      throw ChunkError(
          fmt::format("the {} run past the end of the chunk ({} bytes left)", what, left()));
  }
  unsigned char byte(const char* what) {
    need(1, what);
    return *p_++;
  }
  std::uint64_t varint(const char* what) {
    std::uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      const unsigned char b = byte(what);
      if (shift == 63 && b > 1) break;
      v |= static_cast<std::uint64_t>(b & 0x7f) << shift;
      if (!(b & 0x80)) return v;
    }
    throw ChunkError(fmt::format("a varint in the {} is longer than 64 bits", what));
  }
  std::uint64_t bytes_le(unsigned n, const char* what) {
    need(n, what);
    std::uint64_t v = 0;
    std::memcpy(&v, p_, n);
    p_ += n;
    return v;
  }
  const unsigned char* take(std::size_t n, const char* what) {
    need(n, what);
    const unsigned char* at = p_;
    p_ += n;
    return at;
  }

 private:
  const unsigned char* p_;
  const unsigned char* end_;
};

void decode_v1(std::span<const unsigned char> blob, std::size_t count, RawReading proto,
               std::vector<RawReading>& out) {
  if (count == 0) throw ChunkError("an empty chunk");  // never written
  if (blob.size() != count * kV1RecordBytes)
    throw ChunkError(fmt::format("{} bytes for {} readings of 17 bytes", blob.size(), count));
  const unsigned char* p = blob.data();
  for (std::size_t i = 0; i < count; ++i, p += kV1RecordBytes) {
    std::memcpy(&proto.time_ns, p, 8);
    proto.status = p[8];
    std::memcpy(&proto.value, p + 9, 8);
    out.push_back(proto);
  }
}

void decode_v2(std::span<const unsigned char> blob, std::size_t count, RawReading proto,
               std::vector<RawReading>& out) {
  Reader in(blob);
  const unsigned char flags = in.byte("header");
  if (flags & ~kKnownFlags) throw ChunkError(fmt::format("unknown flags 0x{:02x}", flags));
  const std::uint64_t stored_count = in.varint("header");
  if (stored_count != count)
    throw ChunkError(
        fmt::format("the chunk holds {} readings, its row says {}", stored_count, count));
  if (count == 0) throw ChunkError("an empty chunk");
  const std::size_t base = out.size();
  // Each reading needs at least one time byte (after the first) and a value nibble: a count
  // the BLOB cannot hold is refused before anything is allocated for it.
  if (count - 1 > in.left())
    throw ChunkError(fmt::format("{} readings in {} bytes", count, blob.size()));
  out.resize(base + count, proto);
  RawReading* r = out.data() + base;
  std::uint64_t t = in.bytes_le(8, "first time");
  r[0].time_ns = static_cast<std::int64_t>(t);
  std::uint64_t d = 0;
  const bool dod = flags & kDeltaOfDelta;
  for (std::size_t i = 1; i < count; ++i) {
    const std::uint64_t e = unzigzag(in.varint("times"));
    d = dod ? d + e : e;
    t += d;
    r[i].time_ns = static_cast<std::int64_t>(t);
  }
  if (flags & kStatuses) {
    const unsigned char* s = in.take(count, "statuses");
    for (std::size_t i = 0; i < count; ++i) r[i].status = s[i];
  }
  if (flags & kXorValues) {
    std::uint64_t prev = 0;
    for (std::size_t i = 0; i < count; i += 2) {
      const unsigned char h = in.byte("value headers");
      const unsigned lo = h & 0x0f, hi = h >> 4;
      if (lo > 8 || hi > 8 || (i + 1 == count && hi != 0))
        throw ChunkError(fmt::format("a bad value header 0x{:02x}", h));
      prev ^= in.bytes_le(8 - lo, "values");
      r[i].value = std::bit_cast<double>(prev);
      if (i + 1 < count) {
        prev ^= in.bytes_le(8 - hi, "values");
        r[i + 1].value = std::bit_cast<double>(prev);
      }
    }
  } else {
    const unsigned char* v = in.take(count * 8, "values");
    for (std::size_t i = 0; i < count; ++i) std::memcpy(&r[i].value, v + 8 * i, 8);
  }
  if (in.left() != 0)
    throw ChunkError(fmt::format("{} bytes left over after {} readings", in.left(), count));
}

}  // namespace

void encode(const Columns& c, std::vector<unsigned char>& out) {
  const std::size_t n = c.size();
  if (n == 0 || c.status.size() != n || c.value.size() != n)
    throw std::logic_error("chunk::encode: columns of different sizes or empty");
  // Sizes first (one pass): deltas against deltas of deltas, XOR-coded values against raw.
  std::size_t delta_bytes = 0, dod_bytes = 0, xor_bytes = (n + 1) / 2;
  std::uint64_t prev_d = 0, prev_bits = 0;
  bool statuses = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) {
      const std::uint64_t d =
          static_cast<std::uint64_t>(c.time_ns[i]) - static_cast<std::uint64_t>(c.time_ns[i - 1]);
      delta_bytes += varint_size(zigzag(d));
      dod_bytes += varint_size(zigzag(d - prev_d));
      prev_d = d;
    }
    const std::uint64_t b = bits_of(c.value[i]);
    xor_bytes += significant_bytes(b ^ prev_bits);
    prev_bits = b;
    statuses = statuses || c.status[i] != 0;
  }
  const bool dod = dod_bytes < delta_bytes, xored = xor_bytes < 8 * n;
  const unsigned char flags = static_cast<unsigned char>(
      (dod ? kDeltaOfDelta : 0) | (statuses ? kStatuses : 0) | (xored ? kXorValues : 0));
  // The exact size is known: write through a pointer into the sized buffer (16 bytes of slack
  // for the 8-byte stores of the values), no capacity check per byte; trimmed at the end.
  const std::size_t size = 1 + varint_size(n) + 8 + (dod ? dod_bytes : delta_bytes) +
                           (statuses ? n : 0) + (xored ? xor_bytes : 8 * n);
  out.resize(size + 16);
  unsigned char* w = out.data();
  *w++ = flags;
  w = put_varint(w, n);
  std::memcpy(w, &c.time_ns[0], 8);
  w += 8;
  prev_d = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const std::uint64_t d =
        static_cast<std::uint64_t>(c.time_ns[i]) - static_cast<std::uint64_t>(c.time_ns[i - 1]);
    w = put_varint(w, zigzag(dod ? d - prev_d : d));
    prev_d = d;
  }
  if (statuses) {
    std::memcpy(w, c.status.data(), n);
    w += n;
  }
  if (!xored) {
    std::memcpy(w, c.value.data(), 8 * n);
    w += 8 * n;
  } else {
    prev_bits = 0;
    for (std::size_t i = 0; i < n; i += 2) {
      const std::uint64_t x0 = bits_of(c.value[i]) ^ prev_bits;
      prev_bits = bits_of(c.value[i]);
      std::uint64_t x1 = 0;
      unsigned b1 = 0;
      if (i + 1 < n) {
        x1 = bits_of(c.value[i + 1]) ^ prev_bits;
        prev_bits = bits_of(c.value[i + 1]);
        b1 = significant_bytes(x1);
      }
      const unsigned b0 = significant_bytes(x0);
      // The header holds the leading zero bytes (8 - significant), two values per byte; the
      // high nibble of an odd count's last header is 0. Each value is stored as 8 bytes and
      // the pointer advanced by its significant ones (little-endian: the low bytes first).
      *w++ = static_cast<unsigned char>((8 - b0) | (i + 1 < n ? (8 - b1) << 4 : 0));
      std::memcpy(w, &x0, 8);
      w += b0;
      std::memcpy(w, &x1, 8);
      w += b1;
    }
  }
  if (static_cast<std::size_t>(w - out.data()) != size)
    throw std::logic_error("chunk::encode: size pass and write pass disagree");
  out.resize(size);
}

void decode(int encoding, std::span<const unsigned char> blob, std::size_t count,
            std::uint16_t device, std::uint8_t channel, std::uint8_t quantity,
            std::vector<RawReading>& out) {
  const RawReading proto{.device = device, .channel = channel, .quantity = quantity};
  const std::size_t base = out.size();
  try {
    switch (encoding) {
      case packed_v1:
        return decode_v1(blob, count, proto, out);
      case columns_v2:
        return decode_v2(blob, count, proto, out);
      default:
        throw ChunkError(fmt::format("unknown encoding {}", encoding));
    }
  } catch (const ChunkError&) {
    out.resize(base);  // nothing of a chunk that does not decode
    throw;
  }
}

std::uint32_t checksum(const Key& k, std::span<const unsigned char> blob) {
  const std::array<std::int64_t, 9> fields{k.run_id,   k.seq,     k.device, k.channel, k.quantity,
                                           k.first_ns, k.last_ns, k.count,  k.encoding};
  const std::uint32_t head = cal::crc32c(std::as_bytes(std::span(fields)));
  return cal::crc32c(std::as_bytes(blob), head);
}

}  // namespace cal::storage::chunk
