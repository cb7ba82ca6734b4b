// The capture reader on arbitrary bytes: every record before the first damage, then nullopt
// with the damage described; never a crash, a hang or an unbounded allocation (a block
// length is checked against 64 MiB before any allocation, and libFuzzer's -rss_limit_mb
// would catch more). CaptureError (a bad header) is the reader's clear refusal.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "cal/replay/capture.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The reader takes a path: one scratch file per fuzzing process, rewritten for each input.
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("fuzz_capture_" + std::to_string(::getpid())))
          .string();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    cal::replay::CaptureReader r(path);
    std::size_t bytes = 0;
    while (auto rec = r.next()) bytes += rec->bytes.size();
    if (r.damage()) (void)cal::replay::describe(*r.damage());
    if (bytes > size) __builtin_trap();  // records cannot hold more than the file
  } catch (const cal::replay::CaptureError&) {
  }
  return 0;
}
