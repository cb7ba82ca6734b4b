// The capture reader on arbitrary bytes: every record before the first damage, then nullopt
// with the damage described; never a crash, a hang or an allocation beyond the file (a
// claimed header or block length is checked against the bytes left in the file before
// anything is allocated: found here, a 30-byte file made the reader allocate 64 MiB).
// CaptureError (a bad header) is the reader's clear refusal.
#include <sys/mman.h>
#include <unistd.h>

#include <string>

#include "cal/replay/capture.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The reader takes a path: an in-memory file (memfd), rewritten for each input and opened
  // through /proc/self/fd, so nothing touches the disk and nothing is left behind.
  static const int fd = ::memfd_create("fuzz_capture", 0);
  static const std::string path = "/proc/self/fd/" + std::to_string(fd);
  if (fd < 0 || ::ftruncate(fd, 0) != 0) return 0;
  if (size > 0 && ::pwrite(fd, data, size, 0) != static_cast<ssize_t>(size)) return 0;
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
