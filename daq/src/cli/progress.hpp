#pragma once
// Progress of a long command for a person at a terminal: one line on stderr rewritten in
// place, nothing at all when stderr is not a terminal (a pipe, a file, a test), so that what
// is piped or logged is only the command's output.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

namespace daq {

// "0:07", "12:05", "1:02:03": a duration in seconds as a person reads it on a clock.
std::string clock_text(double seconds);

// The time left of a job `done` of `total` (any unit) after `elapsed_s`, at the rate so far;
// nullopt before there is a rate (nothing done) or when the total is not known.
std::optional<double> remaining_s(double elapsed_s, double done, double total);

class TerminalProgress {
 public:
  // `what` names the job ("export run 1"), `unit` the counted things ("readings"; empty: a
  // job that counts nothing, shown with its time alone); `total` 0 when not known. Shown only
  // when `enabled` and stderr is a terminal.
  TerminalProgress(std::string what, std::string unit, std::uint64_t total, bool enabled);
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;
  ~TerminalProgress();  // clears the line

  // Cheap enough for every row: the clock is read once in 4096 calls, the line redrawn at
  // most 5 times a second.
  void add(std::uint64_t n = 1) {
    done_ += n;
    if (shown_ && (++calls_ & 4095U) == 0) draw(false);
  }
  // A job that learns its total as it goes (a report knows what it reads once it has looked).
  void set_total(std::uint64_t total) { total_ = total; }
  // Redraws (at most 5 times a second): for a job waiting on something it cannot count.
  void tick() {
    if (shown_) draw(false);
  }
  // Erases the line (the next draw brings it back), for a line of output printed in its place.
  void clear();

 private:
  void draw(bool force);
  bool drawn_ = false;  // a line is on the terminal now
  std::string what_, unit_;
  std::uint64_t total_ = 0, done_ = 0, calls_ = 0;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace daq
