#pragma once
// The encodings of a reading chunk's BLOB (one device/channel/quantity per chunk) and the
// checksum stored with it; the layouts are documented in docs/storage.md.
//
//   encoding 1 (schemas 1 and 2): 17-byte records, time_ns int64, status, value double.
//   encoding 2: the times as varint deltas (or deltas of deltas, whichever is smaller), the
//               statuses only when one is not ok, the values XOR-ed with the previous value
//               with the leading zero bytes dropped (or raw, whichever is smaller). Lossless:
//               every time and every bit of every value (NaN payloads, -0.0) comes back.
//
// Decoding checks every length and count, so a damaged BLOB is an error (ChunkError), never
// a misread or a read past its end.
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "cal/storage/store.hpp"

namespace cal::storage::chunk {

inline constexpr int packed_v1 = 1;
inline constexpr int columns_v2 = 2;

// A chunk that does not decode; the message says what is wrong (the store adds where).
class ChunkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The readings of one series, column by column (the writer's scratch, reused between batches).
struct Columns {
  std::vector<std::int64_t> time_ns;
  std::vector<std::uint8_t> status;
  std::vector<double> value;
  std::size_t size() const { return time_ns.size(); }
  void clear() {
    time_ns.clear();
    status.clear();
    value.clear();
  }
  void push(const RawReading& r) {
    time_ns.push_back(r.time_ns);
    status.push_back(r.status);
    value.push_back(r.value);
  }
};

// The encoding-2 BLOB of `c` (at least one reading) into `out` (replaced).
void encode(const Columns& c, std::vector<unsigned char>& out);

// Appends the `count` readings of a BLOB in `encoding` (1 or 2) to `out`, with the series'
// device, channel and quantity. Throws ChunkError when the BLOB does not hold exactly `count`
// readings in that encoding, or the encoding is unknown.
void decode(int encoding, std::span<const unsigned char> blob, std::size_t count,
            std::uint16_t device, std::uint8_t channel, std::uint8_t quantity,
            std::vector<RawReading>& out);

// Where a chunk belongs and what it claims to hold: covered by its checksum together with the
// BLOB, so a damaged row (a changed run, series, time range, count or place in the run) is
// detected as well as damaged bytes.
struct Key {
  std::int64_t run_id = 0;
  std::int64_t seq = 0;  // 0, 1, 2, ... in the order the run's chunks were written
  std::int64_t device = 0, channel = 0, quantity = 0;
  std::int64_t first_ns = 0, last_ns = 0;
  std::int64_t count = 0;
  std::int64_t encoding = columns_v2;
};

// The key of a stored row (any record with the row's device, channel, quantity, times, count and
// encoding) as run `run_id`'s chunk number `seq`: one place that lists what a checksum covers.
template <class Row>
Key key_of(std::int64_t run_id, std::int64_t seq, const Row& r) {
  return {.run_id = run_id,
          .seq = seq,
          .device = r.device,
          .channel = r.channel,
          .quantity = r.quantity,
          .first_ns = r.first_ns,
          .last_ns = r.last_ns,
          .count = r.count,
          .encoding = r.encoding};
}

// CRC-32C of the key (nine little-endian int64s, in the order above) followed by the BLOB.
std::uint32_t checksum(const Key& key, std::span<const unsigned char> blob);

}  // namespace cal::storage::chunk
