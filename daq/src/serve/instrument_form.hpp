#pragma once
// What the set-up page's instrument form is generated from: each driver with its settings
// (name, type, unit, range, default, help) and the keys every device has.
//
// TO BE SWITCHED TO THE DRIVERS' REGISTRY (issue 19, branch `registry`): until it lands in main,
// this one function holds a small table of today's drivers and their keys as the configuration
// loader reads them (cal/daq/config.hpp, DeviceConfig); the registry's option tables
// (cal/drivers/options.hpp: OptionSpec) have the same fields, so the switch replaces the table
// by a loop over cal::drivers::device_drivers() and leaves the page as it is.
#include <nlohmann/json.hpp>

namespace daq::serve {

// caldaq.drivers.v1: {"schema", "source", "common": [option...], "drivers": [{"name",
// "description", "transport_example", "options": [option...]}]}, an option being {"name",
// "type" (boolean | integer | number | string | choice | integer_list), "unit", "min", "max",
// "choices", "default", "help"}.
nlohmann::json driver_descriptions();

}  // namespace daq::serve
