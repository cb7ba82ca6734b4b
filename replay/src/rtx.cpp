// Renishaw .rtx reader (see rtx.hpp).
#include "cal/replay/rtx.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "cal/analysis/text.hpp"

namespace cal::replay {
namespace {

constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
constexpr std::string_view kMarker = "\r\nEOF";     // RTX2CSV-Converter's check
constexpr std::string_view kBareMarker = "EOF::";   // rtx2csv's "EOF::\r\n" stub
constexpr std::string_view kFullMarker = "\r\nEOF::\r\n";  // as CARTO writes it
constexpr std::uint64_t kMarkerSearch = 24;         // the marker starts this close to the end
constexpr double kMaxSamples = 9007199254740992.0;  // 2^53: every count exact in a double

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// A header value for messages: printable, at most 60 characters.
std::string shown(std::string_view s) {
  std::string out;
  for (unsigned char c : s.substr(0, 60)) out += std::isprint(c) ? static_cast<char>(c) : '?';
  return out;
}

std::optional<double> number(const std::string* s) {
  if (!s) return std::nullopt;
  double v = 0;
  const auto t = trim(*s);
  const auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec != std::errc{} || p != t.data() + t.size() || t.empty()) return std::nullopt;
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

RtxReader::RtxReader(const std::filesystem::path& path, RtxHeaderEncoding encoding)
    : name_(path.string()), encoding_(encoding) {
  auto file = std::make_unique<std::ifstream>(path, std::ios::binary);
  if (!*file) throw RtxError(fmt::format("{}: cannot open", name_));
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw RtxError(fmt::format("{}: {}", name_, ec.message()));
  in_ = std::move(file);
  read_header(size);
}

RtxReader::RtxReader(std::string bytes, std::string name, RtxHeaderEncoding encoding)
    : name_(std::move(name)), encoding_(encoding) {
  const std::uint64_t size = bytes.size();
  in_ = std::make_unique<std::istringstream>(std::move(bytes));
  read_header(size);
}

void RtxReader::read_header(std::uint64_t size) {
  const std::string& file = name_;
  std::string head(std::min<std::uint64_t>(size, kMaxHeaderBytes), '\0');
  in_->read(head.data(), static_cast<std::streamsize>(head.size()));
  if (!head.starts_with("HEADER::"))
    throw RtxError(fmt::format("{}: byte 0: not a Renishaw .rtx file (no HEADER:: line)", file));
  // "Key: value" lines up to the "Data:" line; CR-LF as written, a bare LF accepted.
  std::size_t pos = head.find('\n');
  bool data_found = false;
  std::size_t line_number = 1;  // "HEADER::"
  while (pos != std::string::npos && pos + 1 < head.size()) {
    const std::size_t start = pos + 1, eol = head.find('\n', start);
    if (eol == std::string::npos) break;
    const std::string text =
        header_text(trim(std::string_view(head).substr(start, eol - start)), ++line_number, start);
    const std::string_view line = text;
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
                                 shown(line)));
    header_.fields.emplace_back(std::string(trim(line.substr(0, colon))),
                                std::string(trim(line.substr(colon + 1))));
  }
  if (!data_found)
    throw RtxError(
        fmt::format("{}: no 'Data:' line within the first {} bytes (a truncated "
                    "header?)",
                    file, head.size()));

  // The file type decides what the samples are; only the two known ones are read.
  const std::string* type = header_.find("File Type");
  if (!type || trim(*type).empty())
    throw RtxError(fmt::format(
        "{}: header: no 'File Type' (linear or angular): the samples cannot be interpreted", file));
  const std::string t = lower(trim(*type));
  if (t == "linear")
    header_.kind = RtxKind::linear;
  else if (t == "angular")
    header_.kind = RtxKind::angular;
  else
    throw RtxError(fmt::format(
        "{}: header: File Type '{}' is not supported (only Linear and Angular captures are "
        "imported)",
        file, shown(*type)));

