#pragma once
// MTConnect SHDR, a machine position feed for the position-assisted trigger.
//
// MTConnect SHDR, as an adapter sends it to the agent (TCP, port 7878 by default):
// "2024-01-01T12:00:00.123456Z|Xact|123.4567|Yact|-5.0000", a timestamp then key|value pairs;
// "UNAVAILABLE" when the control has no value; "* PING" from the agent, answered by the adapter
// with "* PONG <timeout ms>"; multi-line values between "--multiline--TAG" markers. Keys and
// columns are configuration: every control names its data items differently.
#include <map>
#include <optional>
#include <string>

#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/codec/position.hpp"

namespace cal::drivers::codec {

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
