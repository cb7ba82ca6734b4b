// Named CSV columns (see csv_columns.hpp), on the strict reader of csv_table.hpp.
#include "csv_columns.hpp"

#include <fmt/format.h>

#include "cal/analysis/error.hpp"

namespace daq {
namespace {

CsvColumns columns(const CsvTable& t, const std::vector<std::string>& numeric,
                   const std::vector<std::string>& text) {
  for (const auto* names : {&numeric, &text})
    for (const auto& name : *names) t.require({name});
  // A header and nothing else is an empty measurement, not one that passes every check.
  if (t.rows() == 0)
    throw cal::InputError(
        fmt::format("{}:{}: a header and no rows of data", t.source(), t.header_line()));
  CsvColumns out;
  for (const auto& name : numeric) out.numbers[name] = t.numbers(name);
  for (const auto& name : text) {
    auto& cells = out.texts[name];
    for (std::size_t r = 0; r < t.rows(); ++r) cells.emplace_back(t.text(r, name));
  }
  for (std::size_t r = 0; r < t.rows(); ++r) out.line.push_back(static_cast<int>(t.line(r)));
  return out;
}

}  // namespace

CsvColumns parse_csv_columns(std::string_view content, const std::string& source_name,
                             const std::vector<std::string>& numeric,
                             const std::vector<std::string>& text, const CsvOptions& options) {
  return columns(CsvTable::parse(content, source_name, options), numeric, text);
}

CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& numeric,
                            const std::vector<std::string>& text, const CsvOptions& options) {
  return columns(CsvTable::read(path, options), numeric, text);
}

}  // namespace daq
