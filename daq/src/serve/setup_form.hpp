#pragma once
// The operator's set-up as the page edits it (caldaq.setup.v1): the configuration file's own
// structure as JSON, key for key (docs/config.md), so that
// - the page names each field by its key path ("test.linear.first_mm"), and an error of the
//   configuration loader, which names the key, lands on the field it is about;
// - the set-up is checked by the loader itself (cal::daq::parse_config of the TOML written
//   from it): the page and `daq run -c` cannot disagree about what is valid;
// - "save as TOML" writes exactly the text that was checked.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cal/daq/config.hpp"

namespace daq::serve {

// The set-up of a configuration (what the loader read; defaults of keys not written are left
// out, so the page shows the file's own choices).
nlohmann::json setup_of(const cal::daq::Config& c);

// The TOML text of a set-up: objects are tables, arrays of objects arrays of tables, null
// values are left out. Strings are escaped by toml++ (any text the operator types stays a
// string). Throws cal::InputError for a value TOML cannot hold (the path named), e.g. a set-up
// that is not an object.
std::string setup_toml(const nlohmann::json& setup);

struct SetupProblem {
  std::string key;      // the key path ("test.linear.first_mm"), or a table ("test.linear")
  std::string message;  // the loader's text without the file position
};

// Whether each test can be run with the set-up's devices (the same checks as a run's start).
struct TestReadiness {
  bool configured = false;
  std::optional<std::string> problem;  // e.g. "no device with role = \"ballbar\""
};

struct SetupCheck {
  std::vector<SetupProblem> problems;  // empty: valid
  std::optional<cal::daq::Config> config;
  std::string toml;  // the text the loader read (of the set-up as given)
  TestReadiness linear, circle;
};

// Checks a set-up with the configuration loader. The loader stops at its first error; to show
// every field at fault at once, the key it names is taken out and the rest read again (up to
// 50 times), so each problem is the loader's own. `source_name` names the set-up in messages.
SetupCheck check_setup(const nlohmann::json& setup, std::string_view source_name = "set-up");

nlohmann::json to_json(const SetupCheck& c);  // {"ok", "problems": [{key, message}], "tests"}

}  // namespace daq::serve
