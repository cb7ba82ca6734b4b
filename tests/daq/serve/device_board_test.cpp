// The device board of the operator's page (serve/device_board.hpp) on a hand-driven clock: the
// state shown for each sequence of instrument events, values only while fresh, and the
// environment from a published refractive index.
#include "serve/device_board.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>

namespace {

using cal::drivers::InstrumentState;
using cal::drivers::Quantity;
using cal::drivers::Reading;
using cal::drivers::ReadingStatus;
using daq::serve::DeviceBoard;
using namespace std::chrono_literals;

// Every fixture's laser and air station, and its environment.
constexpr std::string_view kLaserAndAir = R"(
[devices.laser]
driver = "ids3010"
transport = "tcp 127.0.0.1:9090"
role = "laser"
[devices.air]
driver = "ptu300"
transport = "serial /dev/ttyUSB0 4800 7E1"
role = "air"
)";
constexpr std::string_view kEnvironment = R"(
[environment]
wavelength_nm = 633
co2_umol_per_mol = 450
expansion_ppm_per_k = 11.5
)";

cal::daq::Config config() {
  return cal::daq::parse_config(fmt::format("{}{}{}", kLaserAndAir, R"(
[devices.table]
driver = "gauge"
transport = "serial /dev/ttyUSB1 9600 8N1"
unit = "degC"
role = "material"
[devices.bar]
driver = "gauge"
transport = "serial /dev/ttyUSB2 115200 8N1"
role = "ballbar"
)",
                                            kEnvironment),
                                "board.toml");
}

struct Board {
  DeviceBoard::Clock::time_point t{};
  cal::daq::Config c = config();
  DeviceBoard board{c, [this] { return t; }};
  void stream(const std::string& id, std::chrono::milliseconds period) {
    board.expect(id, period, 20);
    board.on_state(id, InstrumentState::connecting, "");
    board.on_state(id, InstrumentState::configuring, "");
    board.on_state(id, InstrumentState::streaming, "");
  }
  void read(const std::string& id, Quantity q, double v, ReadingStatus s = ReadingStatus::ok) {
    board.on_reading(id, Reading{.quantity = q, .status = s, .value = v});
  }
  nlohmann::json device(const std::string& id) const {
    const auto all = board.to_json();
    for (const auto& d : all["devices"])
      if (d["id"] == id) return d;
    return {};
  }
};

TEST(DeviceBoard, StreamingDeviceShowsItsValuesUntilItFallsSilent) {
  Board b;
  b.stream("laser", 100ms);
  b.read("laser", Quantity::displacement_m, 0.125);
  auto d = b.device("laser");
  EXPECT_EQ(d["state"], "streaming");
  EXPECT_DOUBLE_EQ(d["values"]["displacement_m"].get<double>(), 0.125);
  EXPECT_DOUBLE_EQ(d["valid_pct"].get<double>(), 100.0);
  // Silent: no reading for longer than max(2 s, 3 periods) = 2 s.
  b.t += 2000ms;
  EXPECT_EQ(b.device("laser")["state"], "streaming");
  b.t += 1ms;
  d = b.device("laser");
  EXPECT_EQ(d["state"], "silent");
  EXPECT_TRUE(d["values"].empty()) << "a silent device shows no value, not its last one";
  EXPECT_EQ(d["reason"], "no reading for 2.0 s");
  EXPECT_TRUE(d["valid_pct"].is_null());
}

// A device that stays streaming while a reading is flagged (an indicator out of its range):
// its last valid value is not the current one any more, and is not shown as if it were; the next
// valid reading is. The card names the instrument's product and serial number, not only its
// driver's key.
TEST(DeviceBoard, AFlaggedReadingHidesTheLastValidValue) {
  Board b;
  b.stream("bar", 100ms);
  b.read("bar", Quantity::length_m, 0.002);
  EXPECT_DOUBLE_EQ(b.device("bar")["values"]["length_m"].get<double>(), 0.002);
  b.t += 100ms;
  b.read("bar", Quantity::length_m, 0.5, ReadingStatus::out_of_range);
  auto d = b.device("bar");
  EXPECT_EQ(d["state"], "streaming");
  EXPECT_TRUE(d["values"].empty()) << "the value 0.002 m, 100 ms old, shown as current";
  EXPECT_DOUBLE_EQ(d["valid_pct"].get<double>(), 50.0);
  b.t += 100ms;
  b.read("bar", Quantity::length_m, 0.003);
  EXPECT_DOUBLE_EQ(b.device("bar")["values"]["length_m"].get<double>(), 0.003);
  EXPECT_EQ(b.device("laser")["product"], "IDS3010");
  EXPECT_EQ(b.device("bar")["product"], "") << "a gauge reads whatever it is wired to";
}

