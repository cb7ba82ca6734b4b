#include "cal/drivers/codec/position_feed.hpp"
#include "fuzz_common.hpp"

// Both position feed codecs on the same bytes: halsampler and MTConnect SHDR lines.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::drivers::codec;
  fuzz_codec(HalsamplerCodec{}, HalsamplerCodec{{.max_line_bytes = 64}}, data, size);
  fuzz_codec(ShdrCodec{}, ShdrCodec{{.max_line_bytes = 64}}, data, size);
  return 0;
}
