#pragma once
// The configuration's plain sections as JSON, from their field tables (cal/daq/config_fields.hpp):
// the capture header writes and reads them, the operator's set-up form writes them. One
// writer, one reader, the loader's own checks.
#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <variant>

#include "cal/analysis/error.hpp"
#include "cal/daq/config_fields.hpp"
#include "cal/drivers/options.hpp"

namespace daq {

// An option's value as JSON (null: no value).
inline nlohmann::json option_json(const cal::drivers::OptionValue& v) {
  return std::visit(
      [](const auto& x) -> nlohmann::json {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, std::monostate>)
          return nullptr;
        else
          return x;
      },
      v);
}

// A tolerance's limits as JSON: the limits given, by their keys (positioning_limit_keys).
inline nlohmann::json limits_json(const cal::daq::PositioningLimits& l) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& k : cal::daq::positioning_limit_keys)
    if (const auto& v = l.*k.member) j[k.key] = *v;
  return j;
}

enum class FieldKeys {
  header,  // the capture header's keys (a field's header_key where it has one)
  file     // the configuration file's keys
};
enum class FieldValues {
  all,  // every key (the capture header: a replay needs nothing from defaults)
  set   // the keys a file would write: shown always, or not the default (the set-up form)
};

namespace detail {
template <class V>
nlohmann::json value_json(const V& v) {
  if constexpr (std::is_same_v<V, cal::daq::StalePolicy>)
    return cal::daq::fields::to_string(v);
  else
    return v;
}

template <class S>
std::string_view key_of(const cal::daq::fields::Field<S>& f, FieldKeys keys) {
  return keys == FieldKeys::header && !f.header_key.empty() ? f.header_key : f.key;
}

[[noreturn]] inline void refuse(std::string_view where, std::string_view key,
                                const std::string& what) {
  throw cal::InputError(fmt::format("{}: key '{}': {}", where, key, what));
}

template <class S>
void check(const cal::daq::fields::Field<S>& f, std::string_view where, std::string_view key,
           const nlohmann::json& v) {
  namespace fd = cal::daq::fields;
  const auto e = v.is_number()   ? fd::number_error(f, v.get<double>())
                 : v.is_string() ? fd::text_error(f, v.get<std::string>())
                                 : std::nullopt;
  if (e) refuse(where, key, *e);
}

template <class V>
struct Inner {
  using type = V;
};
template <class V>
struct Inner<std::optional<V>> {
  using type = V;
};

// The JSON type a member holds (integers also where a number is expected).
template <class V>
bool has_type(const nlohmann::json& v) {
  if constexpr (std::is_same_v<V, double>)
    return v.is_number();
  else if constexpr (std::is_same_v<V, int>)
    return v.is_number_integer();
  else if constexpr (std::is_same_v<V, bool>)
    return v.is_boolean();
  else if constexpr (std::is_same_v<V, std::string> || std::is_same_v<V, cal::daq::StalePolicy>)
    return v.is_string();
  else
    return v.is_array();
}
}  // namespace detail

// The fields of `s` as a JSON object.
template <class S>
nlohmann::json fields_json(const S& s, std::span<const cal::daq::fields::Field<S>> fields,
                           FieldKeys keys = FieldKeys::header,
                           FieldValues values = FieldValues::all) {
  static const S defaults{};
  nlohmann::json j = nlohmann::json::object();
  for (const auto& f : fields) {
    std::visit(
        [&](auto member) {
          const auto& v = s.*member;
          using V = std::decay_t<decltype(v)>;
          if constexpr (requires { v.has_value(); }) {
            if (v) j[std::string(detail::key_of(f, keys))] = *v;
          } else if (values == FieldValues::all || f.shown == cal::daq::fields::Shown::always ||
                     !(v == defaults.*member)) {
            j[std::string(detail::key_of(f, keys))] = detail::value_json<V>(v);
          }
        },
        f.member);
  }
  return j;
}

// Reads the fields a JSON object has into `s` (the others keep what `s` holds), with the
// configuration loader's checks; `where` names the object in errors ("capture header:
// linear"). Throws cal::InputError naming the key.
template <class S>
void fields_from_json(const nlohmann::json& j, std::span<const cal::daq::fields::Field<S>> fields,
                      S& s, std::string_view where, FieldKeys keys = FieldKeys::header) {
  if (!j.is_object()) detail::refuse(where, "", "expected an object");
  for (const auto& f : fields) {
    const std::string key(detail::key_of(f, keys));
    const auto at = j.find(key);
    if (at == j.end() || at->is_null()) continue;
    std::visit(
        [&](auto member) {
          auto& target = s.*member;
          using V = std::decay_t<decltype(target)>;
          using Inner = typename detail::Inner<V>::type;
          if (!detail::has_type<Inner>(*at))
            detail::refuse(where, key, fmt::format("unexpected {}", at->type_name()));
          if constexpr (requires { std::tuple_size<Inner>::value; })
            if (at->size() != std::tuple_size_v<Inner>)
              detail::refuse(where, key,
                             fmt::format("expected {} values", std::tuple_size_v<Inner>));
          if (at->is_array())
            for (const auto& e : *at) detail::check(f, where, key, e);
          else
            detail::check(f, where, key, *at);
          try {
            if constexpr (std::is_same_v<Inner, cal::daq::StalePolicy>)
              target = *cal::daq::fields::stale_policy(at->get<std::string>());
            else
              target = at->get<Inner>();
          } catch (const nlohmann::json::exception& e) {
            detail::refuse(where, key, e.what());
          }
        },
        f.member);
  }
}

}  // namespace daq
