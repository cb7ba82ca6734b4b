// PCsensor TEMPer codec (see codec/temper.hpp).
#include "temper/codec.hpp"

#include <fmt/format.h>

#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::drivers::codec {
namespace {

constexpr std::uint8_t kData = 0x80, kInit = 0x82;

std::int16_t be16(const std::uint8_t* p) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(p[0] << 8 | p[1]));
}

std::string command(std::uint8_t a, std::uint8_t b) {
  const char bytes[] = {0x00, 0x01, static_cast<char>(a), static_cast<char>(b), 0x01, 0, 0, 0, 0};
  return std::string(bytes, sizeof bytes);
}

}  // namespace

TemperFamily temper_family_from_string(std::string_view s) {
  if (s == "ds75") return TemperFamily::ds75;
  if (s == "gold") return TemperFamily::gold;
  if (s == "temperx") return TemperFamily::temperx;
  throw InputError(fmt::format("TEMPer family '{}' (expected ds75, gold or temperx)", s));
}

std::optional<TemperFamily> temper_family_of_model(std::string_view m) {
  if (m.starts_with("TEMPer1F_V4") || m.starts_with("TEMPer2_V4") || m.starts_with("TEMPerGold_"))
    return TemperFamily::gold;
  if (m.starts_with("TEMPerX_") || m.starts_with("TEMPerHUM_")) return TemperFamily::temperx;
  if (m.starts_with("TEMPer1F") || m.starts_with("TEMPer2F") || m.starts_with("TEMPerF1"))
    return TemperFamily::ds75;
  return std::nullopt;
}

std::string TemperCodec::read_command() { return command(0x80, 0x33); }
std::string TemperCodec::init_command() { return command(0x82, 0x77); }
std::string TemperCodec::model_command() { return command(0x86, 0xff); }

void TemperCodec::do_feed(std::span<const std::byte> bytes, std::vector<TemperFrame>& frames,
                          std::vector<CodecError>& errors) {
  for (std::byte b : bytes) {
    buf_[have_++] = static_cast<std::uint8_t>(b);
    if (have_ < report_bytes) continue;
    on_report(buf_, frames, errors);
    have_ = 0;
    offset_ += report_bytes;
  }
}

void TemperCodec::emit_temperature(int sensor, double t, std::optional<double> rh,
                                   std::vector<TemperFrame>& frames,
                                   std::vector<CodecError>& errors) {
  if (!(t >= config_.min_degc && t <= config_.max_degc)) {
    const bool probe_missing = config_.family != TemperFamily::ds75 && t == 200.0;
    return report(errors, ErrorKind::out_of_range, offset_,
                  probe_missing ? fmt::format("sensor {}: 200 degC: the probe is missing", sensor)
                                : fmt::format("sensor {}: {:.2f} degC outside [{}, {}]", sensor, t,
                                              config_.min_degc, config_.max_degc));
  }
  if (rh && !(*rh >= 0.0 && *rh <= 100.0))
    return report(errors, ErrorKind::out_of_range, offset_,
                  fmt::format("humidity {:.2f} %RH outside [0, 100]", *rh));
  emit(frames, {.sensor = sensor, .temperature_degc = t, .humidity_pct = rh});
}

void TemperCodec::on_report(const std::uint8_t* r, std::vector<TemperFrame>& frames,
                            std::vector<CodecError>& errors) {
  if (r[0] == kInit) {
    sensor_count_ = r[1];
    return;
  }
  if (r[0] != kData) {  // a piece of the model string, or garbage
    for (std::size_t i = 0; i < report_bytes; ++i)
      if (r[i] != 0 && (r[i] < 0x20 || r[i] > 0x7e))
        return report(
            errors, ErrorKind::garbage, offset_,
            fmt::format("report starting {:02x} {:02x}: neither data nor model text", r[0], r[1]));
    for (std::size_t i = 0; i < report_bytes && r[i] != 0; ++i)
      if (model_.size() < 64) model_.push_back(static_cast<char>(r[i]));
    return;
  }
  switch (config_.family) {
    case TemperFamily::ds75:
      if (r[1] != 2 && r[1] != 4)
        return report(errors, ErrorKind::malformed, offset_,
                      fmt::format("ds75 data length {} (expected 2 or 4)", r[1]));
      emit_temperature(0, (be16(r + 2) & ~0xf) / 256.0, std::nullopt, frames, errors);
      if (r[1] == 4)
        emit_temperature(1, (be16(r + 4) & ~0xf) / 256.0, std::nullopt, frames, errors);
      return;
    case TemperFamily::gold:
      if (r[1] != 0x80 && r[1] != 0x01)
        return report(errors, ErrorKind::malformed, offset_,
                      fmt::format("gold sensor id {:02x} (expected 80 or 01)", r[1]));
      return emit_temperature(r[1] == 0x80 ? 0 : 1, be16(r + 2) / 100.0, std::nullopt, frames,
                              errors);
    case TemperFamily::temperx:
      if (r[1] != 0x04 && r[1] != 0x20 && r[1] != 0x40 && r[1] != 0x80)
        return report(errors, ErrorKind::malformed, offset_,
                      fmt::format("temperx sensor id {:02x} (expected 04, 20, 40 or 80)", r[1]));
      return emit_temperature(0, be16(r + 2) / 100.0, (r[4] << 8 | r[5]) / 100.0, frames, errors);
  }
}

}  // namespace cal::drivers::codec
