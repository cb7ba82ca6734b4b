// The device registry: every registered device is complete and its option table consistent,
// options are checked and parsed with the messages the configuration and `daq decode --set`
// show, and the list is the one drivers/devices.cmake names.
#include "cal/drivers/registry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "cal/analysis/error.hpp"

namespace {

namespace d = cal::drivers;

TEST(Registry, ListsTheDevicesInTheOrderOfDevicesCmake) {
  const auto names = d::driver_names();
  EXPECT_EQ(std::vector<std::string_view>(names.begin(), names.end()),
            (std::vector<std::string_view>{"ids3010", "ptu300", "gauge", "temper", "halsampler",
                                           "shdr"}));
  EXPECT_EQ(d::find_driver("ptu300")->name(), "ptu300");
  EXPECT_EQ(d::find_driver("ptu3000"), nullptr);
  try {
    d::driver("laser");
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_STREQ(e.what(),
                 "unknown driver 'laser' (expected one of: ids3010, ptu300, gauge, temper, "
                 "halsampler, shdr)");
  }
}

TEST(Registry, EveryOptionTableIsConsistent) {
  const auto common = d::common_device_keys();
  for (const auto* drv : d::device_drivers()) {
    SCOPED_TRACE(std::string(drv->name()));
    EXPECT_FALSE(drv->description().empty());
    EXPECT_FALSE(drv->transport_example().empty());
    EXPECT_FALSE(drv->decode_input().empty());
    std::set<std::string> seen;
    for (const auto& o : drv->options()) {
      SCOPED_TRACE(o.name);
      EXPECT_TRUE(seen.insert(o.name).second) << "option named twice";
      EXPECT_EQ(std::find(common.begin(), common.end(), o.name), common.end())
          << "a device option may not shadow a common key";
      EXPECT_FALSE(o.help.empty());
      if (o.type == d::OptionType::choice) {
        EXPECT_FALSE(o.choices.empty());
      }
      // A default is a value the table itself accepts (or none: derived).
      if (!std::holds_alternative<std::monostate>(o.default_value)) {
        const auto checked = d::check_option(o, o.default_value);
        EXPECT_EQ(checked.error, "");
      }
    }
    // The defaults alone make a valid device, with readings of some kind.
    const d::Options defaults(drv->options());
    EXPECT_NO_THROW(drv->validate(defaults));
    EXPECT_FALSE(drv->quantities(defaults, {}).empty());
    EXPECT_NE(drv->make_decoder(defaults), nullptr);
    for (const auto& k : drv->usb_ids()) {
      EXPECT_EQ(k.driver, drv->name());
    }
  }
}

TEST(Registry, TheCatalogIsTheDevicesUsbIds) {
  // TEMPer sticks are the only USB devices known by VID:PID (serial instruments sit behind
  // generic adapters, the IDS3010 is on the network).
  ASSERT_FALSE(d::known_usb_devices().empty());
  for (const auto& k : d::known_usb_devices()) {
    EXPECT_EQ(k.driver, "temper");
  }
  ASSERT_NE(d::find_known_device(0x413d, 0x2107), nullptr);
  EXPECT_EQ(d::find_known_device(0x1a86, 0x7523), nullptr);  // a CH340 serial adapter: not ours
}

TEST(Options, CheckedAgainstTheTableWithTheConfigurationsMessages) {
  const d::OptionSpec axes{.name = "axes", .type = d::OptionType::integer_list, .min = 0, .max = 2};
  EXPECT_EQ(d::check_option(axes, std::vector<std::int64_t>{0, 2}).error, "");
  EXPECT_EQ(d::check_option(axes, std::vector<std::int64_t>{3}).error, "3 must be within [0, 2]");
  EXPECT_EQ(d::check_option(axes, std::string("0")).error, "expected an array of integers");
  const d::OptionSpec family{
      .name = "family", .type = d::OptionType::choice, .choices = {"ds75", "gold", "temperx"}};
  EXPECT_EQ(d::check_option(family, std::string("silver")).error,
            "'silver' is not one of: ds75, gold, temperx");
  const d::OptionSpec period{.name = "p", .type = d::OptionType::number, .min = 0.05};
  // An integer is a number (TOML writes 1 for 1.0) and comes back as a double.
  const auto one = d::check_option(period, std::int64_t{1});
  EXPECT_EQ(one.error, "");
  EXPECT_EQ(std::get<double>(one.value), 1.0);
  EXPECT_EQ(d::check_option(period, 0.01).error, "0.01 must be >= 0.05");
  EXPECT_EQ(d::check_option(period, true).error, "expected a number");
  const d::OptionSpec column{.name = "column", .type = d::OptionType::integer, .min = 0};
  EXPECT_EQ(d::check_option(column, 1.5).error, "expected an integer");
  const d::OptionSpec request{.name = "request", .type = d::OptionType::string, .unescape = true};
  EXPECT_EQ(std::get<std::string>(d::check_option(request, std::string("?\\r")).value), "?\r");
}

TEST(Options, ParsedFromSetTextByType) {
  const d::OptionSpec axes{.name = "axes", .type = d::OptionType::integer_list, .min = 0, .max = 2};
  EXPECT_EQ(std::get<std::vector<std::int64_t>>(d::parse_option_text(axes, "0,2")),
            (std::vector<std::int64_t>{0, 2}));
  EXPECT_EQ(std::get<std::vector<std::int64_t>>(d::parse_option_text(axes, "[1]")),
            (std::vector<std::int64_t>{1}));
  const d::OptionSpec tagged{.name = "tagged", .type = d::OptionType::boolean};
  EXPECT_EQ(std::get<bool>(d::parse_option_text(tagged, "true")), true);
  try {
    d::parse_option_text(tagged, "yes");
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_STREQ(e.what(), "option 'tagged': 'yes': expected true or false");
  }
  EXPECT_THROW(d::parse_option_text(axes, "0,x"), cal::InputError);
  EXPECT_EQ(d::format_option_value(std::vector<std::int64_t>{0, 1}), "[0, 1]");
  EXPECT_EQ(d::format_option_value(std::string("?\r")), "\"?\\r\"");
}

TEST(Options, FromTextNamesAnUnknownOptionAndTheDriversOwn) {
  const auto& gauge = d::driver("gauge");
  const std::pair<std::string, std::string> unit{"unit", "um"};
  EXPECT_EQ(d::options_from_text(gauge, std::span(&unit, 1)).text("unit"), "um");
  const std::pair<std::string, std::string> typo{"units", "um"};
  try {
    d::options_from_text(gauge, std::span(&typo, 1));
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_STREQ(
        e.what(),
        "driver 'gauge' has no option 'units' (its options: preset, request, pattern, unit, "
        "scale, offset, min_si, max_si)");
  }
  // Checks between options: a gauge pattern without a capture group.
  const std::pair<std::string, std::string> pattern{"pattern", "[0-9.]+"};
  EXPECT_THROW(d::options_from_text(gauge, std::span(&pattern, 1)), cal::InputError);
}

}  // namespace
