// LinuxCNC halsampler codec (see halsampler/codec.hpp).
#include "halsampler/codec.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <utility>

#include "cal/analysis/error.hpp"

namespace cal::drivers::codec {
HalsamplerCodec::HalsamplerCodec(HalsamplerConfig config)
    : config_(config), splitter_(config.max_line_bytes) {
  if (config_.metres_per_unit.multiplier == 0)
    throw InputError("halsampler: metres per unit must be > 0");
}

void HalsamplerCodec::do_feed(std::span<const std::byte> bytes, std::vector<PositionFrame>& frames,
                              std::vector<CodecError>& errors) {
  splitter_.feed(
      bytes, [&](std::string_view line, std::uint64_t off) { decode(line, off, frames, errors); },
      [&](std::uint64_t off) {
        report(errors, ErrorKind::overlong_line, off,
               fmt::format("halsampler: line longer than {} bytes", config_.max_line_bytes));
      });
}

void HalsamplerCodec::decode(std::string_view line, std::uint64_t offset,
                             std::vector<PositionFrame>& frames, std::vector<CodecError>& errors) {
  if (!is_printable_ascii(line))
    return report(errors, ErrorKind::garbage, offset, "halsampler: non-printable bytes");
  auto tokens = split_whitespace(line);
  if (tokens.size() == 1 && tokens.front() == "overrun") {  // samples lost before the next line
    pending_overrun_ = true;
    return;
  }
  PositionFrame f;
  if (config_.sample_numbers) {
    const auto n = tokens.empty() ? std::nullopt : parse_integer<std::uint64_t>(tokens.front());
    if (!n)
      return report(
          errors, ErrorKind::malformed, offset,
          fmt::format("halsampler: '{}' does not start with a sample number", line.substr(0, 40)));
    f.sample = *n;
    // Numbers skipped by halsampler are lost samples, carried to the next frame emitted even
    // when this line turns out malformed (that one is counted as a codec error instead).
    if (last_sample_ && *n > *last_sample_ + 1) pending_lost_ += *n - *last_sample_ - 1;
    last_sample_ = *n;
    tokens.erase(tokens.begin());
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const int col = config_.column[axis];
    if (col < 0) continue;
    if (static_cast<std::size_t>(col) >= tokens.size())
      return report(errors, ErrorKind::malformed, offset,
                    fmt::format("halsampler: {} values, column {} expected", tokens.size(), col));
    const auto v =
        parse_number_scaled(tokens[static_cast<std::size_t>(col)], config_.metres_per_unit);
    if (!v || !std::isfinite(*v))
      return report(errors, ErrorKind::malformed, offset,
                    fmt::format("halsampler: column {} '{}' is not a number", col,
                                tokens[static_cast<std::size_t>(col)]));
    f.position_m[axis] = *v;
  }
  f.lost_before = std::exchange(pending_lost_, 0);
  f.overrun = std::exchange(pending_overrun_, false);
  emit(frames, std::move(f));
}

}  // namespace cal::drivers::codec
