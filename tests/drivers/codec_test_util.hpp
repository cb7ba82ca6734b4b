#pragma once
// Helpers shared by the codec tests: feed a stream whole, one byte at a time, or in seeded
// random chunks, and collect what the codec produced; run a driver's decoder over a text.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/registry.hpp"

namespace codec_test {

// The independent value of a printed reading in SI: its decimal text with the exponent moved by
// `shift`, read by strtod ("100.000123" mm in metres: strtod("100.000123e-3"); "1.5e3" pm:
// strtod("1.5e-9")). A leading '+' (as gauges print it) is dropped.
inline double strtod_shifted(std::string text, int shift) {
  if (!text.empty() && text.front() == '+') text.erase(0, 1);
  const auto e = text.find_first_of("eE");
  long exponent = shift;
  if (e != std::string::npos) {
    exponent += std::strtol(text.c_str() + e + 1, nullptr, 10);
    text.erase(e);
  }
  text += "e" + std::to_string(exponent);
  return std::strtod(text.c_str(), nullptr);
}

inline std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v); }

template <class Frame>
struct Decoded {
  std::vector<Frame> frames;
  std::vector<cal::drivers::codec::CodecError> errors;
  cal::drivers::codec::CodecStats stats;
};

template <class Codec>
Decoded<typename Codec::Frame> feed_whole(Codec codec, std::string_view stream) {
  Decoded<typename Codec::Frame> d;
  codec.feed(stream, d.frames, d.errors);
  d.stats = codec.stats();
  return d;
}

// The frames of `stream` fed whole to a codec the test keeps (to read its counters after); the
// stream must give no codec error.
template <class Codec>
std::vector<typename Codec::Frame> frames_without_errors(Codec& codec, std::string_view stream) {
  std::vector<typename Codec::Frame> frames;
  std::vector<cal::drivers::codec::CodecError> errors;
  codec.feed(stream, frames, errors);
  EXPECT_TRUE(errors.empty()) << errors.size() << " codec errors, the first: "
                              << (errors.empty() ? "" : errors.front().description);
  return frames;
}

// Every chunk boundary: the stream is fed one byte at a time.
template <class Codec>
Decoded<typename Codec::Frame> feed_bytewise(Codec codec, std::string_view stream) {
  Decoded<typename Codec::Frame> d;
  for (std::size_t i = 0; i < stream.size(); ++i)
    codec.feed(stream.substr(i, 1), d.frames, d.errors);
  d.stats = codec.stats();
  return d;
}

// Random chunk sizes 0..max_chunk (zero-length feeds included on purpose), seeded.
template <class Codec>
Decoded<typename Codec::Frame> feed_random_chunks(Codec codec, std::string_view stream,
                                                  std::uint32_t seed, std::size_t max_chunk = 17) {
  Decoded<typename Codec::Frame> d;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> size(0, max_chunk);
  std::size_t i = 0;
  while (i < stream.size()) {
    const std::size_t n = std::min(size(rng), stream.size() - i);
    codec.feed(stream.substr(i, n), d.frames, d.errors);
    i += n;
  }
  d.stats = codec.stats();
  return d;
}

// What the decoder of `driver` (default options, as `daq decode DRIVER`) makes of `bytes` fed
// whole, then finished; its stats too when asked.
inline std::vector<cal::drivers::DecodedItem> decode_whole(
    std::string_view driver, std::string_view bytes,
    cal::drivers::codec::CodecStats* stats = nullptr) {
  const auto& drv = cal::drivers::driver(driver);
  auto decoder = drv.make_decoder(cal::drivers::options_from_text(drv, {}));
  std::vector<cal::drivers::DecodedItem> items;
  decoder->feed(std::as_bytes(std::span(bytes)), items);
  decoder->finish(items);
  if (stats != nullptr) *stats = decoder->stats();
  return items;
}

inline bool same_errors(const std::vector<cal::drivers::codec::CodecError>& a,
                        const std::vector<cal::drivers::codec::CodecError>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].kind != b[i].kind || a[i].offset != b[i].offset) return false;
  }
  return true;
}

}  // namespace codec_test
