#include "fuzz_common.hpp"
#include "ids3010/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::drivers::codec;
  IdsCodec a, b;
  // Pending requests, so that answers are decoded rather than refused as unknown ids.
  for (int i = 0; i < 8; ++i) {
    a.encode(IdsMethod::get_axes_displacement);
    b.encode(IdsMethod::get_axes_displacement);
  }
  a.note_requests(std::as_bytes(std::span(reinterpret_cast<const char*>(data), size)));
  fuzz_codec(std::move(a), std::move(b), data, size);
  return 0;
}
