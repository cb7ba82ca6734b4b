// The capture file format (see capture.hpp and docs/capture-format.md).
#include "cal/replay/capture.hpp"

#include <fmt/format.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>
#include <utility>

#include "cal/analysis/crc32c.hpp"

namespace cal::replay {
namespace {

constexpr std::array<char, 8> kMagic{'C', 'A', 'L', 'D', 'A', 'Q', 'C', 'P'};
constexpr std::uint32_t kBlockMagic = 0x4B4C4243;  // "CBLK" little-endian
constexpr std::uint32_t kEndMagic = 0x444E4543;    // "CEND": written by close()
constexpr std::size_t kBlockHeader = 16;           // magic, payload length, records, crc
constexpr std::size_t kRecordHeader = 16;          // time, device, kind, reserved, length
constexpr std::uint32_t kMaxHeader = 1 << 20;
constexpr std::uint32_t kMaxPayload = 64 << 20;

template <class T>
void put(std::vector<std::byte>& out, T v) {  // little-endian (the host is; static_assert)
  static_assert(std::endian::native == std::endian::little);
  const auto* p = reinterpret_cast<const std::byte*>(&v);
  out.insert(out.end(), p, p + sizeof(T));
}
template <class T>
T get(const std::byte* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

}  // namespace

std::uint32_t crc32c(std::span<const std::byte> data, std::uint32_t crc) {
  return cal::crc32c(data, crc);
}

// ---------------------------------------------------------------------------------------------

struct CaptureWriter::Impl {
  std::filesystem::path path;
  WriterLimits limits;
  std::FILE* file = nullptr;
  // The block being filled, after room for its 16-byte header so that a block goes to the OS
  // in one write (the file is unbuffered: `written` is then exact at every error).
  std::vector<std::byte> payload = std::vector<std::byte>(kBlockHeader);
  std::uint32_t records = 0;
  std::uint64_t total = 0;
  std::size_t peak = 0;
  std::uint64_t written = 0;  // bytes handed to the OS (or to stdio) without error
  std::string failure;        // the first write error; set, every later call refuses