  // The rate: the actual one, else the nominal; 0 or empty counts as not stated, anything
  // else must be a finite rate in range (an infinite or 1e-300 Hz rate would put every
  // sample at time 0 or beyond the clock).
  auto rate_field = [&](const char* key) -> std::optional<double> {
    const std::string* text = header_.find(key);
    if (!text || trim(*text).empty()) return std::nullopt;
    const auto v = number(text);
    if (v && *v == 0) return std::nullopt;
    if (!v || !(*v >= rtx_min_rate_hz && *v <= rtx_max_rate_hz))
      throw RtxError(fmt::format("{}: header: {} '{}' is not a rate within {} .. {} Hz", file, key,
                                 shown(*text), rtx_min_rate_hz, rtx_max_rate_hz));
    return v;
  };
  auto rate = rate_field("Actual sample rate");
  if (!rate) rate = rate_field("Sample rate");
  if (!rate)
    throw RtxError(
        fmt::format("{}: header: no usable 'Actual sample rate' or 'Sample rate'", file));
  header_.sample_rate_hz = *rate;
  if (const std::string* n = header_.find("Sample no"); n && !trim(*n).empty()) {
    const auto v = number(n);
    if (!v || !(*v >= 0 && *v <= kMaxSamples) || *v != std::floor(*v))
      throw RtxError(
          fmt::format("{}: header: Sample no '{}' is not a whole number of samples "
                      "(0 .. 2^53)",
                      file, shown(*n)));
    header_.declared_samples = static_cast<std::uint64_t>(*v);
  }

  find_end_marker(size);
  if (static_cast<double>(header_.samples) / header_.sample_rate_hz > 9e9)
    throw RtxError(fmt::format("{}: {} samples at {} Hz last longer than the clock can count", file,
                               header_.samples, header_.sample_rate_hz));
  in_->clear();
  in_->seekg(static_cast<std::streamoff>(header_.data_offset));
}

// A header line as UTF-8 (see rtx.hpp): checked, or converted from Windows-1252.
std::string RtxReader::header_text(std::string_view line, std::size_t line_number,
                                   std::size_t at) const {
  std::string out(line);
  if (const auto bad = text::invalid_utf8_at(line)) {
    if (encoding_ != RtxHeaderEncoding::windows1252)
      throw RtxError(fmt::format(
          "{}: line {}, byte {}: the header is not UTF-8 text (byte 0x{:02X}); if the file was "
          "written on a Western Windows, give --header-encoding windows-1252",
          name_, line_number, at + *bad, static_cast<unsigned char>(line[*bad])));
    out = text::windows1252_to_utf8(line);
  }
  for (std::size_t i = 0; i < line.size(); ++i) {
    const auto c = static_cast<unsigned char>(line[i]);
    if ((c < 0x20 && c != '\t') || c == 0x7F)
      throw RtxError(
          fmt::format("{}: line {}, byte {}: a control character (0x{:02X}) in the "
                      "header",
                      name_, line_number, at + i, c));
  }
  return out;
}

// The end marker starts near the end of the file: on a sample boundary, or (a damaged last
// sample) anywhere if it runs to the end, so that it is never read as a sample (its bytes
// "\r\nEOF::\r" are 4.95e27 as a double).
void RtxReader::find_end_marker(std::uint64_t size) {
  std::uint64_t end = size;
  if (size > header_.data_offset) {
    const std::uint64_t from = size > kMarkerSearch ? size - kMarkerSearch : 0;
    std::string tail(size - std::max(from, header_.data_offset), '\0');
    const std::uint64_t tail_at = size - tail.size();
    in_->clear();
    in_->seekg(static_cast<std::streamoff>(tail_at));
    in_->read(tail.data(), static_cast<std::streamsize>(tail.size()));
    const auto marker_at = [&](bool aligned) -> std::optional<std::uint64_t> {
      for (std::uint64_t at = tail_at; at < size; ++at) {
        const auto rest = std::string_view(tail).substr(at - tail_at);
        if (aligned ? (at - header_.data_offset) % 8 == 0 &&
                          (rest.starts_with(kMarker) || rest.starts_with(kBareMarker))
                    : rest.starts_with(kMarker) && kFullMarker.starts_with(rest))
          return at;
      }
      return std::nullopt;
    };
    auto at = marker_at(true);
    if (!at) at = marker_at(false);
    if (at) {
      header_.eof_marker = true;
      header_.eof_offset = *at;
      end = *at;
    }
  }
  const std::uint64_t data_bytes = end - std::min(end, header_.data_offset);
  header_.samples = data_bytes / 8;
  header_.trailing_bytes = data_bytes % 8;
}

std::size_t RtxReader::read(std::span<double> out) {
  const auto n =
      static_cast<std::size_t>(std::min<std::uint64_t>(out.size(), header_.samples - next_));
  if (n == 0) return 0;
  std::vector<char> buf(n * 8);
  in_->read(buf.data(), static_cast<std::streamsize>(buf.size()));
  if (static_cast<std::size_t>(in_->gcount()) != buf.size())
    throw RtxError(fmt::format("{}: byte {}: read error", name_, header_.data_offset + next_ * 8));
  for (std::size_t i = 0; i < n; ++i) out[i] = from_le(buf.data() + 8 * i);
  next_ += n;
  return n;
}

}  // namespace cal::replay
