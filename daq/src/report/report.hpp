#pragma once
// Self-contained HTML reports of stored runs (plots inlined as SVG, no external resources, so
// the file opens offline and prints to PDF): one run, a campaign of runs, or a comparison of
// the same test over time. Content and layout: docs/reports.md.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace cal::storage {
class Store;
}

namespace cal::daq::report {

struct Options {
  // Linear runs: evaluate by this standard (a key of daq analyse --standard); empty: the
  // standard the run was made for.
  std::string standard;
  std::string software = "daq";  // named in the footer
};

// Each throws cal::InputError naming the database and run for an unknown run, a run without
// the data its report needs, or (comparison) runs of different tests.
std::string run_report(const storage::Store& store, std::int64_t run, const Options& o = {});
std::string campaign_report(const storage::Store& store, std::span<const std::int64_t> runs,
                            std::string_view title, const Options& o = {});
std::string comparison_report(const storage::Store& store, std::span<const std::int64_t> runs,
                              const Options& o = {});

}  // namespace cal::daq::report