  [[noreturn]] void fail(std::string_view what) {
    const int saved = errno;  // fmt and string building must not change the reported errno
    failure =
        fmt::format("{}: {} at byte {}: {}", path.string(), what, written, std::strerror(saved));
    throw CaptureError(failure);
  }
  void check_usable() const {
    if (!failure.empty())
      throw CaptureError(
          fmt::format("{} (nothing written since; the blocks before that byte "
                      "are intact)",
                      failure));
    if (!file) throw CaptureError(fmt::format("{}: write after close", path.string()));
  }
  void write(std::span<const std::byte> bytes) {
    if (limits.max_file_bytes > 0 && written + bytes.size() > limits.max_file_bytes) {
      errno = ENOSPC;
      fail("write failed");
    }
    if (std::fwrite(bytes.data(), 1, bytes.size(), file) != bytes.size()) fail("write failed");
    written += bytes.size();
  }
  std::size_t buffered() const { return payload.size() - kBlockHeader; }
  void write_block() {
    if (records == 0) return;
    std::vector<std::byte> head;
    put<std::uint32_t>(head, kBlockMagic);
    put<std::uint32_t>(head, static_cast<std::uint32_t>(buffered()));
    put<std::uint32_t>(head, records);
    // The CRC covers the length and count as well as the payload: a damaged count would
    // otherwise misalign every record after it.
    const auto body = std::span(payload).subspan(kBlockHeader);
    put<std::uint32_t>(head, crc32c(body, crc32c(std::span(head).subspan(4, 8))));
    std::copy(head.begin(), head.end(), payload.begin());
    write(payload);
    payload.resize(kBlockHeader);
    records = 0;
  }
  void flush_to_os() {
    if (std::fflush(file) != 0) fail("flush failed");
  }
};

CaptureWriter::CaptureWriter(const std::filesystem::path& path, std::string_view header_json,
                             WriterLimits limits)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->limits = limits;
  if (header_json.size() > kMaxHeader)
    throw CaptureError(fmt::format("{}: header of {} bytes is over the 1 MiB limit", path.string(),
                                   header_json.size()));
  if (limits.block_bytes > max_block_bytes)
    throw CaptureError(fmt::format("{}: block size {} bytes is over the {} byte limit",
                                   path.string(), limits.block_bytes, max_block_bytes));
  impl_->file = std::fopen(path.c_str(), "wb");
  if (!impl_->file)
    throw CaptureError(fmt::format("{}: cannot create: {}", path.string(), std::strerror(errno)));
  std::setvbuf(impl_->file, nullptr, _IONBF, 0);  // our blocks are the buffer
  std::vector<std::byte> head;
  for (char c : kMagic) head.push_back(static_cast<std::byte>(c));
  put<std::uint16_t>(head, capture_major_version);
  put<std::uint16_t>(head, capture_minor_version);
  put<std::uint32_t>(head, static_cast<std::uint32_t>(header_json.size()));
  const auto* json = reinterpret_cast<const std::byte*>(header_json.data());
  head.insert(head.end(), json, json + header_json.size());
  put<std::uint32_t>(head, crc32c(std::span(head).subspan(8)));
  impl_->payload.reserve(kBlockHeader + limits.block_bytes + 1024);
  try {
    impl_->write(head);
    impl_->flush_to_os();
  } catch (const CaptureError&) {
    std::fclose(std::exchange(impl_->file, nullptr));  // the destructor does not run
    throw;
  }
}

CaptureWriter::~CaptureWriter() {
  if (!impl_ || !impl_->file) return;
  try {
    close();
  } catch (const CaptureError&) {
    // the destructor cannot report; close() can
  }
}

void CaptureWriter::record(std::int64_t time_ns, std::uint16_t device, RecordKind kind,
                           std::span<const std::byte> bytes) {
  Impl& m = *impl_;
  m.check_usable();
  if (bytes.size() > max_record_bytes)
    throw CaptureError(fmt::format("{}: a record of {} bytes is over the {} byte limit",
                                   m.path.string(), bytes.size(), max_record_bytes));
  put<std::int64_t>(m.payload, time_ns);
  put<std::uint16_t>(m.payload, device);
  put<std::uint8_t>(m.payload, static_cast<std::uint8_t>(kind));
  put<std::uint8_t>(m.payload, 0);
  put<std::uint32_t>(m.payload, static_cast<std::uint32_t>(bytes.size()));
  m.payload.insert(m.payload.end(), bytes.begin(), bytes.end());
  ++m.records;
  ++m.total;
  m.peak = std::max(m.peak, m.buffered());
  if (m.buffered() >= m.limits.block_bytes) m.write_block();
}

void CaptureWriter::event(std::int64_t time_ns, std::uint16_t device, std::string_view text) {
  record(time_ns, device, RecordKind::event, std::as_bytes(std::span(text.data(), text.size())));
}

void CaptureWriter::flush() {
  impl_->check_usable();
  impl_->write_block();
  impl_->flush_to_os();
}

void CaptureWriter::close() {
  Impl& m = *impl_;
  if (!m.file) return;
  if (!m.failure.empty()) {
    // Close without writing: an end block after a failed write would claim a complete file.
    std::FILE* f = std::exchange(m.file, nullptr);
    std::fclose(f);
    m.check_usable();
  }
  try {
    m.write_block();
    // The end block: a capture without it was not closed (the session was interrupted),
    // which a cut exactly between two blocks could not otherwise show.
    std::vector<std::byte> end, count;
    put<std::uint64_t>(count, m.total);
    put<std::uint32_t>(end, kEndMagic);
    put<std::uint32_t>(end, 8);
    put<std::uint32_t>(end, 0);
    put<std::uint32_t>(end, crc32c(count));
    end.insert(end.end(), count.begin(), count.end());
    m.write(end);
    m.flush_to_os();
  } catch (const CaptureError&) {
    std::fclose(std::exchange(m.file, nullptr));
    throw;
  }
  std::FILE* f = std::exchange(m.file, nullptr);
  if (std::fclose(f) != 0) m.fail("close failed");
}

std::size_t CaptureWriter::buffered_bytes() const { return impl_->buffered(); }
std::size_t CaptureWriter::max_buffered_bytes() const { return impl_->peak; }
std::uint64_t CaptureWriter::bytes_written() const { return impl_->written; }
const std::filesystem::path& CaptureWriter::path() const { return impl_->path; }

// ---------------------------------------------------------------------------------------------

struct CaptureReader::Impl {
  std::filesystem::path path;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file{nullptr, &std::fclose};
  std::string header;
  std::uint16_t minor = 0;
  std::uint64_t offset = 0;  // of the next unread byte
  std::uint64_t block = 0;
  std::vector<std::byte> payload;
  std::size_t pos = 0;     // in payload
  std::uint32_t left = 0;  // records left in the block
  std::optional<Damage> damage;
  std::uint64_t records = 0;
  bool complete = false;
  std::uint64_t block_start = 0;

