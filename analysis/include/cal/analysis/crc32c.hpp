#pragma once
// CRC-32C (Castagnoli: reflected, polynomial 0x82F63B78, initial and final XOR 0xFFFFFFFF), as
// used by iSCSI (RFC 3720, whose appendix B.4 gives test vectors) and ext4. The capture file
// checks its blocks with it and the run store its reading chunks, so it lives here, below
// both. No I/O; a checksum, not metrology, but analysis/ is the library everything depends on.
//
// x86-64 with SSE4.2 uses the CRC32 instruction (8 bytes per instruction); every other CPU
// uses slicing-by-8 tables (8 bytes per step). Both give identical results.
#include <cstddef>
#include <cstdint>
#include <span>

namespace cal {

// The CRC of `data`, continued from `crc` (the CRC of what came before; 0 for a start), so
// crc32c(b, crc32c(a)) == crc32c(a followed by b).
std::uint32_t crc32c(std::span<const std::byte> data, std::uint32_t crc = 0);

// The portable path alone (slicing-by-8), for tests and for benchmarks of the fallback.
std::uint32_t crc32c_portable(std::span<const std::byte> data, std::uint32_t crc = 0);

// True when crc32c() uses the CPU's CRC32 instruction.
bool crc32c_hardware();

}  // namespace cal
