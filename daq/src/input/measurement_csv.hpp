#pragma once
// The positional-deviation CSV of `daq analyse iso230-2` and `daq compensate --input`
// (documented in docs/cli.md):
//   target_mm,run,direction,deviation_um
//   0.000,1,up,1.25
// Header required (columns in any order, further named columns ignored); every row has as
// many cells as the header; direction is up/down (also +/-, forward/backward); lines
// starting with '#' and blank lines are skipped. Read by the strict CsvTable (csv_table.hpp).
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/iso230_2.hpp"
#include "csv_table.hpp"

namespace daq {

// Throws cal::InputError naming the file, line and column at fault.
std::vector<cal::iso230_2::Measurement> parse_measurements(std::string_view text,
                                                           const std::string& source_name,
                                                           const CsvOptions& options = {});
std::vector<cal::iso230_2::Measurement> read_measurements(const std::string& path,
                                                          const CsvOptions& options = {});

}  // namespace daq
