#pragma once
// Named columns of a small CSV file with a header line, for the commands that read measured
// profiles, points or CMM data: columns in any order, extra named columns ignored, '#' lines
// and blank lines skipped, cells trimmed. Read by the one strict reader (csv_table.hpp): every
// row has as many cells as the header, numeric cells are finite plain decimals (no hex, nan,
// inf, NUL or trailing text), decimal commas only with CsvOptions::decimal_comma.
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "csv_table.hpp"

namespace daq {

struct CsvColumns {
  std::map<std::string, std::vector<double>> numbers;
  std::map<std::string, std::vector<std::string>> texts;
  std::vector<int> line;  // the file line of each row, for messages
  std::size_t rows() const { return line.size(); }
};

// Throws cal::InputError naming the file, the line and the column at fault (a missing column,
// no rows of data, a cell that is not a finite number, a row with another number of cells than
// the header, an unreadable or oversized file).
CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& numeric,
                            const std::vector<std::string>& text = {},
                            const CsvOptions& options = {});
CsvColumns parse_csv_columns(std::string_view content, const std::string& source_name,
                             const std::vector<std::string>& numeric,
                             const std::vector<std::string>& text = {},
                             const CsvOptions& options = {});

}  // namespace daq
