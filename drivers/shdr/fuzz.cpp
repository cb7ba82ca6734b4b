#include "fuzz_common.hpp"
#include "shdr/codec.hpp"

// MTConnect SHDR lines (libFuzzer; built by scripts/fuzz).
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::drivers::codec;
  fuzz_codec(ShdrCodec{}, ShdrCodec{{.max_line_bytes = 64}}, data, size);
  return 0;
}
