#pragma once
// Text printed for a person at a terminal: every line that carries stored or foreign text
// (names, notes, device ids, drivers, transports, paths, a codec's quote of the bytes) goes
// through terminal_safe, so that control characters and ESC sequences in it are shown as
// escapes (\x1B) instead of acting on the terminal (cal/analysis/text.hpp).
#include <fmt/format.h>

#include <string>
#include <utility>

#include "cal/analysis/text.hpp"

namespace daq {

// One line (the format string without its "\n"), escaped for the terminal, then a newline.
template <class... Args>
void print_line(fmt::format_string<Args...> format, Args&&... args) {
  fmt::print("{}\n", cal::text::terminal_safe(fmt::format(format, std::forward<Args>(args)...)));
}

}  // namespace daq
