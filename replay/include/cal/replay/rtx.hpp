#pragma once
// Reader of Renishaw dynamic-capture files (.rtx, written by CARTO Capture for the XL-80 and
// XM-60 at up to 50 kHz), so that a run measured with the vendor's software can be imported
// and analysed here. The layout, as publicly described (github.com/TanmayPani/rtx2csv):
//
//   HEADER::\r\n
//   Owner: CARTO-Dynamic\r\n          one "Key: value" line per field (Version no,
//   Sample rate: 50000\r\n            File Type, Velocity, Sample rate, Sample no,
//   ...                               Trigger point, Trigger interval, Actual sample rate,
//   Data:\r\n                         Flags, Machine, Serial No, Date, By, Axis, Location)
//   <float64 little-endian samples>
//   EOF::\r\n
//
// The header does not state the unit of the samples; the importer takes it as an option.
// Damage is reported, never hidden: a partial last sample or a missing EOF marker is noted
// in the header (trailing_bytes, eof_marker) and every complete sample before it is read.
#include <cstdint>
#include <filesystem>
#include <fstream>
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

struct RtxHeader {
  std::vector<std::pair<std::string, std::string>> fields;  // in file order
  double sample_rate_hz = 0.0;                    // "Actual sample rate", else "Sample rate"
  std::optional<std::uint64_t> declared_samples;  // "Sample no"
  std::uint64_t data_offset = 0;                  // first byte of the samples
  std::uint64_t samples = 0;                      // complete samples in the file
  std::uint64_t trailing_bytes = 0;               // of a partial last sample (damage)
  bool eof_marker = false;                        // the file ends with "EOF::"

  // The value of a field, or nullptr.
  const std::string* find(std::string_view key) const;
};

class RtxReader {
 public:
  // Throws RtxError naming the file and the byte offset: not an .rtx header, no "Data:" line
  // within the first 64 KiB, no usable sample rate.
  explicit RtxReader(const std::filesystem::path& path);
  const RtxHeader& header() const { return header_; }
  // Reads up to out.size() samples in order; returns how many (0 at the end).
  std::size_t read(std::span<double> out);

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  RtxHeader header_;
  std::uint64_t next_ = 0;  // next sample index
};

}  // namespace cal::replay
