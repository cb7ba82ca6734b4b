// PCsensor TEMPer codec (see temper/codec.hpp).
#include "temper/codec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

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

namespace {

constexpr std::pair<std::string_view, TemperFamily> kFamilies[] = {
    {"ds75", TemperFamily::ds75},       {"gold", TemperFamily::gold},
    {"temperx", TemperFamily::temperx}, {"sht2x", TemperFamily::sht2x},
    {"si7005", TemperFamily::si7005},   {"si7006", TemperFamily::si7006}};

// The models the public projects document (docs/drivers.md has the table with its sources),
// one per line (firmware prefix, family, inner, probe, humidity, ds75 slots, source). Each
// prefix is as long as its source compares (urwen/temper compares firmware[:N] for a fixed N;
// ugold.c compares the whole 16 bytes): a firmware no source names is refused, never guessed.
// OpenBSD's ugold.c also reads any "TEMPer1F*", "TEMPer2F*" or "TEMPerF1*" as DS75, but only on
// Microdia 0c45:7401 and with the sensors found by the report's length; the codec does not know
// the USB id, and the probe's slot differs between the TEMPer1F models that are documented
// (first value on TEMPer1F1.1, second on TEMPer1F_V1.3), so those catch-alls are not applied:
// an undocumented model there is read only with an explicit `family` (docs/drivers.md).
// clang-format off
constexpr TemperModel kModels[] = {
    // DS75 family, 0c45:7401 (Microdia).
    {"TEMPerF1.2", TemperFamily::ds75, true, false, false, {0, -1}, "urwen/temper (TEMPerF1.2: one inner sensor, /256)"},
    {"TEMPerF1.4", TemperFamily::ds75, true, false, false, {0, -1}, "urwen/temper (TEMPerF1.4: one inner sensor, /256)"},
    {"TEMPer1F1.", TemperFamily::ds75, false, true, false, {1, -1}, "urwen/temper README (TEMPer1F1.1Per1F: external sensor only, first value)"},
    {"TEMPer1F_V1.3", TemperFamily::ds75, false, true, false, {-1, 1}, "padelt/temper-python 1.5.1 (TEMPer1F_V1.3: one sensor, at offset 4)"},
    {"TEMPer2_M12_V1.3", TemperFamily::ds75, true, true, false, {0, 1}, "urwen/temper (/256 at offsets 2 and 4, 1a86:e025)"},
    // Gold family: a report per sensor, 80 inner, 01 probe, /100.
    {"TEMPerGold_V3.1", TemperFamily::gold, true, false, false, {0, 1}, "OpenBSD ugold.c, urwen/temper"},
    {"TEMPerGold_V3.3", TemperFamily::gold, true, false, false, {0, 1}, "urwen/temper"},
    {"TEMPerGold_V3.4", TemperFamily::gold, true, false, false, {0, 1}, "OpenBSD ugold.c, urwen/temper"},
    {"TEMPerGold_V3.5", TemperFamily::gold, true, false, false, {0, 1}, "OpenBSD ugold.c, ccwienk/temper (3553:a001)"},
    {"TEMPer2_V3.7", TemperFamily::gold, true, true, false, {0, 1}, "urwen/temper (inner at offset 2, probe at 10: the second report)"},
    {"TEMPer2_V3.9", TemperFamily::gold, true, true, false, {0, 1}, "urwen/temper"},
    {"TEMPer2_V4.1", TemperFamily::gold, true, true, false, {0, 1}, "OpenBSD ugold.c, ccwienk/temper (3553:a001)"},
    {"TEMPer1F_V3.9", TemperFamily::gold, false, true, false, {0, 1}, "ccwienk/temper (TEMPer1F_V3.9: the probe only, 1a86:e025)"},
    {"TEMPer1F_V4.1", TemperFamily::gold, false, true, false, {0, 1}, "OpenBSD ugold.c (TEMPer1F lacks the inner sensor), ccwienk/temper"},
    // TEMPerX family: the stick's temperature and humidity.
    {"TEMPerX_V3.1", TemperFamily::temperx, true, false, true, {0, 1}, "OpenBSD ugold.c, urwen/temper"},
    {"TEMPerX_V3.3", TemperFamily::temperx, true, true, true, {0, 1}, "OpenBSD ugold.c, urwen/temper; the probe (id 01) from urwen/temper PR #16's usbmon trace of a TEMPer1F"},
    {"TEMPerHUM_V3.8", TemperFamily::temperx, true, false, true, {0, 1}, "ccwienk/temper PR #45, urwen/temper #29 and #34 (as TEMPerHUM_V3.9)"},
    {"TEMPerHUM_V3.9", TemperFamily::temperx, true, false, true, {0, 1}, "OpenBSD ugold.c, urwen/temper"},
    {"TEMPerHUM_V4.0", TemperFamily::temperx, true, false, true, {0, 1}, "OpenBSD ugold.c"},
    {"TEMPerHUM_V4.1", TemperFamily::temperx, true, false, true, {0, 1}, "OpenBSD ugold.c"},
    // Sensirion and Silicon Labs sensors.
    {"TEMPer1F_H1V1.5F", TemperFamily::sht2x, true, false, true, {0, 1}, "urwen/temper (SHT2x equations; OpenBSD ugold reads it otherwise, see docs/drivers.md)"},
    {"TEMPerHumM12V1.0", TemperFamily::si7005, true, false, true, {0, 1}, "OpenBSD ugold.c"},
    {"TEMPerHumM12V1.2", TemperFamily::si7006, true, false, true, {0, 1}, "OpenBSD ugold.c"},
};
// clang-format on

}  // namespace

