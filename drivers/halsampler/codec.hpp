#pragma once
// A machine position feed for the position-assisted trigger.
//
// LinuxCNC halsampler (`halsampler [-t] [-c CHAN]`, fed by a sampler component whose pins are
// e.g. joint.0.pos-fb, joint.1.pos-fb): one line per sample, the value of each pin followed by a
// space ("%f " for floats, "0 "/"1 " for bits). Only with -t does the line start with the
// sample number: the default is untagged, and then column 0 is a pin, never a number to skip
// (a bit pin there reads 0 or 1). When it falls behind the realtime side, halsampler prints a
// line "overrun" (the samples in between are lost; with -t the sample numbers jump by as many).
// Source: LinuxCNC src/hal/components/sampler_usr.c (`if (tag) printf("%d ", ...)`,
// `printf("overrun\n")`); checked on the five recordings of ../shared/realdata.
#include <array>
#include <optional>

#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/codec/position.hpp"

namespace cal::drivers::codec {

struct HalsamplerConfig {
  bool sample_numbers = false;         // true for halsampler -t (the sample number first)
  std::array<int, 3> column{0, 1, 2};  // value column of X, Y, Z (0-based, after the number); -1
  // Machine units to metres, exact: mm (kMillimetresToMetres) or inch (kInchesToMetres). A
  // printed "%f" position is stored as its decimal in metres, correctly rounded.
  DecimalScale metres_per_unit = kMillimetresToMetres;
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
  bool pending_overrun_ = false;
};

}  // namespace cal::drivers::codec
