#pragma once
// PCsensor TEMPer USB-HID thermometers: 8-byte input reports, as publicly reverse-engineered.
// Sources: OpenBSD's ugold(4) driver (sys/dev/usb/ugold.c, rev. 1.29), urwen/temper's temper.py
// and its README's device table, ccwienk/temper (the maintained fork of urwen/temper, its
// supported-devices table), padelt/temper-python (TEMPer1F_V1.3). The host writes 8-byte output
// reports:
//   01 80 33 01 00 00 00 00   read the sensors     -> answer 80 ...
//   01 82 77 01 00 00 00 00   init: sensor count    -> answer 82 NN ...
//   01 86 ff 01 00 00 00 00   firmware string       -> two reports of ASCII, e.g. "TEMPerGold_V3.5
//   "
// The firmware string names the model, and the model the layout (family) and the sensors: see
// temper_models() below and docs/drivers.md. Data answers by family:
//   ds75  : 80 LL aH aL bH bL ..; LL = 2 (one value) or 4 (two); each a DS75 12-bit two's
//           complement, T = int16(h<<8 | l) / 256 with the low 4 bits ignored. Which sensor
//           each value is depends on the model (TEMPer1F_V1.3 has only the second, its probe).
//   gold  : 80 SS th tl ..; SS = 0x80 inner sensor, 0x01 outer (probe), a report per sensor;
//           T = int16(th<<8 | tl) / 100 degC; 200.00 degC means "probe missing".
//   temperx: 80 SS th tl hh hl ..; SS in {04, 20, 40, 80} (inner); T as gold, RH = (hh hl)/100;
//           SS = 01: the probe of a TEMPer1F/TEMPer2 on TEMPerX firmware, hh hl the 4e 20 filler.
//   sht2x : 80 SS th tl hh hl ..; Sensirion SHT2x equations on the raw counts (urwen/temper):
//           T = -46.85 + 175.72 * 4 t / 65536, RH = -6 + 125 * 16 h / 65536.
//   si7005, si7006: as OpenBSD's ugold (Silicon Labs equations), SS as temperx.
// Reports may arrive split at any byte (the codec reassembles 8-byte reports).
#include <array>
#include <optional>
#include <span>
#include <string>

#include "cal/drivers/codec/common.hpp"

namespace cal::drivers::codec {

enum class TemperFamily { ds75, gold, temperx, sht2x, si7005, si7006 };
// ds75 | gold | temperx | sht2x | si7005 | si7006; throws cal::InputError otherwise.
TemperFamily temper_family_from_string(std::string_view s);
std::string_view to_string(TemperFamily f);

// A model as the public projects document it: the start of its firmware string, its report
// family and its sensors. Channel 0 is the sensor in the stick (inner), 1 the probe on a cable.
struct TemperModel {
  std::string_view firmware;  // the firmware string starts with this
  TemperFamily family;
  bool inner = true;      // has the sensor in the stick
  bool probe = false;     // has the probe on a cable
  bool humidity = false;  // reports the stick's humidity
  // ds75 only: the channel of the first and the second value of a report (-1: not a sensor).
  std::array<int, 2> ds75_slots{0, 1};
  std::string_view source;  // the public project(s) that document it
};
// The detection table (longest matching prefix wins).
std::span<const TemperModel> temper_models();
// The model of a firmware string, or nullptr (unknown: refused, never guessed).
const TemperModel* temper_model_of(std::string_view firmware);
// The family a firmware string belongs to; nullopt if unknown.
std::optional<TemperFamily> temper_family_of_model(std::string_view model);

struct TemperConfig {
  TemperFamily family = TemperFamily::gold;
  double min_degc = -40.0, max_degc = 125.0;  // plausible range; outside: out_of_range
  // The sensors the model has (from the detection table): a report of a sensor it does not have
  // is malformed, never a phantom reading.
  bool inner = true, probe = true;
  std::array<int, 2> ds75_slots{0, 1};  // ds75: the channels of a report's two values
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
  // Changes the layout (the firmware said which); the stream and the counts go on.
  void configure(const TemperConfig& config) { config_ = config; }
  const TemperConfig& config() const { return config_; }
  // The model string received so far (printable ASCII of non-data reports), and how many
  // reports it came in (the firmware answer is two).
  const std::string& model() const { return model_; }
  int model_reports() const { return model_reports_; }
  // Forgets the model string received so far (the firmware query is being asked again).
  void reset_model() {
    model_.clear();
    model_reports_ = 0;
  }
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
  void emit_temperx_probe(const std::uint8_t* r, std::vector<TemperFrame>& frames,
                          std::vector<CodecError>& errors);
  void emit_ds75(int sensor, const std::uint8_t* reg, std::vector<TemperFrame>& frames,
                 std::vector<CodecError>& errors);

  TemperConfig config_;
  std::uint8_t buf_[report_bytes] = {};
  std::size_t have_ = 0;
  std::uint64_t offset_ = 0;  // stream offset of buf_[0]
  std::string model_;
  int model_reports_ = 0;
  int sensor_count_ = 0;
};

}  // namespace cal::drivers::codec
