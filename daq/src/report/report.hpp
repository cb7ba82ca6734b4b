#pragma once
// Self-contained HTML reports of stored runs (plots inlined as SVG, no external resources, so
// the file opens offline and prints to PDF): one run, a campaign of runs, or a comparison of
// the same test over time. Content and layout: docs/reports.md.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cal::storage {
class RunReader;
}

namespace cal::daq::report {

struct Options {
  // Linear runs: evaluate by this standard (a key of daq analyse --standard); empty: the
  // standard the run was made for.
  std::string standard;
  std::string software = "daq";  // named in the footer
  // Told, after each batch, how many of a long run's readings have been read for its plots
  // and how many there are to read (daq report's progress on a terminal). Empty: not told.
  std::function<void(std::uint64_t done, std::uint64_t total)> reading_progress;
  // The version of the run's stops the store reads (daq report RUN --version N on the central
  // store); 0: the current one. Named on page one when the run has more than one.
  int version = 0;
};

// Each throws cal::InputError naming the database and run for an unknown run, a run without
// the data its report needs, or (comparison) runs of different tests.
std::string run_report(const storage::RunReader& store, std::int64_t run, const Options& o = {});
std::string campaign_report(const storage::RunReader& store, std::span<const std::int64_t> runs,
                            std::string_view title, const Options& o = {});
std::string comparison_report(const storage::RunReader& store, std::span<const std::int64_t> runs,
                              const Options& o = {});
// The same test before ("as found") and after ("as left") a compensation, side by side, then
// both runs' reports.
std::string as_found_as_left_report(const storage::RunReader& store, std::int64_t found,
                                    std::int64_t left, const Options& o = {});

// The compensation loop (daq verify): the as-left run against the compensation table written
// before it (the newest of its machine and axis, or the one given): the verdict and the
// as-found, expected and as-left deviations on page one, the change point by point, then both
// runs' reports. cal::InputError when there is no compensation to check the run against.
std::string verification_report(const storage::RunReader& store, std::int64_t run,
                                std::optional<std::int64_t> compensation, const Options& o = {});

// Straightness and squareness are analysed from measured profiles (CSV files, not stored
// runs): the report shows the deviations with the ISO 230-1 reference lines.
struct Profile {
  std::string source;  // the file it came from
  std::vector<double> position_mm, deviation_um;
};
// All three reference lines (least squares, end point, minimum zone).
std::string straightness_report(const Profile& p, const Options& o = {});
// Two straightness runs against one square: A moving (deviation in +B), B moving (in +A).
std::string squareness_report(const Profile& along_a, const Profile& along_b,
                              double square_error_um_per_m, const Options& o = {});

}  // namespace cal::daq::report
