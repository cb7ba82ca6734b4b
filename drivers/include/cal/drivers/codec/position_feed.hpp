#pragma once
// Machine position feeds for the position-assisted trigger: the positions the control reports
// (actual or commanded), as text lines.
//
// LinuxCNC halsampler (`halsampler [-t] [-c CHAN]`, fed by a sampler component whose pins are
// e.g. joint.0.pos-fb, joint.1.pos-fb): one line per sample, the sample number first (unless
// -t), then the value of each pin, separated by spaces: "1234 12.500000 -3.250000 0.000000".
// Samples the realtime side could not hand over make halsampler skip sample numbers; the codec
// reports how many were lost before each line.
//
// MTConnect SHDR, as an adapter sends it to the agent (TCP, port 7878 by default):
// "2024-01-01T12:00:00.123456Z|Xact|123.4567|Yact|-5.0000", a timestamp then key|value pairs;
// "UNAVAILABLE" when the control has no value; "* PING" from the agent, answered by the adapter
// with "* PONG <timeout ms>"; multi-line values between "--multiline--TAG" markers. Keys and
// columns are configuration: every control names its data items differently.
#include <array>
#include <map>
#include <optional>
#include <string>

#include "cal/drivers/codec/common.hpp"

namespace cal::drivers::codec {

struct PositionFrame {
  std::array<std::optional<double>, 3> position_m;  // X, Y, Z: those the line carried
  std::optional<std::uint64_t> sample;              // halsampler's sample number
  std::uint64_t lost_before = 0;                    // samples skipped before this one
  std::optional<std::int64_t> time_unix_ns;         // SHDR's timestamp (UTC)
};

struct HalsamplerConfig {
  bool sample_numbers = true;          // false for halsampler -t
  std::array<int, 3> column{0, 1, 2};  // value column of X, Y, Z (0-based, after the number); -1
  double metres_per_unit = 1e-3;       // machine units: mm (1e-3) or inch (0.0254)
  std::size_t max_line_bytes = 1024;
};

class HalsamplerCodec : public CodecBase<HalsamplerCodec, PositionFrame> {
 public:
  explicit HalsamplerCodec(HalsamplerConfig config = {});
  void do_feed(std::span<const std::byte> bytes, std::vector<PositionFrame>& frames,
               std::vector<CodecError>& errors);

 private:
  void decode(std::string_view line, std::uint64_t offset, std::vector<PositionFrame>& frames,
              std::vector<CodecError>& errors);
  HalsamplerConfig config_;
  LineSplitter splitter_;
  std::optional<std::uint64_t> last_sample_;
  std::uint64_t pending_lost_ = 0;
};

struct ShdrConfig {
  // Data item key -> axis (0 X, 1 Y, 2 Z), e.g. {"Xact", 0}, {"Yact", 1}, {"Zact", 2}.
  std::map<std::string, int, std::less<>> keys{{"Xact", 0}, {"Yact", 1}, {"Zact", 2}};
  double metres_per_unit = 1e-3;  // MTConnect positions are in millimetres
  double max_abs_m = 100.0;       // plausibility: beyond it, out_of_range
  std::size_t max_line_bytes = 8192;
};

class ShdrCodec : public CodecBase<ShdrCodec, PositionFrame> {
 public:
  explicit ShdrCodec(ShdrConfig config = {});
  void do_feed(std::span<const std::byte> bytes, std::vector<PositionFrame>& frames,
               std::vector<CodecError>& errors);
  std::uint64_t pings() const { return pings_; }  // "* PING" seen (the instrument answers)
  std::uint64_t pongs() const { return pongs_; }
  std::optional<std::int64_t> pong_timeout_ms() const { return pong_timeout_ms_; }

  static std::string ping() { return "* PING\n"; }

 private:
  void decode(std::string_view line, std::uint64_t offset, std::vector<PositionFrame>& frames,
              std::vector<CodecError>& errors);
  void heartbeat(std::string_view line);
  ShdrConfig config_;
  LineSplitter splitter_;
  std::string multiline_tag_;  // inside a multi-line value until this marker comes back
  std::uint64_t pings_ = 0, pongs_ = 0;
  std::optional<std::int64_t> pong_timeout_ms_;
};

// "2024-01-01T12:00:00.123456Z" (fraction optional, Z optional) as Unix ns; nullopt if not.
std::optional<std::int64_t> parse_iso8601_utc_ns(std::string_view s);

}  // namespace cal::drivers::codec
