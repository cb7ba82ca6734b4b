// Renishaw .rtx reader (see rtx.hpp).
#include "cal/replay/rtx.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>

namespace cal::replay {
namespace {

constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
constexpr std::string_view kEofMarker = "EOF::\r\n";

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::optional<double> number(const std::string* s) {
  if (!s) return std::nullopt;
  double v = 0;
  const auto t = trim(*s);
  const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec != std::errc{} || p != t.data() + t.size()) return std::nullopt;
  return v;
}

double from_le(const char* bytes) {
  std::uint64_t u = 0;
  std::memcpy(&u, bytes, 8);
  if constexpr (std::endian::native == std::endian::big) u = __builtin_bswap64(u);
  return std::bit_cast<double>(u);
}

}  // namespace

const std::string* RtxHeader::find(std::string_view key) const {
  for (const auto& [k, v] : fields)
    if (k == key) return &v;
  return nullptr;
}

RtxReader::RtxReader(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {
  const std::string file = path.string();
  if (!in_) throw RtxError(fmt::format("{}: cannot open", file));
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw RtxError(fmt::format("{}: {}", file, ec.message()));
  std::string head(std::min<std::uint64_t>(size, kMaxHeaderBytes), '\0');
  in_.read(head.data(), static_cast<std::streamsize>(head.size()));
  if (!head.starts_with("HEADER::"))
    throw RtxError(fmt::format("{}: byte 0: not a Renishaw .rtx file (no HEADER:: line)", file));
  // "Key: value" lines up to the "Data:" line; CR-LF as written, a bare LF accepted.
  std::size_t pos = head.find('\n');
  bool data_found = false;
  while (pos != std::string::npos && pos + 1 < head.size()) {
    const std::size_t start = pos + 1, eol = head.find('\n', start);
    if (eol == std::string::npos) break;
    const auto line = trim(std::string_view(head).substr(start, eol - start));
    pos = eol;
    if (line == "Data:") {
      header_.data_offset = eol + 1;
      data_found = true;
      break;
    }
    if (line.empty() || line.ends_with("::")) continue;  // a section line
    const auto colon = line.find(':');
    if (colon == std::string_view::npos)
      throw RtxError(fmt::format("{}: byte {}: header line '{}' is not 'Key: value'", file, start,
                                 std::string(line.substr(0, 60))));
    header_.fields.emplace_back(std::string(trim(line.substr(0, colon))),
                                std::string(trim(line.substr(colon + 1))));
  }
  if (!data_found)
    throw RtxError(
        fmt::format("{}: no 'Data:' line within the first {} bytes (a truncated "
                    "header?)",
                    file, head.size()));
  auto rate = number(header_.find("Actual sample rate"));
  if (!rate || !(*rate > 0)) rate = number(header_.find("Sample rate"));
  if (!rate || !(*rate > 0))
    throw RtxError(
        fmt::format("{}: header: no usable 'Actual sample rate' or 'Sample rate'", file));
  header_.sample_rate_hz = *rate;
  if (const auto n = number(header_.find("Sample no")); n && *n >= 0)
    header_.declared_samples = static_cast<std::uint64_t>(*n);
  std::uint64_t end = size;
  if (size >= header_.data_offset + kEofMarker.size()) {
    std::string tail(kEofMarker.size(), '\0');
    in_.seekg(static_cast<std::streamoff>(size - kEofMarker.size()));
    in_.read(tail.data(), static_cast<std::streamsize>(tail.size()));
    if (tail == kEofMarker) header_.eof_marker = true, end -= kEofMarker.size();
  }
  const std::uint64_t data_bytes = end - header_.data_offset;
  header_.samples = data_bytes / 8;
  header_.trailing_bytes = data_bytes % 8;
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(header_.data_offset));
}

std::size_t RtxReader::read(std::span<double> out) {
  const auto n =
      static_cast<std::size_t>(std::min<std::uint64_t>(out.size(), header_.samples - next_));
  if (n == 0) return 0;
  std::vector<char> buf(n * 8);
  in_.read(buf.data(), static_cast<std::streamsize>(buf.size()));
  if (static_cast<std::size_t>(in_.gcount()) != buf.size())
    throw RtxError(
        fmt::format("{}: byte {}: read error", path_.string(), header_.data_offset + next_ * 8));
  for (std::size_t i = 0; i < n; ++i) out[i] = from_le(buf.data() + 8 * i);
  next_ += n;
  return n;
}

}  // namespace cal::replay
