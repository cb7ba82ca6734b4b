#pragma once
// "Did you mean ...?" for a mistyped command or option. The words are checked against the
// command tree before CLI11 parses them: CLI11 alone reads `daq report 1 --fromat pdf` as an
// unexpected --fromat and a second RUN 'pdf', and `daq analys 1` as a missing subcommand, so
// its message names the wrong thing.
#include <CLI/CLI.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace daq {

// Optimal string alignment distance: insertions, deletions, substitutions and transpositions
// of two neighbours ("fromat" is one from "format") each count 1.
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate nearest to `word` if it is near enough to be a typo (at most a third of the
// word's letters changed, at least one allowed), the first of equals; else nullopt.
std::optional<std::string> nearest(std::string_view word, std::span<const std::string> candidates);

// The first word of `args` (argv without the program's name) that is no command or option of
// `app` where it stands, as the message of a usage error ("unknown option '--fromat' of daq
// report; did you mean '--format'?"); nullopt when every word is known (values of options and
// positional arguments are left to CLI11).
std::optional<std::string> unknown_word(const CLI::App& app, std::span<const std::string> args);

// "daq report": the command line of the deepest subcommand `app` parsed, for "see ... --help".
std::string parsed_command(const CLI::App& app);

}  // namespace daq
