// Progress of a long command on a terminal (see progress.hpp).
#include "progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>

namespace daq {

std::string clock_text(double seconds) {
  const auto s = static_cast<std::int64_t>(std::llround(std::max(seconds, 0.0)));
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60);
  return fmt::format("{}:{:02}", s / 60, s % 60);
}

std::optional<double> remaining_s(double elapsed_s, double done, double total) {
  if (done <= 0 || total <= 0 || elapsed_s <= 0) return std::nullopt;
  return std::max(total - done, 0.0) * elapsed_s / done;
}

TerminalProgress::TerminalProgress(std::string what, std::string unit, std::uint64_t total,
                                   bool enabled)
    : what_(std::move(what)),
      unit_(std::move(unit)),
      total_(total),
      shown_(enabled && ::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {
  if (shown_) draw(true);  // at once: the person sees what runs before the first rate
}

TerminalProgress::~TerminalProgress() { clear(); }

void TerminalProgress::clear() {
  if (!drawn_) return;
  fmt::print(stderr, "\r\033[K");
  std::fflush(stderr);
  drawn_ = false;
}

void TerminalProgress::draw(bool force) {
  const auto now = std::chrono::steady_clock::now();
  if (!force && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const auto done = static_cast<double>(done_), total = static_cast<double>(total_);
  std::string line = unit_.empty() ? what_ : fmt::format("{}: {} {}", what_, done_, unit_);
  if (total_ > 0 && !unit_.empty())
    line = fmt::format("{}: {:3.0f} % ({} of {} {})", what_, 100.0 * done / total, done_, total_,
                       unit_);
  line += fmt::format(", {} elapsed", clock_text(elapsed));
  if (const auto left = remaining_s(elapsed, done, total))
    line += fmt::format(", about {} left", clock_text(*left));
  fmt::print(stderr, "\r\033[K{}", line);
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace daq
