#pragma once
// Named columns of a small CSV file with a header line, for the commands that read measured
// profiles, points or CMM data: columns in any order, extra columns ignored, '#' lines and blank
// lines skipped, cells trimmed. Numeric cells must be finite numbers.
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace daq {

struct CsvColumns {
  std::map<std::string, std::vector<double>> numbers;
  std::map<std::string, std::vector<std::string>> texts;
  std::vector<int> line;  // the file line of each row, for messages
  std::size_t rows() const { return line.size(); }
};

// Throws cal::InputError naming the file, the line and the column at fault (a missing column,
// a cell that is not a finite number, an unreadable file).
CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& numeric,
                            const std::vector<std::string>& text = {});
CsvColumns parse_csv_columns(std::string_view content, const std::string& source_name,
                             const std::vector<std::string>& numeric,
                             const std::vector<std::string>& text = {});

}  // namespace daq
