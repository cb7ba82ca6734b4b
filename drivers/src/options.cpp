// Device option tables (see options.hpp).
#include "cal/drivers/options.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::drivers {
namespace {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

std::string unescape(std::string s) {
  static constexpr std::pair<std::string_view, char> kEscapes[] = {
      {"\\r", '\r'}, {"\\n", '\n'}, {"\\t", '\t'}};
  for (const auto& [text, c] : kEscapes)
    for (std::size_t at; (at = s.find(text)) != std::string::npos;) s.replace(at, 2, 1, c);
  return s;
}

// "must be >= 0", "must be <= 2", "must be within [0, 2]"; empty when in range.
std::string range_error(const OptionSpec& spec, double v) {
  if (!std::isfinite(v)) return fmt::format("{} is not a finite number", v);
  const bool low = spec.min && v < *spec.min, high = spec.max && v > *spec.max;
  if (!low && !high && std::isfinite(v)) return {};
  if (spec.min && spec.max)
    return fmt::format("{} must be within [{}, {}]", v, *spec.min, *spec.max);
  if (spec.min) return fmt::format("{} must be >= {}", v, *spec.min);
  if (spec.max) return fmt::format("{} must be <= {}", v, *spec.max);
  return fmt::format("{} is not a finite number", v);
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::optional<std::int64_t> parse_integer(std::string_view s) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  std::int64_t v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc{} || p != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<double> parse_double(std::string_view s) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc{} || p != s.data() + s.size()) return std::nullopt;
  return v;
}

}  // namespace

std::string_view to_string(OptionType type) {
  using enum OptionType;
  static constexpr EnumName<OptionType> kNames[] = {
      {boolean, "boolean"}, {integer, "integer"}, {number, "number"},
      {string, "string"},   {choice, "choice"},   {integer_list, "integer list"}};
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, type, "unknown");
}

const OptionSpec* find_option(std::span<const OptionSpec> table, std::string_view name) {
  for (const auto& o : table)
    if (o.name == name) return &o;
  return nullptr;
}

CheckedOption check_option(const OptionSpec& spec, OptionValue value) {
  switch (spec.type) {
    case OptionType::boolean:
      if (!std::holds_alternative<bool>(value)) return {{}, "expected true or false"};
      return {value, {}};
    case OptionType::integer: {
      const auto* v = std::get_if<std::int64_t>(&value);
      if (!v) return {{}, "expected an integer"};
      if (auto e = range_error(spec, static_cast<double>(*v)); !e.empty()) return {{}, e};
      return {value, {}};
    }
    case OptionType::number: {
      double v = 0;
      if (const auto* i = std::get_if<std::int64_t>(&value))
        v = static_cast<double>(*i);  // an integer is a number (TOML writes 1 for 1.0)
      else if (const auto* d = std::get_if<double>(&value))
        v = *d;
      else
        return {{}, "expected a number"};
      if (auto e = range_error(spec, v); !e.empty()) return {{}, e};
      return {v, {}};
    }
    case OptionType::string: {
      auto* s = std::get_if<std::string>(&value);
      if (!s) return {{}, "expected a string"};
      return {spec.unescape ? unescape(*s) : *s, {}};
    }
    case OptionType::choice: {
      const auto* s = std::get_if<std::string>(&value);
      if (!s) return {{}, "expected a string"};
      if (std::find(spec.choices.begin(), spec.choices.end(), *s) == spec.choices.end())
        return {{}, fmt::format("'{}' is not one of: {}", *s, fmt::join(spec.choices, ", "))};
      return {value, {}};
    }
    case OptionType::integer_list: {
      const auto* l = std::get_if<std::vector<std::int64_t>>(&value);
      if (!l) return {{}, "expected an array of integers"};
      for (const auto v : *l)
        if (auto e = range_error(spec, static_cast<double>(v)); !e.empty()) return {{}, e};
      return {value, {}};
    }
  }
  return {{}, "unknown option type"};
}