  std::size_t read(void* out, std::size_t n) {
    const std::size_t got = std::fread(out, 1, n, file.get());
    offset += got;
    return got;
  }
  // Bytes after the read position now (a file still being written may have grown).
  std::uint64_t bytes_left() const {
    struct stat st {};
    if (::fstat(::fileno(file.get()), &st) != 0) return UINT64_MAX;  // let the read tell
    const auto size = static_cast<std::uint64_t>(st.st_size);
    return size > offset ? size - offset : 0;
  }
  [[noreturn]] void bad_header(std::string_view what) const {
    throw CaptureError(fmt::format("{}: {}", path.string(), what));
  }
  template <class Damaged>
  bool end_block(const std::array<std::byte, kBlockHeader>& h, Damaged& damaged) {
    if (get<std::uint32_t>(h.data() + 4) != 8 || get<std::uint32_t>(h.data() + 8) != 0)
      return damaged("bad end block (length must be 8 and count 0)");
    std::array<std::byte, 8> count{};
    if (read(count.data(), 8) != 8) return damaged("truncated end block");
    if (get<std::uint32_t>(h.data() + 12) != crc32c(count))
      return damaged("bad CRC in the end block");
    if (get<std::uint64_t>(count.data()) != records)
      return damaged(fmt::format("the end block counts {} records, {} were read",
                                 get<std::uint64_t>(count.data()), records));
    complete = true;
    return false;
  }

  bool load_block() {
    if (complete) return false;
    const std::uint64_t at = offset;
    std::array<std::byte, kBlockHeader> h{};
    const std::size_t got = read(h.data(), h.size());
    auto damaged = [&](std::string what) {
      damage = Damage{at, block, std::move(what)};
      return false;
    };
    if (got == 0)
      return damaged(
          fmt::format("no end block: the capture was not closed (the session was "
                      "interrupted); {} records before it are intact",
                      records));
    if (got < h.size()) return damaged(fmt::format("truncated block header ({} of 16 bytes)", got));
    if (get<std::uint32_t>(h.data()) == kEndMagic) return end_block(h, damaged);
    if (get<std::uint32_t>(h.data()) != kBlockMagic)
      return damaged("not a block (bad block magic)");
    const auto size = get<std::uint32_t>(h.data() + 4);
    const auto count = get<std::uint32_t>(h.data() + 8);
    const auto crc = get<std::uint32_t>(h.data() + 12);
    if (size > kMaxPayload) return damaged(fmt::format("block length {} is implausible", size));
    // A length beyond the end of the file is a cut (or a damaged length): said without
    // allocating it, so a 30-byte file claiming a 64 MiB block costs nothing (found by
    // fuzz_capture).
    if (const std::uint64_t there = bytes_left(); size > there)
      return damaged(fmt::format("truncated block ({} of {} payload bytes)", there, size));
    payload.resize(size);
    if (const std::size_t n = read(payload.data(), size); n < size)
      return damaged(fmt::format("truncated block ({} of {} payload bytes)", n, size));
    if (crc32c(payload, crc32c(std::span(h).subspan(4, 8))) != crc)
      return damaged("bad CRC (the block is corrupted)");
    block_start = at;
    pos = 0;
    left = count;
    ++block;
    return true;
  }
};

CaptureReader::CaptureReader(const std::filesystem::path& path) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.file.reset(std::fopen(path.c_str(), "rb"));
  if (!m.file)
    throw CaptureError(fmt::format("{}: cannot open: {}", path.string(), std::strerror(errno)));
  std::array<char, 8> magic{};
  if (m.read(magic.data(), 8) != 8 || magic != kMagic)
    m.bad_header("not a caldaq capture file (no CALDAQCP magic at byte 0)");
  std::array<std::byte, 8> v{};
  if (const auto got = m.read(v.data(), 8); got != 8)
    m.bad_header(
        fmt::format("truncated header at byte {} (the version and length need 8 "
                    "bytes from byte 8)",
                    8 + got));
  const auto major = get<std::uint16_t>(v.data());
  m.minor = get<std::uint16_t>(v.data() + 2);
  const auto length = get<std::uint32_t>(v.data() + 4);
  if (major > capture_major_version || major == 0)
    m.bad_header(fmt::format("capture format version {}.{} (byte 8) is {} this daq reads ({}.x)",
                             major, m.minor, major == 0 ? "not one" : "newer than",
                             capture_major_version));
  if (length > kMaxHeader)
    m.bad_header(fmt::format("header length {} at byte 12 is over the 1 MiB limit", length));
  if (std::uint64_t{length} + 4 > m.bytes_left())  // said without allocating the length
    m.bad_header(fmt::format("truncated header at byte {} (the header ends at byte {})",
                             m.offset + m.bytes_left(), 20 + std::uint64_t{length}));
  m.header.resize(length);
  std::array<std::byte, 4> crc{};
  if (m.read(m.header.data(), length) != length || m.read(crc.data(), 4) != 4)
    m.bad_header(fmt::format("truncated header at byte {} (the header ends at byte {})", m.offset,
                             20 + std::uint64_t{length}));
  std::vector<std::byte> checked(v.begin(), v.end());
  const auto* h = reinterpret_cast<const std::byte*>(m.header.data());
  checked.insert(checked.end(), h, h + length);
  if (crc32c(checked) != get<std::uint32_t>(crc.data()))
    m.bad_header(fmt::format("header CRC mismatch at byte {} (damaged header)", 16 + length));
}

