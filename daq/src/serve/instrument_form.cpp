// The drivers' settings for the set-up page (see instrument_form.hpp: to be generated from the
// drivers' registry once it lands).
#include "serve/instrument_form.hpp"

#include <optional>
#include <string>
#include <vector>

namespace daq::serve {

using nlohmann::json;

namespace {

struct Option {
  const char* name;
  const char* type;
  const char* unit = "";
  std::optional<double> min = {}, max = {};
  std::vector<std::string> choices = {};
  json default_value = nullptr;  // null: none (the help says what then)
  const char* help = "";
};

json to_json(const Option& o) {
  return {{"name", o.name},
          {"type", o.type},
          {"unit", o.unit},
          {"min", o.min ? json(*o.min) : json(nullptr)},
          {"max", o.max ? json(*o.max) : json(nullptr)},
          {"choices", o.choices},
          {"default", o.default_value},
          {"help", o.help}};
}

json options(std::initializer_list<Option> list) {
  json a = json::array();
  for (const auto& o : list) a.push_back(to_json(o));
  return a;
}

const Option poll{.name = "poll_s",
                  .type = "number",
                  .unit = "s",
                  .min = 0.0,
                  .default_value = 0.0,
                  .help = "poll period; 0: the driver's default"};
const Option feed_unit{.name = "unit",
                       .type = "choice",
                       .choices = {"mm", "in"},
                       .default_value = "mm",
                       .help = "the control's unit"};

}  // namespace

json driver_descriptions() {
  json drivers = json::array();
  const auto add = [&](const char* name, const char* description, const char* example, json opts) {
    drivers.push_back({{"name", name},
                       {"description", description},
                       {"transport_example", example},
                       {"options", std::move(opts)}});
  };
  add("ids3010", "Attocube IDS3010 displacement interferometer (JSON-RPC over TCP)",
      "tcp 192.168.1.5:9090",
      options({{.name = "axes",
                .type = "integer_list",
                .min = 0.0,
                .max = 2.0,
                .default_value = json::array({0}),
                .help = "interferometer axes to read (0, 1, 2)"},
               poll}));
  add("ptu300", "Vaisala PTU300 barometer, hygrometer and thermometer (serial)",
      "serial /dev/ttyUSB0 4800 7E1", options({poll}));
  add("gauge", "line-oriented serial gauge: a ballbar's transducer, a length gauge, a thermometer",
      "serial /dev/ttyUSB1 9600 8N1",
      options({{.name = "request",
                .type = "string",
                .default_value = "",
                .help = "sent to poll, e.g. ?\\r; empty: the gauge streams"},
               {.name = "pattern",
                .type = "string",
                .default_value = "",
                .help = "regular expression with one group; empty: a bare number"},
               {.name = "unit",
                .type = "choice",
                .choices = {"mm", "um", "in", "m", "degC"},
                .default_value = "mm",
                .help = "the value's unit"},
               poll}));
  add("temper", "PCsensor TEMPer USB thermometer (HID)", "hid 413d:2107",
      options({{.name = "family",
                .type = "choice",
                .choices = {"ds75", "gold", "temperx"},
                .default_value = "gold",
                .help = "report layout (docs/drivers.md)"},
               poll}));
  add("halsampler", "LinuxCNC halsampler position lines (serial or TCP)", "tcp 192.168.1.20:5000",
      options({{.name = "column",
                .type = "integer",
                .min = 0.0,
                .default_value = 0,
                .help = "the test axis' value column after the sample number"},
               feed_unit}));
  add("shdr", "MTConnect SHDR adapter: the control's position (TCP)", "tcp 192.168.1.20:7878",
      options({{.name = "key",
                .type = "string",
                .default_value = "",
                .help = "the test axis' data item; empty: <axis>act, e.g. Xact"},
               feed_unit}));
  const json common = options(
      {{.name = "transport",
        .type = "string",
        .help = "tcp HOST:PORT | serial DEVICE BAUD FRAME [FLOW] | hid VID:PID | hid /dev/hidrawN"},
       {.name = "role",
        .type = "choice",
        .choices = {"laser", "air", "material", "ballbar", "position"},
        .help = "what a run uses it for"},
       {.name = "serial_number", .type = "string", .help = "in the report"},
       {.name = "certificate", .type = "string", .help = "calibration certificate (report)"},
       {.name = "calibration_due", .type = "string", .help = "YYYY-MM-DD (report warns after)"}});
  return {{"schema", "caldaq.drivers.v1"},
          {"source",
           "built-in table (daq/src/serve/instrument_form.cpp), until the drivers' "
           "registry lands"},
          {"common", common},
          {"drivers", drivers}};
}

}  // namespace daq::serve
