// The drivers' settings for the set-up page and `daq devices --options --json`, from the
// registry (see instrument_form.hpp).
#include "serve/instrument_form.hpp"

#include <fmt/format.h>

#include <iterator>
#include <string_view>

#include "cal/daq/config.hpp"
#include "cal/drivers/registry.hpp"

namespace daq::serve {

using nlohmann::json;

namespace {

json option_json(const cal::drivers::OptionSpec& o) {
  json e{{"name", o.name},
         {"type", cal::drivers::to_string(o.type)},
         {"unit", o.unit},
         {"default", cal::drivers::format_option_value(o.default_value)},
         {"help", o.help}};
  if (o.min) e["min"] = *o.min;
  if (o.max) e["max"] = *o.max;
  if (!o.choices.empty()) e["choices"] = o.choices;
  return e;
}

// The keys of every [devices.ID] table are the configuration loader's (cal/daq/config.hpp,
// DeviceConfig), not a device's: described here for the form. A common key this table does not
// know (added to the registry's list later) is shown as a plain text field.
json common_option(std::string_view key) {
  using cal::drivers::OptionSpec;
  using cal::drivers::OptionType;
  OptionSpec o{.name = std::string(key)};
  if (key == "transport") {
    o.help = "tcp HOST:PORT | serial DEVICE BAUD FRAME [FLOW] | hid VID:PID | hid /dev/hidrawN";
  } else if (key == "role") {
    o.type = OptionType::choice;
    // Every role the configuration loader knows: a straightness test reads an indicator, a
    // roll test a level, a rotary test an angular reference (a card without them lost the role
    // and the test its probe).
    o.choices.assign(std::begin(cal::daq::device_roles), std::end(cal::daq::device_roles));
    o.help = "what a run uses it for";
  } else if (key == "poll_s") {
    o.type = OptionType::number;
    o.unit = "s";
    o.min = 0.0;
    o.default_value = 0.0;
    o.help = "poll period; 0: the driver's default";
  } else if (key == "serial_number") {
    o.help = "the instrument's serial number (report)";
  } else if (key == "certificate") {
    o.help = "calibration certificate (report)";
  } else if (key == "calibration_due") {
    o.help = "YYYY-MM-DD (the report warns after it)";
  }
  return option_json(o);
}

}  // namespace

json driver_descriptions() {
  json common = json::array();
  for (const auto key : cal::drivers::common_device_keys())
    if (key != "driver") common.push_back(common_option(key));
  json out{{"schema", "caldaq.drivers.v1"},
           {"common_keys", cal::drivers::common_device_keys()},
           {"common", common},
           {"drivers", json::array()}};
  for (const auto* d : cal::drivers::device_drivers()) {
    json options = json::array();
    for (const auto& o : d->options()) options.push_back(option_json(o));
    json usb = json::array();
    for (const auto& k : d->usb_ids())
      usb.push_back({{"vid_pid", fmt::format("{:04x}:{:04x}", k.vendor_id, k.product_id)},
                     {"description", k.description}});
    out["drivers"].push_back({{"name", d->name()},
                              {"description", d->description()},
                              {"transport", d->transport_example()},
                              {"decode_input", d->decode_input()},
                              {"options", options},
                              {"usb", usb}});
  }
  return out;
}

}  // namespace daq::serve
