#include "fuzz_common.hpp"
#include "temper/codec.hpp"

// The three report families in turn (the first byte picks one), so each decoder sees
// arbitrary reports.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::drivers::codec;
  const TemperFamily families[] = {TemperFamily::ds75, TemperFamily::gold, TemperFamily::temperx};
  const TemperConfig config{.family = families[size > 0 ? data[0] % 3 : 0]};
  fuzz_codec(TemperCodec{config}, TemperCodec{config}, data, size);
  return 0;
}
