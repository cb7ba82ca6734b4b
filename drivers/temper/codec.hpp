#pragma once
// PCsensor TEMPer USB-HID thermometers: 8-byte input reports, as publicly reverse-engineered
// (OpenBSD's ugold(4) driver, sys/dev/usb/ugold.c, is the reference used here; the Python
// temper.py of urwen/temper agrees). The host writes 8-byte output reports:
//   01 80 33 01 00 00 00 00   read the sensors     -> answer 80 ...
//   01 82 77 01 00 00 00 00   init: sensor count    -> answer 82 NN ...
//   01 86 ff 01 00 00 00 00   model string          -> answers in ASCII, e.g. "TEMPerGold_V3.1 "
// Data answers differ by family:
//   ds75  (TEMPer1F/TEMPer2F/TEMPerF1, 0c45:7401): 80 LL t1h t1l t2h t2l .. ; LL = 2 (one
//         sensor) or 4 (two); each value a DS75 12-bit two's complement, 1/16 degC per count
//         in the top 12 bits: T = int16(h<<8 | l) / 256 with the low 4 bits zero.
//   gold  (TEMPerGold_V3.x, TEMPer1F_V4.1, TEMPer2_V4.1; 413d:2107, 1a86:e025): 80 SS th tl ..;
//         SS = 0x80 inner sensor, 0x01 outer (probe); T = int16(th<<8 | tl) / 100 degC;
//         200.00 degC means "probe missing".
//   temperx (TEMPerX_V3.x, TEMPerHUM_V3.9+): 80 SS th tl hh hl ..; SS in {04, 20, 40, 80}
//         (inner); T as gold, RH = (hh<<8 | hl) / 100 %RH.
// Reports may arrive split at any byte (the codec reassembles 8-byte reports).
#include <optional>
#include <string>

#include "cal/drivers/codec/common.hpp"

namespace cal::drivers::codec {

enum class TemperFamily { ds75, gold, temperx };
TemperFamily temper_family_from_string(std::string_view s);  // ds75 | gold | temperx
// The family a model string (the answer to the 0x86 command) belongs to; nullopt if unknown.
std::optional<TemperFamily> temper_family_of_model(std::string_view model);

struct TemperConfig {
  TemperFamily family = TemperFamily::gold;
  double min_degc = -40.0, max_degc = 125.0;  // plausible range; outside: out_of_range
};

struct TemperFrame {
  int sensor = 0;  // 0 inner (in the stick), 1 outer (the probe on a cable)
  double temperature_degc = 0.0;
  std::optional<double> humidity_pct;  // temperx only
};

class TemperCodec : public CodecBase<TemperCodec, TemperFrame> {
 public:
  static constexpr std::size_t report_bytes = 8;
  explicit TemperCodec(TemperConfig config = {}) : config_(config) {}
  void do_feed(std::span<const std::byte> bytes, std::vector<TemperFrame>& frames,
               std::vector<CodecError>& errors);
  // The model string received so far (printable ASCII of non-data reports).
  const std::string& model() const { return model_; }
  // The sensor count from the last init answer (0x82), 0 before one.
  int sensor_count() const { return sensor_count_; }

  // The 8-byte output reports, each prefixed with hidapi's report ID 0x00.
  static std::string read_command();
  static std::string init_command();
  static std::string model_command();

 private:
  void on_report(const std::uint8_t* r, std::vector<TemperFrame>& frames,
                 std::vector<CodecError>& errors);
  void emit_temperature(int sensor, double t_degc, std::optional<double> rh,
                        std::vector<TemperFrame>& frames, std::vector<CodecError>& errors);

  TemperConfig config_;
  std::uint8_t buf_[report_bytes] = {};
  std::size_t have_ = 0;
  std::uint64_t offset_ = 0;  // stream offset of buf_[0]
  std::string model_;
  int sensor_count_ = 0;
};

}  // namespace cal::drivers::codec
