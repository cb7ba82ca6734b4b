// The Renishaw .rtx reader on arbitrary bytes: a header it refuses with RtxError (named),
// or samples it reads to the end; never a crash, a hang or undefined behaviour (UBSan:
// Sample no 1e300, a rate of 1e-300 Hz).
#include <array>
#include <string>

#include "cal/replay/rtx.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    cal::replay::RtxReader r(std::string(reinterpret_cast<const char*>(data), size), "fuzz.rtx");
    const auto& h = r.header();
    if (!(h.sample_rate_hz >= cal::replay::rtx_min_rate_hz &&
          h.sample_rate_hz <= cal::replay::rtx_max_rate_hz))
      __builtin_trap();  // the reader promised a rate in range
    std::array<double, 7> buf{};
    std::uint64_t n = 0;
    while (const auto got = r.read(buf)) n += got;
    if (n != h.samples || h.data_offset + 8 * n > size) __builtin_trap();
  } catch (const cal::replay::RtxError&) {
  }
  return 0;
}
