// "Did you mean ...?" for mistyped commands and options (see suggest.hpp).
#include "suggest.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <numeric>
#include <vector>

namespace daq {
namespace {

// "-150", "-0.5", ".5", "12": a (negative) number is a value, never an option.
bool is_number(std::string_view s) {
  if (s.starts_with('-') || s.starts_with('+')) s.remove_prefix(1);
  return !s.empty() && (std::isdigit(static_cast<unsigned char>(s.front())) || s.front() == '.');
}

bool is_option(std::string_view s) { return s.size() > 1 && s.front() == '-' && !is_number(s); }

// "daq report", "daq model map": how a person types the command `app`.
std::string command_line(const CLI::App& app) {
  std::vector<std::string> names;
  // The root's own name is argv[0] once parsed ("build/daq/daq"): always "daq" here.
  for (const CLI::App* a = &app; a->get_parent() != nullptr; a = a->get_parent())
    if (!a->get_name().empty()) names.push_back(a->get_name());
  std::string line = "daq";
  for (auto it = names.rbegin(); it != names.rend(); ++it) line += " " + *it;
  return line;
}

// The option `name` ("--db", "-o") of `app` or of a command it is part of.
const CLI::Option* find_option(const CLI::App& app, const std::string& name) {
  for (const CLI::App* a = &app; a != nullptr; a = a->get_parent())
    if (const CLI::Option* o = a->get_option_no_throw(name)) return o;
  return nullptr;
}

void add_option_names(const CLI::App& app, std::vector<std::string>& names) {
  for (const CLI::Option* o : app.get_options()) {
    for (const auto& l : o->get_lnames()) names.push_back("--" + l);
    for (const auto& s : o->get_snames()) names.push_back("-" + s);
  }
  for (const CLI::App* group :
       app.get_subcommands([](const CLI::App* x) { return x->get_name().empty(); }))
    add_option_names(*group, names);
}

std::vector<const CLI::App*> named_subcommands(const CLI::App& app) {
  return app.get_subcommands([](const CLI::App* x) { return !x->get_name().empty(); });
}

std::vector<std::string> subcommand_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* s : named_subcommands(app)) {
    names.push_back(s->get_name());
    for (const auto& a : s->get_aliases()) names.push_back(a);
  }
  return names;
}

bool has_positionals(const CLI::App& app) {
  return !app.get_options([](const CLI::Option* o) { return o->get_positional(); }).empty();
}

// "; did you mean '--format'?", else where the right words are listed.
std::string hint(const std::optional<std::string>& near, const CLI::App& app) {
  return near ? fmt::format("; did you mean '{}'?", *near)
              : fmt::format(" (see {} --help)", command_line(app));
}

}  // namespace

std::size_t edit_distance(std::string_view a, std::string_view b) {
  // Three rows of the optimal string alignment table: two back for transpositions.
  std::vector<std::size_t> prev2(b.size() + 1), prev(b.size() + 1), row(b.size() + 1);
  std::iota(prev.begin(), prev.end(), std::size_t{0});
  for (std::size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      row[j] = std::min({prev[j] + 1, row[j - 1] + 1, prev[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        row[j] = std::min(row[j], prev2[j - 2] + 1);
    }
    std::swap(prev2, prev);
    std::swap(prev, row);
  }
  return prev[b.size()];
}

std::optional<std::string> nearest(std::string_view word, std::span<const std::string> candidates) {
  // Dashes do not count as letters: "--wht" has three, and may differ from "--what" by one.
  const auto letters =
      std::max<std::size_t>(word.size() - std::min(word.find_first_not_of('-'), word.size()), 1);
  const std::size_t allowed = std::max<std::size_t>(1, letters / 3);
  std::optional<std::string> best;
  std::size_t best_distance = allowed + 1;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_distance) best = c, best_distance = d;
  }
  return best;
}

std::optional<std::string> unknown_word(const CLI::App& app, std::span<const std::string> args) {
  const CLI::App* cur = &app;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--") break;  // everything after it is a positional value
    if (is_number(arg) || arg == "-") continue;
    if (is_option(arg)) {
      const bool long_form = arg.starts_with("--");
      const auto eq = arg.find('=');
      // "--db=FILE", "-oFILE": the option's name only.
      const std::string name = long_form ? arg.substr(0, eq) : arg.substr(0, 2);
      const CLI::Option* opt = find_option(*cur, name);
      if (opt == nullptr) {
        std::vector<std::string> names;
        for (const CLI::App* a = cur; a != nullptr; a = a->get_parent())
          add_option_names(*a, names);
        return fmt::format("unknown option '{}' of {}{}", name, command_line(*cur),
                           hint(nearest(name, names), *cur));
      }
      if ((long_form && eq != std::string::npos) || (!long_form && arg.size() > 2)) continue;
      // Its values: as many words as it takes, up to the next option.
      for (int n = opt->get_items_expected_max(); n > 0 && i + 1 < args.size(); --n) {
        if (args[i + 1] == "--" || is_option(args[i + 1])) break;
        ++i;
      }
      continue;
    }
    const auto subs = named_subcommands(*cur);
    const auto sub = std::find_if(subs.begin(), subs.end(),
                                  [&](const CLI::App* s) { return s->check_name(arg); });
    if (sub != subs.end()) {
      cur = *sub;
      continue;
    }
    if (subs.empty()) continue;  // a positional value
    const auto names = subcommand_names(*cur);
    const auto near = nearest(arg, names);
    // A word where only a command can stand, or one so near a command's name that it is no
    // value of a positional argument.
    if ((cur->get_require_subcommand_min() > 0 && !has_positionals(*cur)) || near)
      return fmt::format("unknown command '{}' of {}{}", arg, command_line(*cur), hint(near, *cur));
  }
  return std::nullopt;
}

std::string parsed_command(const CLI::App& app) {
  const CLI::App* cur = &app;
  for (auto subs = cur->get_subcommands(); !subs.empty(); subs = cur->get_subcommands())
    cur = subs.back();
  return command_line(*cur);
}

}  // namespace daq
