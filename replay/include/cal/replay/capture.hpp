#pragma once
// The wire-level capture file (format: docs/capture-format.md). A capture holds, per device,
// the exact bytes received and sent with their times, and events (opened, closed, errors),
// after a header describing the session. It is written streaming, in blocks with a CRC-32C
// each, with bounded memory; a truncated or damaged file is detected, and every record
// before the damage is still read.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace cal::replay {

inline constexpr std::uint16_t capture_major_version = 1;
inline constexpr std::uint16_t capture_minor_version = 0;

// Opening, writing and reading errors: the message names the file, and the byte offset
// where it applies.
class CaptureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// CRC-32C (Castagnoli, reflected, poly 0x82F63B78), as used by iSCSI and ext4; the check
// value of "123456789" is 0xE3069283. The implementation is cal::crc32c
// (cal/analysis/crc32c.hpp: the CPU's CRC32 instruction where there is one).
std::uint32_t crc32c(std::span<const std::byte> data, std::uint32_t crc = 0);

enum class RecordKind : std::uint8_t {
  received = 0,  // bytes from the device
  sent = 1,      // bytes to the device
  event = 2,     // text: "opened", "closed", "error: ...", "gap: ..."
};

struct Record {
  std::int64_t time_ns = 0;  // since the session start (monotonic)
  std::uint16_t device = 0;
  RecordKind kind = RecordKind::received;
  std::vector<std::byte> bytes;
  std::string_view text() const {
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }
};

// A record read in place: `bytes` points into the reader's current block and stays valid
// until the reader's next call of next() or next_view(). No allocation per record.
struct RecordView {
  std::int64_t time_ns = 0;
  std::uint16_t device = 0;
  RecordKind kind = RecordKind::received;
  std::span<const std::byte> bytes;
  std::string_view text() const {
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }
};

// Limits that keep every block readable: a record's bytes are at most max_record_bytes and
// block_bytes at most max_block_bytes, so a block payload stays under the reader's 64 MiB
// plausibility limit (block_bytes + one record + its 16-byte header).
inline constexpr std::size_t max_record_bytes = 16u << 20;
inline constexpr std::size_t max_block_bytes = 32u << 20;

struct WriterLimits {
  std::size_t block_bytes = 64 * 1024;  // a block is written when its payload reaches this
  // A cap on the file size (0: none): a write that would pass it fails as on a full disk
  // (ENOSPC), which is how the tests exercise that path (as StoreOptions::max_pages does).
  std::uint64_t max_file_bytes = 0;
};

class CaptureWriter {
 public:
  // header_json: the session (devices, settings, software, start time), a JSON object as
  // text (the format does not interpret it). Throws CaptureError naming the path: cannot
  // create, header over 1 MiB, block_bytes over max_block_bytes, or the header cannot be
  // written (e.g. a full disk: the message carries the errno text).
  //
  // After any write error every later call throws at once, and nothing more is written: the
  // blocks flushed before the error stay intact and readable.
  CaptureWriter(const std::filesystem::path& path, std::string_view header_json,
                WriterLimits limits = {});
  ~CaptureWriter();  // writes the last block; errors there are lost, call close() to see them
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;

  // Throws CaptureError if bytes is over max_record_bytes, after close(), after an earlier
  // write error, or when writing a full block fails (path, byte offset and errno text).
  void record(std::int64_t time_ns, std::uint16_t device, RecordKind kind,
              std::span<const std::byte> bytes);
  void event(std::int64_t time_ns, std::uint16_t device, std::string_view text);
  // Writes the pending block and flushes it to the OS (what is flushed survives a crash of
  // this process).
  void flush();
  void close();
  // Bytes of records held in memory: below block_bytes between calls, and at most
  // block_bytes + 16 + the record size inside the call that completes a block.
  std::size_t buffered_bytes() const;
  std::size_t max_buffered_bytes() const;  // the peak, for the bounded-memory test
  std::uint64_t bytes_written() const;
  const std::filesystem::path& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct Damage {
  std::uint64_t offset = 0;  // byte offset of the damaged block (or of the truncation)
  std::uint64_t block = 0;   // 0-based block number
  std::string what;          // "truncated block header", "bad CRC", ...
};
// "block 3 at byte 1234: bad CRC (the block is corrupted)", for messages.
std::string describe(const Damage& d);

class CaptureReader {
 public:
  // Reads and checks the header. Throws CaptureError: cannot open, not a capture file, a
  // newer major version, truncated or damaged header.
  explicit CaptureReader(const std::filesystem::path& path);
  ~CaptureReader();
  CaptureReader(CaptureReader&&) noexcept;

  const std::string& header_json() const;
  std::uint16_t minor_version() const;
  // The next record, or nullopt at the end of the file or at damage (then damage() says
  // what and where; every record before it has been returned).
  std::optional<Record> next();
  // The same without copying the bytes (see RecordView for how long they stay valid).
  std::optional<RecordView> next_view();
  const std::optional<Damage>& damage() const;
  std::uint64_t records_read() const;
  const std::filesystem::path& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Replay pacing: records are handed out in file order; in real time (speed > 0) each one no
// earlier than its recorded time / speed after the start, using the injected clock and sleep
// so that tests check the pacing without sleeping; speed 0 is as fast as possible.
struct PacingClock {
  std::function<std::int64_t()> now_ns;  // monotonic
  std::function<void(std::int64_t until_ns)> sleep_until;
};
PacingClock system_pacing_clock();

class ReplaySource {
 public:
  // devices: the device ids to hand out (empty: all). The first record is handed out at once;
  // record k no earlier than start + (t_k - t_first) / speed on the injected clock. Throws
  // CaptureError for a speed that is negative or not finite, and as CaptureReader does.
  ReplaySource(const std::filesystem::path& path, double speed = 0.0,
               std::vector<std::uint16_t> devices = {}, PacingClock clock = system_pacing_clock());
  const std::string& header_json() const;
  std::optional<Record> next();  // waits for the record's time in real-time mode
  const std::optional<Damage>& damage() const;

 private:
  CaptureReader reader_;
  double speed_;
  std::vector<std::uint16_t> devices_;
  PacingClock clock_;
  std::optional<std::int64_t> start_ns_, first_record_ns_;
};

}  // namespace cal::replay
