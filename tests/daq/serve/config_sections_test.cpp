// The configuration's plain sections declared once (cal/daq/config_fields.hpp, issue 19): the
// TOML loader, the capture header and the operator's set-up form all go through the same field
// tables. Each test below fails if one of them drops, renames or stops checking a key.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <variant>

#include "cal/analysis/error.hpp"
#include "cal/daq/config.hpp"
#include "cal/daq/config_fields.hpp"
#include "serve/setup_form.hpp"
#include "session_spec.hpp"

namespace {

namespace fd = cal::daq::fields;
using nlohmann::json;

// Every key of every table away from its default (values written here by hand).
constexpr const char* kEveryKey = R"([environment]
equation = "edlen"
stale_after_s = 20
on_stale = "fallback"
fallback_temperature_degc = 21
fallback_pressure_pa = 99000
fallback_humidity_pct = 40
fallback_material_degc = 20.5
co2_umol_per_mol = 420
wavelength_nm = 633.0
expansion_ppm_per_k = 11.8
[trigger]
tolerance_um = 2.5
dwell_s = 1.1
window_mm = 0.4
[test.linear]
axis = "Y"
first_mm = -20
last_mm = 480
interval_mm = 50
random_fraction = 0.25
cycle = "pendulum"
runs = 4
bidirectional = false
overrun_mm = 4
feed_mm_per_min = 3000
dwell_s = 3.5
dead_path_mm = 12
standard = "vdi3441"
measure = "straightness"
direction = "Z"
stationary_mm = [100, 0, 50]
probe_offset_mm = [0, 0, -120]
beams = [2, 0]
separation_mm = [0, 10, 0]
sign = -1
square = true
[test.circle]
radius_mm = 150
feed_mm_per_min = 500
sample_rate_hz = 250
overshoot_deg = 30
centre_mm = [1, 2, 3]
standard = "iso230-4:1996"
planes = ["ZX", "YZ"]
feeds_mm_per_min = [500, 2000]
radii_mm = [100, 150]
partial_arc_deg = 200
partial_overshoot_deg = 5
feed_in_mm = 2
dwell_s = 0.5
bar = "QC20-1234"
)";

// Whether each field of `table` holds something other than its default in `s`; the keys
// that do not are returned (an empty list: every key came through).
template <class S>
std::vector<std::string> at_default(const S& s, std::span<const fd::Field<S>> table) {
  static const S defaults{};
  std::vector<std::string> keys;
  for (const auto& f : table)
    std::visit(
        [&](auto member) {
          if (s.*member == defaults.*member) keys.emplace_back(f.key);
        },
        f.member);
  return keys;
}

cal::daq::Config through_header(const cal::daq::Config& c) {
  const json header = json::parse(daq::capture_header(c, {}, "test"));
  return daq::config_from_json(header.at("config"));
}

TEST(ConfigSections, TheExampleSetsEveryKeyOfEveryTable) {
  // The premise of the tests below: kEveryKey moves every key off its default (a key added to a
  // table must be added here too). calibrated_radius_mm is left at 0 (not given): with
  // several radii the loader refuses it, and it is checked on its own below.
  const auto c = cal::daq::parse_config(kEveryKey, "every.toml");
  EXPECT_TRUE(at_default(c.environment, fd::environment()).empty());
  EXPECT_TRUE(at_default(c.trigger, fd::trigger()).empty());
  EXPECT_EQ(at_default(*c.linear, fd::linear()), (std::vector<std::string>{"count"}));
  // reference is a rotary test's key (the example is a straightness test: it is refused there).
  EXPECT_EQ(at_default(c.linear->measure, fd::measure()), (std::vector<std::string>{"reference"}));
  EXPECT_EQ(at_default(*c.circle, fd::circle()),
            (std::vector<std::string>{"plane", "calibrated_radius_mm"}));
}

