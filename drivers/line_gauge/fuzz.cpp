#include "fuzz_common.hpp"
#include "line_gauge/codec.hpp"

// A fresh codec per input, copied from prototypes built once: compiling the pattern's
// std::regex for every input allocated ~40 kB each time, which ASan's quarantine of freed
// memory held on to (the RSS climbed to ~1 GB, then stayed; with the quarantine off it stayed
// at 34 MB: no growth in the codec itself). The copy has the same state as a new codec.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::drivers::codec;
  static const GaugeCodec plain{};
  static const GaugeCodec pattern{
      GaugeConfig{.pattern = "T=([+-]?[0-9.]+)", .unit = GaugeUnit::degc, .max_line_bytes = 64}};
  fuzz_codec(GaugeCodec(plain), GaugeCodec(pattern), data, size);
  return 0;
}
