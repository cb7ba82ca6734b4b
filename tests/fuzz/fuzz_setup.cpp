// The operator's set-up (caldaq.setup.v1 JSON, POST /api/setup/check) on arbitrary text, parsed
// as every JSON input is (json_input.hpp: depth bounded, errors named) and checked by the
// set-up form with the configuration loader: a check with its problems, or cal::InputError.
// Never a crash, a hang or another exception (nlohmann's type errors on a set-up of the wrong
// shape included).
#include <string_view>

#include "cal/analysis/error.hpp"
#include "json_input.hpp"
#include "serve/setup_form.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto setup = cal::daq::parse_json_input(text, "fuzz setup");
    const auto check = daq::serve::check_setup(setup, "fuzz setup");
    (void)daq::serve::to_json(check).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    if (check.problems.empty() && !check.config) __builtin_trap();  // valid but no configuration
  } catch (const cal::InputError&) {
  }
  return 0;
}