TEST(ConfigSections, EveryKeySurvivesTheCaptureHeader) {
  const auto back = through_header(cal::daq::parse_config(kEveryKey, "every.toml"));
  EXPECT_TRUE(at_default(back.environment, fd::environment()).empty());
  EXPECT_TRUE(at_default(back.trigger, fd::trigger()).empty());
  ASSERT_TRUE(back.linear && back.circle);
  EXPECT_EQ(at_default(*back.linear, fd::linear()), (std::vector<std::string>{"count"}));
  EXPECT_EQ(at_default(back.linear->measure, fd::measure()),
            (std::vector<std::string>{"reference"}));
  // Spot checks against the file's text.
  EXPECT_EQ(back.environment.on_stale, cal::daq::StalePolicy::fallback);
  EXPECT_DOUBLE_EQ(back.environment.fallback_pressure_pa, 99000);
  EXPECT_EQ(back.linear->measure.kind, "straightness");
  EXPECT_EQ(back.linear->measure.beams, (std::array<int, 2>{2, 0}));
  EXPECT_EQ(back.linear->measure.probe_offset_mm, (std::array<double, 3>{0, 0, -120}));
  EXPECT_EQ(back.circle->planes, (std::vector<std::string>{"ZX", "YZ"}));
  EXPECT_EQ(back.circle->radii_mm, (std::vector<double>{100, 150}));
  EXPECT_EQ(back.circle->bar, "QC20-1234");
  // The optional keys: absent stays absent, present comes back.
  EXPECT_FALSE(back.linear->count);
  EXPECT_DOUBLE_EQ(*back.linear->interval_mm, 50);
  EXPECT_DOUBLE_EQ(through_header(cal::daq::parse_config(
                                      "[test.circle]\ncalibrated_radius_mm = 150.0012\n", "c.toml"))
                       .circle->calibrated_radius_mm,
                   150.0012);
}

std::string header_error(const std::string& section, const json& patch) {
  json header =
      json::parse(daq::capture_header(cal::daq::parse_config(kEveryKey, "every.toml"), {}, "test"));
  header["config"][section].update(patch);
  try {
    daq::config_from_json(header.at("config"));
  } catch (const cal::InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ConfigSections, ADamagedHeaderIsRefusedWithTheLoadersOwnChecks) {
  EXPECT_EQ(header_error("linear", {{"dwell_s", -5}}),
            "capture header: linear: key 'dwell_s': -5 must be > 0 and at most 3600 s");
  EXPECT_EQ(header_error("environment", {{"on_stale", "maybe"}}),
            "capture header: environment: key 'on_stale': 'maybe' is not one of: stop, fallback");
  EXPECT_EQ(header_error("trigger", {{"window_mm", "wide"}}),
            "capture header: trigger: key 'window_mm': unexpected string");
  EXPECT_EQ(header_error("circle", {{"radii_mm", {100, -1}}}),
            "capture header: circle: key 'radii_mm': -1 must be > 0 and at most 5000 mm");
  EXPECT_EQ(header_error("circle", {{"planes", {"XY", 3}}}).substr(0, 47),
            "capture header: circle: key 'planes': [json.exc");
  EXPECT_EQ(header_error("linear", {{"measure", {{"beams", {0, 1, 2}}}}}),
            "capture header: measure: key 'beams': expected 2 values");
  EXPECT_EQ(header_error("linear", {{"runs", 1.5}}),
            "capture header: linear: key 'runs': unexpected number");
  EXPECT_EQ(header_error("linear", {{"runs", 7}}), "(accepted)");
}

TEST(ConfigSections, TheSetUpFormKeepsTheMeasureAndSetKeys) {
  // The form wrote only the single-test keys before: a straightness test's set-up and the
  // ballbar set were lost on the way through the page.
  const auto text =
      daq::serve::setup_toml(daq::serve::setup_of(cal::daq::parse_config(kEveryKey, "every.toml")));
  const auto again = cal::daq::parse_config(text, "again.toml");
  EXPECT_EQ(at_default(again.linear->measure, fd::measure()),
            (std::vector<std::string>{"reference"}))
      << text;
  EXPECT_EQ(again.linear->measure.direction, "Z");
  EXPECT_TRUE(again.linear->measure.square);
  EXPECT_EQ(again.circle->feeds_mm_per_min, (std::vector<double>{500, 2000}));
  EXPECT_DOUBLE_EQ(again.circle->partial_arc_deg, 200);
  // In the table's order (docs/config.md), not alphabetically.
  EXPECT_LT(text.find("\nmeasure = \"straightness\""), text.find("\ndirection = \"Z\""));
  EXPECT_LT(text.find("\nradius_mm = 150"), text.find("\nfeed_mm_per_min = 500"));
}

TEST(ConfigSections, EveryKeyIsDocumented) {
  std::ifstream in(CALDAQ_CONFIG_DOC);
  ASSERT_TRUE(in) << CALDAQ_CONFIG_DOC;
  std::stringstream doc;
  doc << in.rdbuf();
  const auto documented = [&](std::string_view key) {
    return doc.str().find(std::string(key) + " =") != std::string::npos ||
           doc.str().find("`" + std::string(key) + "`") != std::string::npos;
  };
  std::vector<std::string_view> missing;
  const auto check = [&](auto table) {
    for (const auto& f : table)
      if (!documented(f.key)) missing.push_back(f.key);
  };
  check(fd::environment()), check(fd::trigger()), check(fd::linear()), check(fd::measure()),
      check(fd::circle());
  EXPECT_TRUE(missing.empty()) << "not in docs/config.md: "
                               << fmt::format("{}", fmt::join(missing, ", "));
}

}  // namespace
