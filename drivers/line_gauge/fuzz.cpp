#include "fuzz_common.hpp"
#include "line_gauge/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cal::drivers::codec;
  fuzz_codec(GaugeCodec{},
             GaugeCodec{GaugeConfig{
                 .pattern = "T=([+-]?[0-9.]+)", .unit = GaugeUnit::degc, .max_line_bytes = 64}},
             data, size);
  return 0;
}