TemperFamily temper_family_from_string(std::string_view s) {
  for (const auto& [name, f] : kFamilies)
    if (name == s) return f;
  throw InputError(
      fmt::format("TEMPer family '{}' (expected ds75, gold, temperx, sht2x, si7005 or si7006)", s));
}

std::string_view to_string(TemperFamily f) {
  for (const auto& [name, family] : kFamilies)
    if (family == f) return name;
  return "unknown";
}

std::span<const TemperModel> temper_models() { return kModels; }

const TemperModel* temper_model_of(std::string_view firmware) {
  const TemperModel* best = nullptr;
  for (const auto& m : kModels)
    if (firmware.starts_with(m.firmware) && (!best || m.firmware.size() > best->firmware.size()))
      best = &m;
  return best;
}

std::optional<TemperFamily> temper_family_of_model(std::string_view m) {
  if (const auto* model = temper_model_of(m)) return model->family;
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

// A DS75's temperature register holds 12 bits left-aligned: "the four least significant bits
// ... are always 0" (Maxim DS75 data sheet, temperature register format). A register with any of
// them set did not come from the sensor: ff ff is what a TEMPer1F_V1.3 sends when its probe does
// not answer (edorfaus/TEMPered#32), which masking the nibble used to read as -0.0625 degC.
void TemperCodec::emit_ds75(int sensor, const std::uint8_t* reg, std::vector<TemperFrame>& frames,
                            std::vector<CodecError>& errors) {
  const auto raw = static_cast<std::uint16_t>(reg[0] << 8 | reg[1]);
  if (raw == 0xffff)
    return report(errors, ErrorKind::out_of_range, offset_,
                  fmt::format("sensor {}: ff ff: the sensor did not answer (probe unplugged or "
                              "broken); no temperature",
                              sensor));
  if ((raw & 0xf) != 0)
    return report(errors, ErrorKind::malformed, offset_,
                  fmt::format("sensor {}: register {:02x} {:02x} cannot come from a DS75 (its "
                              "low 4 bits are always 0); no temperature",
                              sensor, reg[0], reg[1]));
  emit_temperature(sensor, be16(reg) / 256.0, std::nullopt, frames, errors);
}

// A TEMPerX_V3.3 firmware also runs sticks with a probe (TEMPer1F, TEMPer2): urwen/temper PR
// #16's usbmon trace of a TEMPer1F shows 80 01 08 dc 4e 20, the probe at 22.68 degC with 4e 20
// (200.00, the value urwen/temper's _parse_bytes skips as "no value") where a stick reports
// humidity. The probe measures no humidity, so those two bytes are never read as one.
void TemperCodec::emit_temperx_probe(const std::uint8_t* r, std::vector<TemperFrame>& frames,
                                     std::vector<CodecError>& errors) {
  if (!config_.probe)
    return report(errors, ErrorKind::malformed, offset_,
                  "temperx sensor id 01 (the probe): the model has no probe");
  emit_temperature(1, be16(r + 2) / 100.0, std::nullopt, frames, errors);
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
    ++model_reports_;
    return;
  }
  const bool inner_id = r[1] == 0x04 || r[1] == 0x20 || r[1] == 0x40 || r[1] == 0x80;
  const std::uint16_t t_raw = static_cast<std::uint16_t>(r[2] << 8 | r[3]);
  const std::uint16_t h_raw = static_cast<std::uint16_t>(r[4] << 8 | r[5]);
  switch (config_.family) {
    case TemperFamily::ds75:
      if (r[1] != 2 && r[1] != 4)
        return report(errors, ErrorKind::malformed, offset_,
                      fmt::format("ds75 data length {} (expected 2 or 4)", r[1]));
      for (int slot = 0; slot < (r[1] == 4 ? 2 : 1); ++slot)
        if (const int channel = config_.ds75_slots[static_cast<std::size_t>(slot)]; channel >= 0)
          emit_ds75(channel, r + 2 + 2 * slot, frames, errors);
      return;
    case TemperFamily::gold: {
      if (r[1] != 0x80 && r[1] != 0x01)
        return report(errors, ErrorKind::malformed, offset_,
                      fmt::format("gold sensor id {:02x} (expected 80 or 01)", r[1]));
      const int sensor = r[1] == 0x80 ? 0 : 1;
      if (!(sensor == 0 ? config_.inner : config_.probe))
        return report(errors, ErrorKind::malformed, offset_,
                      fmt::format("gold sensor id {:02x}: the model has no {} sensor", r[1],
                                  sensor == 0 ? "inner" : "probe"));
      return emit_temperature(sensor, be16(r + 2) / 100.0, std::nullopt, frames, errors);
    }
    default:
      break;
  }
  if (config_.family == TemperFamily::temperx && r[1] == 0x01)
    return emit_temperx_probe(r, frames, errors);
  if (!inner_id)  // temperx (but its probe), sht2x, si700x: the stick's sensor only
    return report(errors, ErrorKind::malformed, offset_,
                  fmt::format("{} sensor id {:02x} (expected 04, 20, 40 or 80)",
                              to_string(config_.family), r[1]));
  switch (config_.family) {
    case TemperFamily::temperx:
      return emit_temperature(0, be16(r + 2) / 100.0, h_raw / 100.0, frames, errors);
    case TemperFamily::sht2x:  // urwen/temper: the counts shifted back, then Sensirion's equations
      return emit_temperature(0, -46.85 + 175.72 * (be16(r + 2) * 4.0) / 65536.0,
                              -6.0 + 125.0 * (be16(r + 4) * 16.0) / 65536.0, frames, errors);
    case TemperFamily::si7005:  // ugold: 14 bits, 32 per degC from -50; 12 bits, 16 per %RH
      return emit_temperature(0, (t_raw & 0x3fff) / 32.0 - 50.0,
                              std::clamp((h_raw & 0x0fff) / 16.0 - 24.0, 0.0, 100.0), frames,
                              errors);
    case TemperFamily::si7006:  // ugold: status bits cleared, Silicon Labs' equations
      return emit_temperature(0, (t_raw & ~3) * 175.72 / 65536.0 - 46.85,
                              std::clamp((h_raw & ~3) * 125.0 / 65536.0 - 6.0, 0.0, 100.0), frames,
                              errors);
    default:
      return;
  }
}

}  // namespace cal::drivers::codec
