#pragma once
// One subcommand and the options it parses into: the way every cmd_*.cpp adds a command.
#include <CLI/CLI.hpp>
#include <concepts>
#include <memory>
#include <string>
#include <utility>

namespace daq {

// A command being declared: `cmd` takes the options, `o` holds their values (neither is null).
template <class Options>
struct Command {
  CLI::App* cmd;
  Options* o;
};

// Adds NAME to PARENT; RUN gets the parsed options. They are shared with the callback because
// CLI11 keeps pointers into them: they must live as long as the application does.
template <class Options, std::invocable<Options&> Run>
Command<Options> add_command(CLI::App& parent, std::string name, Run run, std::string help) {
  auto options = std::make_shared<Options>();
  auto* cmd = parent.add_subcommand(std::move(name), std::move(help));
  cmd->callback([options, run] { run(*options); });
  return {cmd, options.get()};
}

// Adds the group NAME to PARENT: a command that does its work by one of its subcommands, which
// must be given (never null).
inline CLI::App* add_group(CLI::App& parent, std::string name, std::string help) {
  auto* group = parent.add_subcommand(std::move(name), std::move(help));
  group->require_subcommand(1);
  return group;
}

}  // namespace daq
