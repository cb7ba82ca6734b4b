// The set-up page's instrument form is generated from the drivers' registry: every registered
// driver with its whole option table, and nothing else (issue 16, issue 19).
#include "serve/instrument_form.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "cal/daq/config.hpp"
#include "cal/drivers/registry.hpp"

namespace {

using nlohmann::json;

TEST(InstrumentForm, EveryRegisteredDriverWithItsWholeOptionTable) {
  const json doc = daq::serve::driver_descriptions();
  EXPECT_EQ(doc["schema"], "caldaq.drivers.v1");
  const auto drivers = cal::drivers::device_drivers();
  ASSERT_EQ(doc["drivers"].size(), drivers.size());
  for (std::size_t i = 0; i < drivers.size(); ++i) {
    const auto& d = *drivers[i];
    const json& j = doc["drivers"][i];
    EXPECT_EQ(j["name"], std::string(d.name()));
    EXPECT_EQ(j["transport"], std::string(d.transport_example()));
    ASSERT_EQ(j["options"].size(), d.options().size()) << d.name();
    for (std::size_t k = 0; k < d.options().size(); ++k) {
      const auto& spec = d.options()[k];
      const json& o = j["options"][k];
      EXPECT_EQ(o["name"], spec.name);
      EXPECT_EQ(o["type"], std::string(cal::drivers::to_string(spec.type)));
      EXPECT_EQ(o["unit"], spec.unit);
      EXPECT_EQ(o["help"], spec.help);
      EXPECT_EQ(o["default"], cal::drivers::format_option_value(spec.default_value));
      EXPECT_EQ(o.contains("min"), spec.min.has_value()) << spec.name;
      if (spec.min) {
        EXPECT_EQ(o["min"].get<double>(), *spec.min);
      }
      if (spec.max) {
        EXPECT_EQ(o["max"].get<double>(), *spec.max);
      }
      if (!spec.choices.empty()) {
        EXPECT_EQ(o["choices"], spec.choices);
      }
    }
  }
}

TEST(InstrumentForm, TheCommonKeysAreThoseOfEveryDeviceTable) {
  const json doc = daq::serve::driver_descriptions();
  std::set<std::string> common, want;
  for (const auto& o : doc["common"]) common.insert(o["name"].get<std::string>());
  for (const auto k : cal::drivers::common_device_keys())
    if (k != "driver") want.insert(std::string(k));  // the form's driver selector
  EXPECT_EQ(common, want);
}

// The form's role choices are the configuration loader's: each is read, another is refused, and
// every role a run uses is offered (the angular reference of a rotary run, "angle", was not:
// its card could not be given it).
TEST(InstrumentForm, TheRoleChoicesAreTheLoaders) {
  const json doc = daq::serve::driver_descriptions();
  json roles;
  for (const auto& o : doc["common"])
    if (o["name"] == "role") roles = o["choices"];
  ASSERT_FALSE(roles.empty());
  EXPECT_EQ(roles, json({"laser", "air", "material", "ballbar", "position", "indicator", "level",
                         "angle"}));
  const std::string driver(cal::drivers::device_drivers().front()->name());
  const std::string transport(cal::drivers::device_drivers().front()->transport_example());
  const auto config = [&](const std::string& role) {
    return "[machine]\nname = \"M\"\n[devices.d]\ndriver = \"" + driver + "\"\ntransport = \"" +
           transport + "\"\nrole = \"" + role + "\"\n";
  };
  for (const auto& r : roles) {
    try {
      cal::daq::parse_config(config(r.get<std::string>()), "roles.toml");
    } catch (const std::exception& e) {
      // Only the role matters here: a transport example with a placeholder host is fine.
      EXPECT_EQ(std::string(e.what()).find("role"), std::string::npos) << e.what();
    }
  }
  try {
    cal::daq::parse_config(config("spindle"), "roles.toml");
    ADD_FAILURE() << "role = \"spindle\" was read";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("key 'devices.d.role'"), std::string::npos) << e.what();
  }
}

}  // namespace
