#include "fuzz_common.hpp"
#include "halsampler/codec.hpp"

// halsampler lines, tagged and untagged (libFuzzer; built by scripts/fuzz).
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::drivers::codec;
  fuzz_codec(HalsamplerCodec{}, HalsamplerCodec{{.max_line_bytes = 64}}, data, size);
  fuzz_codec(HalsamplerCodec{{.sample_numbers = false}},
             HalsamplerCodec{{.sample_numbers = false, .max_line_bytes = 64}}, data, size);
  return 0;
}