OptionValue parse_option_text(const OptionSpec& spec, std::string_view text) {
  const auto fail = [&](std::string_view why) -> OptionValue {
    throw InputError(fmt::format("option '{}': '{}': {}", spec.name, text, why));
  };
  OptionValue v;
  switch (spec.type) {
    case OptionType::boolean:
      if (trim(text) == "true")
        v = true;
      else if (trim(text) == "false")
        v = false;
      else
        return fail("expected true or false");
      break;
    case OptionType::integer:
      if (auto i = parse_integer(text))
        v = *i;
      else
        return fail("expected an integer");
      break;
    case OptionType::number:
      if (auto d = parse_double(text))
        v = *d;
      else
        return fail("expected a number");
      break;
    case OptionType::string:
    case OptionType::choice:
      v = std::string(text);
      break;
    case OptionType::integer_list: {
      std::string_view body = trim(text);
      if (body.starts_with('[') && body.ends_with(']')) body = body.substr(1, body.size() - 2);
      std::vector<std::int64_t> list;
      while (!trim(body).empty()) {
        const auto comma = body.find(',');
        const auto item = parse_integer(body.substr(0, comma));
        if (!item) return fail("expected integers separated by commas, e.g. 0,1");
        list.push_back(*item);
        if (comma == std::string_view::npos) break;
        body.remove_prefix(comma + 1);
      }
      v = std::move(list);
      break;
    }
  }
  auto checked = check_option(spec, std::move(v));
  if (!checked.error.empty()) return fail(checked.error);
  return checked.value;
}

std::string format_option_value(const OptionValue& value) {
  return std::visit(Overloaded{[](std::monostate) { return std::string(); },
                               [](bool b) { return std::string(b ? "true" : "false"); },
                               [](std::int64_t i) { return fmt::format("{}", i); },
                               [](double d) { return fmt::format("{}", d); },
                               [](const std::string& s) {
                                 std::string out = "\"";
                                 for (char c : s) {
                                   if (c == '\r')
                                     out += "\\r";
                                   else if (c == '\n')
                                     out += "\\n";
                                   else if (c == '\t')
                                     out += "\\t";
                                   else if (c == '"' || c == '\\')
                                     out += std::string("\\") + c;
                                   else
                                     out += c;
                                 }
                                 return out + "\"";
                               },
                               [](const std::vector<std::int64_t>& l) {
                                 return fmt::format("[{}]", fmt::join(l, ", "));
                               }},
                    value);
}

Options::Options(std::span<const OptionSpec> table) {
  for (const auto& o : table) values_[o.name] = o.default_value;
}

void Options::set(std::string_view name, OptionValue value) {
  const auto it = values_.find(name);
  if (it == values_.end())
    throw std::logic_error(fmt::format("option '{}' is not in the table", name));
  it->second = std::move(value);
  set_.emplace(name);
}

bool Options::is_set(std::string_view name) const { return set_.contains(name); }

bool Options::has_value(std::string_view name) const {
  return !std::holds_alternative<std::monostate>(value(name));
}

const OptionValue& Options::value(std::string_view name) const {
  const auto it = values_.find(name);
  if (it == values_.end())
    throw std::logic_error(fmt::format("option '{}' is not in the table", name));
  return it->second;
}

namespace {
template <class T>
const T& get(const Options& o, std::string_view name) {
  const T* v = std::get_if<T>(&o.value(name));
  if (!v) throw std::logic_error(fmt::format("option '{}' read as the wrong type", name));
  return *v;
}
}  // namespace

bool Options::boolean(std::string_view name) const { return get<bool>(*this, name); }
std::int64_t Options::integer(std::string_view name) const {
  return get<std::int64_t>(*this, name);
}
double Options::number(std::string_view name) const { return get<double>(*this, name); }
const std::string& Options::text(std::string_view name) const {
  return get<std::string>(*this, name);
}
const std::vector<std::int64_t>& Options::integers(std::string_view name) const {
  return get<std::vector<std::int64_t>>(*this, name);
}

}  // namespace cal::drivers