TEST(DeviceBoard, ReconnectingCountsTheAttemptsOfItsLimit) {
  Board b;
  b.board.expect("air", 1000ms, 20);
  for (int i = 0; i < 3; ++i) {
    b.board.on_state("air", InstrumentState::connecting, "");
    b.board.on_state("air", InstrumentState::reconnecting,
                     "serial /dev/ttyUSB0 4800 7E1: cannot open: No such file or directory");
  }
  const auto d = b.device("air");
  EXPECT_EQ(d["state"], "reconnecting");
  EXPECT_EQ(d["attempt"], 3);
  EXPECT_EQ(d["max_attempts"], 20);
  // The loader reads the devices in the order of their names: air comes first; every device
  // that is not ready is named (laser and table have not been opened in this fixture).
  const auto why = b.board.refusal("linear");
  ASSERT_TRUE(why);
  EXPECT_EQ(*why,
            "not ready: air (serial /dev/ttyUSB0 4800 7E1) is reconnecting (attempt 3 of 20): "
            "serial /dev/ttyUSB0 4800 7E1: cannot open: No such file or directory; "
            "laser (tcp 127.0.0.1:9090) is closed; table (serial /dev/ttyUSB1 9600 8N1) is closed");
  // A reading resets the count (as the instrument's own back-off does).
  b.stream("air", 1000ms);
  b.read("air", Quantity::air_pressure_pa, 100000);
  EXPECT_EQ(b.device("air")["attempt"], 0);
  EXPECT_EQ(*b.board.refusal("linear"),
            "not ready: laser (tcp 127.0.0.1:9090) is closed; "
            "table (serial /dev/ttyUSB1 9600 8N1) is closed");
}

// A straightness run reads its indicator: Start must wait for it as for the laser. (Before,
// only the laser, air, material and position feed were asked: a run started with its
// indicator's port held by another program, captured every stop with the laser and waited for
// indicator values that never came.) A rotary run's stops come from its angular reference:
// the laser and the position feed are not its devices.
cal::daq::Config with_kind(std::string_view kind) {
  return cal::daq::parse_config(
      fmt::format(R"({}
[devices.indicator]
driver = "gauge"
transport = "serial /dev/ttyUSB3 9600 8N1"
role = "indicator"
[devices.table]
driver = "gauge"
transport = "serial /dev/ttyUSB4 9600 8N1"
unit = "arcsec"
role = "angle"
{}
[trigger]
tolerance_um = 1
dwell_s = 1.5
window_mm = 0.5
[test.linear]
axis = "{}"
first_mm = 0
last_mm = {}
interval_mm = {}
runs = 1
feed_mm_per_min = 1000
dwell_s = 4
measure = "{}"
{}
)",
                  kLaserAndAir, kEnvironment, kind == "rotary" ? "C" : "X",
                  kind == "rotary" ? 360 : 200, kind == "rotary" ? 90 : 100, kind,
                  kind == "rotary" ? "" : "direction = \"Y\""),
      "kinds.toml");
}

// A device streaming with a fresh reading (the board's clock stands still).
void live(DeviceBoard& board, const std::string& id, Quantity q) {
  board.expect(id, 1000ms, 20);
  board.on_state(id, InstrumentState::streaming, "");
  board.on_reading(id, Reading{.quantity = q, .status = ReadingStatus::ok, .value = 0.001});
}

TEST(DeviceBoard, StartWaitsForTheInstrumentTheKindReads) {
  const auto c = with_kind("straightness");
  DeviceBoard board(c, [] { return DeviceBoard::Clock::time_point{}; });
  live(board, "laser", Quantity::displacement_m);
  live(board, "air", Quantity::air_pressure_pa);
  board.expect("indicator", 1000ms, 20);
  board.on_state("indicator", InstrumentState::connecting, "");
  board.on_state("indicator", InstrumentState::reconnecting, "busy: pid 7 (flock)");
  const auto why = board.refusal("linear");
  ASSERT_TRUE(why);
  EXPECT_EQ(*why,
            "not ready: indicator (serial /dev/ttyUSB3 9600 8N1) is reconnecting (attempt 1 of "
            "20): busy: pid 7 (flock)");
  const auto device = [&c](std::string_view id) {
    return *std::find_if(c.devices.begin(), c.devices.end(),
                         [id](const auto& d) { return d.id == id; });
  };
  EXPECT_TRUE(daq::serve::run_uses(c, "linear", device("indicator")));
  EXPECT_FALSE(daq::serve::run_uses(c, "linear", device("table")));  // the angle: not this kind's
  EXPECT_FALSE(daq::serve::run_uses(c, "circle", device("indicator")));
  live(board, "indicator", Quantity::length_m);
  EXPECT_EQ(board.refusal("linear"), std::nullopt);
}

