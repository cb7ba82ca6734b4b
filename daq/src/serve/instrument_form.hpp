#pragma once
// What the set-up page's instrument form and `daq devices --options --json` are generated from:
// the drivers' registry (cal/drivers/registry.hpp), each driver with its option table (name,
// type, unit, range, default, help), and the keys every [devices.ID] table has. No device is
// named here or in the page: a device added to the registry appears in the form by itself.
#include <nlohmann/json.hpp>

namespace daq::serve {

// caldaq.drivers.v1 (docs/cli.md, `daq devices --options --json`): {"schema", "common_keys",
// "common": [option...], "drivers": [{"name", "description", "transport", "decode_input",
// "options": [option...], "usb": [{"vid_pid", "description"}]}]}, an option being {"name",
// "type" (boolean | integer | number | string | choice | integer_list), "unit", "default" (as
// a TOML file writes it; "" when derived from other options), "help", and "min", "max",
// "choices" where it has them}. "common" describes the common keys other than "driver".
nlohmann::json driver_descriptions();

}  // namespace daq::serve
