#pragma once
// Every JSON document from outside (model files, capture headers, the set-up, stored result
// documents read back) is parsed here: nlohmann's parser itself is iterative, but dump(), copy
// and comparison recurse, so a document nested 100 000 deep crashes whatever prints it. The
// depth is checked before parsing (a linear scan), and every error names the input and the
// byte (docs/cli.md, "JSON inputs").
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace cal::daq {

// Deeper than any document caldaq writes (a model file's source is 4 levels down).
inline constexpr std::size_t kMaxJsonDepth = 64;

// Throws InputError "WHERE: line L, byte B: JSON nested deeper than 64 levels".
void check_json_depth(std::string_view text, std::string_view where,
                      std::size_t max_depth = kMaxJsonDepth);

// Rethrows a parse error of `where` as InputError "WHERE: not valid JSON (parse error at line
// L, column C: ...)" (syntax, bytes that are not UTF-8, numbers out of range).
[[noreturn]] void throw_json_input_error(std::string_view where,
                                         const nlohmann::json::exception& e);

// The document, its depth checked; InputError naming `where` for anything wrong.
template <class Json = nlohmann::json, class Callback = std::nullptr_t>
Json parse_json_input(std::string_view text, std::string_view where, Callback callback = nullptr) {
  check_json_depth(text, where);
  try {
    if constexpr (std::is_same_v<Callback, std::nullptr_t>)
      return Json::parse(text.begin(), text.end());
    else
      return Json::parse(text.begin(), text.end(), typename Json::parser_callback_t(callback));
  } catch (const nlohmann::json::exception& e) {
    throw_json_input_error(where, e);
  }
}

// A document this program stored, read back: the value, or a discarded value (is_discarded())
// when it is not valid JSON or nested deeper than kMaxJsonDepth (a damaged database). Never
// throws.
nlohmann::json parse_stored_json(std::string_view text);

// A document as printed output (--json): bytes in its strings that are not UTF-8 (text stored
// by an older version, a path, a device's string) shown as U+FFFD instead of an exception
// (nlohmann's dump() throws on them).
std::string dump_output(const nlohmann::json& j, int indent = -1);

}  // namespace cal::daq
