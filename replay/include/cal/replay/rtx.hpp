#pragma once
// Reader of Renishaw dynamic-capture files (.rtx, written by CARTO Capture for the XL-80 and
// XM-60 at up to 50 kHz), so that a run measured with the vendor's software can be imported
// and analysed here. The layout, as the two public readers read it (github.com/TanmayPani/
// rtx2csv, rtx_to_csv.py; github.com/travdt/RTX2CSV-Converter, RTXFileProcessor.cs):
//
//   HEADER::\r\n
//   Owner: CARTO-Dynamic\r\n          one "Key: value" line per field (Version no,
//   File Type: Linear\r\n             File Type, Velocity, Sample rate, Sample no,
//   Sample rate: 50000\r\n            Trigger point, Trigger interval, Actual sample rate,
//   ...                               Flags, Machine, Serial No, Date, By, Axis, Location)
//   Data:\r\n
//   <float64 little-endian samples>
//   \r\nEOF::\r\n                      the end marker, where a next sample would start
//
// The end marker: RTX2CSV-Converter stops at the first 8-byte sample whose bytes start
// 0D 0A 45 4F 46 ("\r\nEOF"); rtx2csv strips a final "EOF::\r\n". Both are accepted when
// they start on a sample boundary within the last 24 bytes. Neither reader, nor any other
// public source found, states the unit of the samples or lists the File Type values; the
// importer takes the unit as an option and accepts the types "Linear" and "Angular" (any
// case), refusing every other type by name.
//
// The header's text: no public source states its encoding. UTF-8 (and so ASCII) is read as
// it is; any other byte is refused with the line and byte, unless the caller says the file
// was written in the Windows-1252 code page (CARTO runs on Windows, whose Western code page
// writes "By: Müller" as 4D FC 6C ...), in which case the header is converted to UTF-8.
// Control characters in a header line are refused (they would reach terminals and reports).
//
// Damage is reported, never hidden: a partial last sample or a missing end marker is noted
// in the header (trailing_bytes, eof_marker) and every complete sample before it is read.
// Nonsense in the header (a sample rate that is not finite or outside 0.001 Hz .. 10 MHz, a
// sample count that is not a whole number of at most 2^53) is refused.
#include <cstdint>
#include <filesystem>
#include <istream>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace cal::replay {

class RtxError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class RtxKind { linear, angular };

struct RtxHeader {
  std::vector<std::pair<std::string, std::string>> fields;  // in file order
  RtxKind kind = RtxKind::linear;                           // from "File Type"
  double sample_rate_hz = 0.0;                    // "Actual sample rate", else "Sample rate"
  std::optional<std::uint64_t> declared_samples;  // "Sample no"
  std::uint64_t data_offset = 0;                  // first byte of the samples
  std::uint64_t samples = 0;                      // complete samples in the file
  std::uint64_t trailing_bytes = 0;               // of a partial last sample (damage)
  bool eof_marker = false;                        // the file ends with the end marker
  std::uint64_t eof_offset = 0;                   // where the marker starts (if any)

  // The value of a field, or nullptr.
  const std::string* find(std::string_view key) const;
};

// How the header's bytes are read (see above).
enum class RtxHeaderEncoding { utf8, windows1252 };

// Limits of the header values (see above).
inline constexpr double rtx_min_rate_hz = 1e-3, rtx_max_rate_hz = 1e7;

class RtxReader {
 public:
  // Throws RtxError naming the file and the byte offset: not an .rtx header, no "Data:" line
  // within the first 64 KiB, no usable sample rate, a File Type that is missing or not
  // supported (named), nonsense header values (named, with the value).
  explicit RtxReader(const std::filesystem::path& path,
                     RtxHeaderEncoding encoding = RtxHeaderEncoding::utf8);
  // The same from bytes in memory (tests, fuzzing); `name` stands for the file in messages.
  RtxReader(std::string bytes, std::string name,
            RtxHeaderEncoding encoding = RtxHeaderEncoding::utf8);
  const RtxHeader& header() const { return header_; }
  // Reads up to out.size() samples in order; returns how many (0 at the end).
  std::size_t read(std::span<double> out);

 private:
  void read_header(std::uint64_t size);
  std::string header_text(std::string_view line, std::size_t line_number, std::size_t at) const;
  void find_end_marker(std::uint64_t size);
  std::string name_;
  RtxHeaderEncoding encoding_ = RtxHeaderEncoding::utf8;
  std::unique_ptr<std::istream> in_;
  RtxHeader header_;
  std::uint64_t next_ = 0;  // next sample index
};

}  // namespace cal::replay
