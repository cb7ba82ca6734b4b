#pragma once
// Each fuzz target feeds the input to a codec twice: whole, and split at a position taken from
// the first byte, so both the framing and the reassembly paths see arbitrary bytes. Any
// crash, sanitizer report or exception is a failure (codecs must not throw on bad bytes).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "cal/drivers/codec/common.hpp"

template <class Codec>
void fuzz_codec(Codec whole, Codec split, const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  std::vector<typename Codec::Frame> frames;
  std::vector<cal::drivers::codec::CodecError> errors;
  whole.feed(bytes, frames, errors);
  const std::size_t cut = size > 0 ? data[0] % (size + 1) : 0;
  split.feed(bytes.substr(0, cut), frames, errors);
  split.feed(bytes.substr(cut), frames, errors);
}