TEST(DeviceBoard, ARotaryRunDoesNotWaitForTheLaser) {
  const auto c = with_kind("rotary");
  DeviceBoard board(c, [] { return DeviceBoard::Clock::time_point{}; });
  live(board, "air", Quantity::air_pressure_pa);
  live(board, "table", Quantity::angle_rad);
  EXPECT_EQ(board.refusal("linear"), std::nullopt);  // the laser closed, the indicator too
  board.expect("table", 1000ms, 20);
  board.on_state("table", InstrumentState::reconnecting, "gone");
  ASSERT_TRUE(board.refusal("linear"));
  EXPECT_NE(board.refusal("linear")->find("table (serial /dev/ttyUSB4"), std::string::npos);
}

TEST(DeviceBoard, GivenUpIsFailedStoppedIsClosed) {
  Board b;
  b.stream("table", 1000ms);
  b.board.on_state("table", InstrumentState::closed, "stopped");
  EXPECT_EQ(b.device("table")["state"], "closed");
  b.board.on_state("table", InstrumentState::closed, "gave up after 20 attempts: timeout");
  EXPECT_EQ(b.device("table")["state"], "failed");
  b.board.on_failed("bar", "devices.bar.transport 'x': expected serial DEVICE BAUD FRAME");
  EXPECT_EQ(b.device("bar")["state"], "failed");
  EXPECT_EQ(*b.board.refusal("circle"),
            "not ready: bar (serial /dev/ttyUSB2 115200 8N1) is failed: devices.bar.transport "
            "'x': expected serial DEVICE BAUD FRAME");
}

TEST(DeviceBoard, SignalLostReadingsLowerTheValidShare) {
  Board b;
  b.stream("laser", 100ms);
  for (int i = 0; i < 4; ++i) b.read("laser", Quantity::displacement_m, 0.1);
  b.board.on_state("laser", InstrumentState::signal_lost, "");
  for (int i = 0; i < 4; ++i)
    b.read("laser", Quantity::displacement_m, 0, ReadingStatus::signal_lost);
  const auto d = b.device("laser");
  EXPECT_EQ(d["state"], "signal lost");
  EXPECT_DOUBLE_EQ(d["valid_pct"].get<double>(), 50.0);  // 4 valid of 8
  EXPECT_TRUE(d["values"].empty()) << "no value while the signal is lost";
  EXPECT_NE(b.board.refusal("linear"), std::nullopt);
}

TEST(DeviceBoard, TheBallbarNeedsOnlyToBeReachable) {
  Board b;
  b.board.expect("bar", 1000ms, -1);
  b.board.on_state("bar", InstrumentState::connecting, "");
  b.board.on_state("bar", InstrumentState::configuring, "");
  EXPECT_EQ(b.device("bar")["state"], "open");
  EXPECT_EQ(b.board.refusal("circle"), std::nullopt);
  b.board.on_state("bar", InstrumentState::reconnecting, "cannot open: No such device");
  EXPECT_NE(b.board.refusal("circle"), std::nullopt);
}

TEST(DeviceBoard, TheEnvironmentFromFreshValuesOnly) {
  Board b;
  b.stream("air", 1000ms);
  b.stream("table", 1000ms);
  b.read("air", Quantity::air_temperature_degc, 20.0);
  b.read("air", Quantity::air_pressure_pa, 100000.0);
  b.read("air", Quantity::air_humidity_pct, 0.0);
  auto env = b.board.to_json()["environment"];
  // No material reading yet: n is known, the factor uses the fallback material (20 degC).
  // Ciddor (1996), Table 1: dry air, 20 degC, 100 kPa, 633 nm, 450 umol/mol: (n - 1) 1e8 =
  // 26824.4; the factor at 20 degC is 1/n - 1 = -268.172 ppm.
  EXPECT_NEAR((env["n"].get<double>() - 1) * 1e8, 26824.4, 0.06);
  EXPECT_NEAR(env["factor_ppm"].get<double>(), -268.172, 0.001);
  EXPECT_TRUE(env["material_fallback"].get<bool>());
  // The table at 21 degC with 11.5 ppm/K: 1 / (n (1 + 11.5e-6)) - 1 = -279.669 ppm.
  b.read("table", Quantity::material_temperature_degc, 21.0);
  env = b.board.to_json()["environment"];
  EXPECT_DOUBLE_EQ(env["material_degc"].get<double>(), 21.0);
  EXPECT_NEAR(env["factor_ppm"].get<double>(), -279.669, 0.001);
  // The air station falls silent: no air, no n, no factor (never the last ones).
  b.t += 3001ms;
  b.read("table", Quantity::material_temperature_degc, 21.0);
  env = b.board.to_json()["environment"];
  EXPECT_TRUE(env["air_temperature_degc"].is_null());
  EXPECT_TRUE(env["n"].is_null());
  EXPECT_TRUE(env["factor_ppm"].is_null());
  EXPECT_DOUBLE_EQ(env["material_degc"].get<double>(), 21.0);
}

}  // namespace
