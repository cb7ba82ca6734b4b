// Named CSV columns (see csv_columns.hpp).
#include "csv_columns.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "cal/analysis/error.hpp"

namespace daq {
namespace {

std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) {
    const auto b = c.find_first_not_of(" \t\r"), e = c.find_last_not_of(" \t\r");
    cells.push_back(b == std::string::npos ? "" : c.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

}  // namespace

CsvColumns parse_csv_columns(std::string_view content, const std::string& source_name,
                             const std::vector<std::string>& numeric,
                             const std::vector<std::string>& text) {
  std::istringstream in{std::string(content)};
  std::string line;
  int n = 0;
  std::map<std::string, std::size_t> col;
  CsvColumns out;
  while (std::getline(in, line)) {
    ++n;
    if (line.find('\0') != std::string::npos)
      throw cal::InputError(fmt::format("{}:{}: a NUL byte: not a text CSV file", source_name, n));
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos)
      continue;
    const auto cells = cells_of(line);
    if (col.empty()) {
      for (std::size_t i = 0; i < cells.size(); ++i) col.emplace(cells[i], i);
      for (const auto* names : {&numeric, &text})
        for (const auto& name : *names)
          if (!col.count(name))
            throw cal::InputError(
                fmt::format("{}:{}: the header has no column {}", source_name, n, name));
      continue;
    }
    for (const auto& name : numeric) {
      const std::size_t i = col.at(name);
      const std::string cell = i < cells.size() ? cells[i] : "";
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (cell.empty() || *end != '\0' || !std::isfinite(v))
        throw cal::InputError(
            fmt::format("{}:{}: column {}: '{}' is not a number (a finite number is expected)",
                        source_name, n, name, cell));
      out.numbers[name].push_back(v);
    }
    for (const auto& name : text) {
      const std::size_t i = col.at(name);
      out.texts[name].push_back(i < cells.size() ? cells[i] : "");
    }
    out.line.push_back(n);
  }
  if (col.empty()) throw cal::InputError(fmt::format("{}: empty (no header line)", source_name));
  for (const auto& name : numeric) out.numbers[name];  // present even with no rows
  for (const auto& name : text) out.texts[name];
  return out;
}

CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& numeric,
                            const std::vector<std::string>& text) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw cal::InputError(fmt::format("{}: cannot open", path));
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_csv_columns(ss.str(), path, numeric, text);
}

}  // namespace daq
