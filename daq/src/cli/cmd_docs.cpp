// daq man-pages DIR, daq completion bash: the manual pages and the shell completion, made from
// the command tree itself so that they say what --help says (the Debian package builds them
// with the executable: packaging/README.md).
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "commands.hpp"

namespace daq {
namespace {

namespace fs = std::filesystem;

constexpr const char* kVersion = "daq 0.1.0";

const CLI::App& root_of(const CLI::App& app) {
  const CLI::App* a = &app;
  while (a->get_parent() != nullptr) a = a->get_parent();
  return *a;
}

std::vector<const CLI::App*> named(const CLI::App& app) {
  return app.get_subcommands([](const CLI::App* x) { return !x->get_name().empty(); });
}

// The commands a person types, each with its path ("report", "model map"), in definition order.
void each_command(const CLI::App& app, const std::string& path,
                  std::vector<std::pair<std::string, const CLI::App*>>& out) {
  for (const CLI::App* sub : named(app)) {
    const std::string p = path.empty() ? sub->get_name() : path + " " + sub->get_name();
    out.emplace_back(p, sub);
    each_command(*sub, p, out);
  }
}

std::vector<std::pair<std::string, const CLI::App*>> commands(const CLI::App& root) {
  std::vector<std::pair<std::string, const CLI::App*>> out;
  each_command(root, "", out);
  return out;
}

// The options of a command, with those of its nameless option groups.
std::vector<const CLI::Option*> options_of(const CLI::App& app) {
  std::vector<const CLI::Option*> out;
  for (const CLI::Option* o : app.get_options()) out.push_back(o);
  for (const CLI::App* g :
       app.get_subcommands([](const CLI::App* x) { return x->get_name().empty(); }))
    for (const CLI::Option* o : options_of(*g)) out.push_back(o);
  return out;
}

// Text for troff: backslashes and hyphens escaped, no line starting with a control character,
// and every character beyond ASCII as its code point (\[u00B5]), so that the page renders the
// same whatever input encoding groff assumes.
std::string roff(const std::string& text) {
  std::string out;
  bool line_start = true;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (line_start && (c == '.' || c == '\'')) out += "\\&";
    line_start = c == '\n';
    if (c == '\\') {
      out += "\\e";
    } else if (c == '-') {
      out += "\\-";
    } else if (c < 0x80) {
      out += static_cast<char>(c);
    } else {
      // A UTF-8 sequence: its length from the lead byte, its bits from the rest.
      const int extra = c >= 0xF0 ? 3 : c >= 0xE0 ? 2 : c >= 0xC0 ? 1 : 0;
      std::uint32_t code = c & (0x3FU >> extra);
      for (int k = 0; k < extra && i + 1 < text.size(); ++k)
        code = (code << 6) | (static_cast<unsigned char>(text[++i]) & 0x3FU);
      out += fmt::format("\\[u{:04X}]", code);
    }
  }
  return out;
}

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

std::string page_name(const std::string& path) {
  std::string name = "daq";
  for (char c : path) name += c == ' ' ? '-' : c;
  if (!path.empty()) name.insert(3, "-");
  return name;
}

std::string upper(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string man_page(const CLI::App& app, const std::string& path,
                     const std::vector<std::pair<std::string, const CLI::App*>>& all) {
  const std::string name = page_name(path);
  const std::string line = path.empty() ? "daq" : "daq " + path;
  // NAME is one line (whatis and apropos read it): the description's first paragraph, whose
  // lines --help breaks; daq's own begins with its name ("daq - machine-tool ..."): said once.
  const std::string description = app.get_description();
  std::string summary = description.substr(0, description.find("\n\n"));
  std::replace(summary.begin(), summary.end(), '\n', ' ');
  if (const std::string own = name + " - "; summary.starts_with(own)) summary.erase(0, own.size());
  std::string m = fmt::format(".TH {} 1 \"\" \"{}\" \"caldaq\"\n.SH NAME\n{} \\- {}\n", upper(name),
                              kVersion, roff(name), roff(summary));
  std::string positionals;
  for (const CLI::Option* o : options_of(app))
    if (o->get_positional()) positionals += " " + o->get_name(true);
  const bool has_subs = !named(app).empty();
  m += fmt::format(".SH SYNOPSIS\n.B {}\n[OPTIONS]{}{}\n", roff(line), roff(positionals),
                   has_subs ? " [COMMAND]" : "");
  m += fmt::format(".SH DESCRIPTION\n{}\n", roff(app.get_description()));
  std::string arguments, options;
  for (const CLI::Option* o : options_of(app)) {
    const std::string type = o->get_type_name();
    const bool takes_value = !type.empty() && o->get_items_expected_max() > 0;
    std::string entry =
        fmt::format(".TP\n.B {}{}\n{}\n", roff(o->get_name(true, true)),
                    takes_value && o->nonpositional() ? " \\fI" + roff(type) + "\\fR" : "",
                    roff(o->get_description().empty() ? "(no description)" : o->get_description()));
    if (!o->get_default_str().empty())
      entry += fmt::format(".br\nDefault: {}\n", roff(o->get_default_str()));
    (o->nonpositional() ? options : arguments) += entry;
  }
  if (!arguments.empty()) m += ".SH ARGUMENTS\n" + arguments;
  m += ".SH OPTIONS\n" + options;
  std::string subs;
  for (const auto& [p, s] : all)
    if (s->get_parent() == &app)
      subs += fmt::format(".TP\n.B daq {}\n{} (see \\fB{}\\fR(1))\n", roff(p),
                          roff(first_line(s->get_description())), roff(page_name(p)));
  if (!subs.empty()) m += ".SH COMMANDS\n" + subs;
  if (path.empty())
    m += ".SH EXIT STATUS\n0 on success; 2 for a usage error, bad input, or a file, device or port "
         "that cannot be used (the message names it); 1 for any other failure.\n"
         ".SH ENVIRONMENT\n.TP\n.B CALDAQ_DB\nThe run database when \\-\\-db is not given "
         "(default ~/.local/share/caldaq/site.sqlite).\n";
  m += fmt::format(".SH SEE ALSO\n{}\n",
                   path.empty() ? "The documents in /usr/share/doc/caldaq." : "\\fBdaq\\fR(1)");
  return m;
}

void write_man_pages(const CLI::App& root, const fs::path& dir) {
  fs::create_directories(dir);
  const auto all = commands(root);
  const auto write = [&](const std::string& path, const CLI::App& app) {
    const fs::path file = dir / (page_name(path) + ".1");
    std::ofstream out(file);
    out << man_page(app, path, all);
    if (!out) throw cal::InputError(fmt::format("{}: cannot write", file.string()));
  };
  write("", root);
  for (const auto& [path, app] : all) write(path, *app);
  fmt::print("{} manual pages written to {}\n", all.size() + 1, dir.string());
}

// A static completion: for the command typed so far, its commands and options; files for the
// rest (-o default).
std::string bash_completion(const CLI::App& root) {
  const auto all = commands(root);
  const auto words = [](const CLI::App& app) {
    std::set<std::string> w;
    for (const CLI::App* sub : named(app)) {
      w.insert(sub->get_name());
      for (const auto& a : sub->get_aliases()) w.insert(a);
    }
    for (const CLI::Option* o : options_of(app)) {
      for (const auto& l : o->get_lnames()) w.insert("--" + l);
      for (const auto& s : o->get_snames()) w.insert("-" + s);
    }
    std::string text;
    for (const auto& x : w) text += (text.empty() ? "" : " ") + x;
    return text;
  };
  std::string known, cases = fmt::format("    '') words='{}' ;;\n", words(root));
  for (const auto& [path, app] : all) {
    known += fmt::format("      '{}') path='{}' ;;\n", path, path);
    for (const auto& a : app->get_aliases()) {
      const auto at = path.rfind(' ');
      const std::string alias = (at == std::string::npos ? "" : path.substr(0, at + 1)) + a;
      known += fmt::format("      '{}') path='{}' ;;\n", alias, path);
    }
    cases += fmt::format("    '{}') words='{}' ;;\n", path, words(*app));
  }
  return fmt::format(R"(# bash completion for daq (generated by `daq completion bash`)
_daq() {{
  local cur=${{COMP_WORDS[COMP_CWORD]}} path='' w i words=''
  for ((i = 1; i < COMP_CWORD; i++)); do
    w=${{COMP_WORDS[i]}}
    case "${{path:+$path }}$w" in
{}    esac
  done
  case "$path" in
{}  esac
  COMPREPLY=($(compgen -W "$words" -- "$cur"))
}}
complete -o default -F _daq daq
)",
                     known, cases);
}

}  // namespace

void add_docs_commands(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  CLI::App* man = app.add_subcommand(
      "man-pages", "Write the manual pages of daq and of each of its commands (troff, section 1)");
  man->add_option("DIR", *dir, "Directory to write daq.1, daq-report.1, ... into")->required();
  man->callback([man, dir] { write_man_pages(root_of(*man), *dir); });

  auto shell = std::make_shared<std::string>();
  CLI::App* completion =
      app.add_subcommand("completion",
                         "Print the shell completion script (source it, or install it as "
                         "/usr/share/bash-completion/completions/daq)");
  completion->add_option("SHELL", *shell, "The shell: bash")
      ->required()
      ->check(CLI::IsMember({"bash"}));
  completion->callback([completion, shell] {  // shell: alive while CLI11 writes into it
    fmt::print("{}", bash_completion(root_of(*completion)));
  });
}

}  // namespace daq
