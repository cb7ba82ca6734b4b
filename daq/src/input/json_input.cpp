// JSON inputs parsed with their depth bounded (see json_input.hpp).
#include "json_input.hpp"

#include <fmt/format.h>

#include <optional>
#include <string>

#include "cal/analysis/error.hpp"
#include "cal/analysis/json_scan.hpp"

namespace cal::daq {
namespace {

// Where the text first nests deeper than max_depth (brackets outside strings), or nullopt.
std::optional<std::size_t> too_deep_at(std::string_view text, std::size_t max_depth) {
  std::size_t depth = 0;
  const auto at = cal::text::find_outside_json_strings(text, 0, [&](char c) {
    if (c == '[' || c == '{') return ++depth > max_depth;
    if ((c == ']' || c == '}') && depth > 0) --depth;
    return false;
  });
  return at == std::string_view::npos ? std::nullopt : std::optional(at);
}

}  // namespace

void check_json_depth(std::string_view text, std::string_view where, std::size_t max_depth) {
  const auto at = too_deep_at(text, max_depth);
  if (!at) return;
  std::size_t line = 1;
  for (std::size_t i = 0; i < *at; ++i) line += text[i] == '\n';
  throw InputError(fmt::format("{}: line {}, byte {}: JSON nested deeper than {} levels", where,
                               line, *at, max_depth));
}

void throw_json_input_error(std::string_view where, const nlohmann::json::exception& e) {
  // nlohmann's messages start "[json.exception.parse_error.101] ": the part after is the reason.
  std::string_view what = e.what();
  if (const auto close = what.find("] "); what.starts_with("[json.") && close != what.npos)
    what.remove_prefix(close + 2);
  throw InputError(fmt::format("{}: not valid JSON ({})", where, what));
}

nlohmann::json parse_stored_json(std::string_view text) {
  if (too_deep_at(text, kMaxJsonDepth)) return nlohmann::json(nlohmann::json::value_t::discarded);
  return nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
}

std::string dump_output(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace cal::daq