CaptureReader::~CaptureReader() = default;
CaptureReader::CaptureReader(CaptureReader&&) noexcept = default;
const std::string& CaptureReader::header_json() const { return impl_->header; }
std::uint16_t CaptureReader::minor_version() const { return impl_->minor; }
const std::optional<Damage>& CaptureReader::damage() const { return impl_->damage; }
const std::filesystem::path& CaptureReader::path() const { return impl_->path; }

std::string describe(const Damage& d) {
  return fmt::format("block {} at byte {}: {}", d.block, d.offset, d.what);
}
std::uint64_t CaptureReader::records_read() const { return impl_->records; }

std::optional<Record> CaptureReader::next() {
  const auto v = next_view();
  if (!v) return std::nullopt;
  return Record{v->time_ns, v->device, v->kind, {v->bytes.begin(), v->bytes.end()}};
}

std::optional<RecordView> CaptureReader::next_view() {
  Impl& m = *impl_;
  if (m.damage) return std::nullopt;
  while (m.left == 0)
    if (!m.load_block()) return std::nullopt;
  // Within a CRC-checked block a malformed record can only come from a writer bug; it is
  // still reported as damage rather than read past the end.
  if (m.payload.size() - m.pos < kRecordHeader) {
    m.damage = Damage{m.block_start, m.block - 1, "record header past the block end"};
    return std::nullopt;
  }
  const std::byte* p = m.payload.data() + m.pos;
  RecordView r;
  r.time_ns = get<std::int64_t>(p);
  r.device = get<std::uint16_t>(p + 8);
  r.kind = static_cast<RecordKind>(get<std::uint8_t>(p + 10));
  const auto length = get<std::uint32_t>(p + 12);
  if (m.payload.size() - m.pos - kRecordHeader < length) {
    m.damage = Damage{m.block_start, m.block - 1, "record longer than its block"};
    return std::nullopt;
  }
  r.bytes = std::span(p + kRecordHeader, length);
  m.pos += kRecordHeader + length;
  --m.left;
  ++m.records;
  return r;
}

// ---------------------------------------------------------------------------------------------

PacingClock system_pacing_clock() {
  return {[] {
            return std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::steady_clock::now().time_since_epoch())
                .count();
          },
          [](std::int64_t until_ns) {
            std::this_thread::sleep_until(
                std::chrono::steady_clock::time_point(std::chrono::nanoseconds(until_ns)));
          }};
}

ReplaySource::ReplaySource(const std::filesystem::path& path, double speed,
                           std::vector<std::uint16_t> devices, PacingClock clock)
    : reader_(path), speed_(speed), devices_(std::move(devices)), clock_(std::move(clock)) {
  if (!(speed >= 0) || !std::isfinite(speed))
    throw CaptureError(
        fmt::format("{}: replay speed {} must be finite and >= 0 (0: as fast as "
                    "possible)",
                    path.string(), speed));
}

const std::string& ReplaySource::header_json() const { return reader_.header_json(); }
const std::optional<Damage>& ReplaySource::damage() const { return reader_.damage(); }

std::optional<Record> ReplaySource::next() {
  for (;;) {
    auto r = reader_.next();
    if (!r) return r;
    if (!devices_.empty() &&
        std::find(devices_.begin(), devices_.end(), r->device) == devices_.end())
      continue;
    if (speed_ > 0) {
      if (!start_ns_) start_ns_ = clock_.now_ns(), first_record_ns_ = r->time_ns;
      const auto due =
          *start_ns_ +
          static_cast<std::int64_t>(static_cast<double>(r->time_ns - *first_record_ns_) / speed_);
      if (clock_.now_ns() < due) clock_.sleep_until(due);
    }
    return r;
  }
}

}  // namespace cal::replay
