// The reading chunk decoder (cal::storage::chunk): a database file is input from outside, and a
// chunk's checksum can be forged along with its bytes, so the decoder must refuse any BLOB it
// cannot decode exactly (ChunkError) without reading out of bounds or allocating beyond the
// BLOB. The first byte picks the encoding, the next two the claimed count; the rest is the BLOB.
// A decoded chunk must encode again to a BLOB that decodes to the same readings.
#include <cstring>
#include <vector>

#include "cal/storage/chunk.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::storage;
  if (size < 3) return 0;
  const int encoding = data[0] % 4;
  const std::size_t count = data[1] | (std::size_t{data[2]} << 8);
  const std::span<const unsigned char> blob(data + 3, size - 3);
  std::vector<RawReading> out;
  try {
    chunk::decode(encoding, blob, count, 1, 2, 3, out);
  } catch (const chunk::ChunkError&) {
    if (!out.empty()) __builtin_trap();  // nothing is left of a refused chunk
    return 0;
  }
  if (out.size() != count) __builtin_trap();
  chunk::Columns c;
  for (const auto& r : out) c.push(r);
  std::vector<unsigned char> again;
  chunk::encode(c, again);
  std::vector<RawReading> back;
  chunk::decode(chunk::columns_v2, again, count, 1, 2, 3, back);
  for (std::size_t i = 0; i < count; ++i)
    if (back[i].time_ns != out[i].time_ns || back[i].status != out[i].status ||
        std::memcmp(&back[i].value, &out[i].value, 8) != 0)
      __builtin_trap();
  return 0;
}
