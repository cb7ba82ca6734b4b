#pragma once
// A machine position feed for the position-assisted trigger.
//
// LinuxCNC halsampler (`halsampler [-t] [-c CHAN]`, fed by a sampler component whose pins are
// e.g. joint.0.pos-fb, joint.1.pos-fb): one line per sample, the sample number first (unless
// -t), then the value of each pin, separated by spaces: "1234 12.500000 -3.250000 0.000000".
// Samples the realtime side could not hand over make halsampler skip sample numbers; the codec
// reports how many were lost before each line.
#include <array>
#include <optional>

#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/codec/position.hpp"

namespace cal::drivers::codec {

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

}  // namespace cal::drivers::codec
