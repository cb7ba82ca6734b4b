#include "fuzz_common.hpp"
#include "ptu300/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::drivers::codec;
  fuzz_codec(Ptu300Codec{}, Ptu300Codec{Ptu300Config{.checksum = Ptu300Checksum::cs2}}, data, size);
  return 0;
}
