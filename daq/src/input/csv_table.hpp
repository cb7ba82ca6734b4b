#pragma once
// The one reader of the measurement CSV files (`daq analyse iso230-2|circle|straightness|
// squareness`, `daq compensate --input|--straightness`): a header line naming the columns,
// then one row per line. Strict, because a misread here is a wrong calibration:
// - every row has exactly as many cells as the header (so a decimal-comma file, whose
//   "4,000" splits into two cells, is refused instead of read as 4);
// - numbers are plain decimals: [+-]digits[.digits][(e|E)[+-]digits]; no hex, no inf/nan,
//   no trailing garbage, no embedded NUL;
// - a decimal comma only with CsvOptions::decimal_comma, and then cells are separated by ';';
// - '#' lines and blank lines are skipped; cells are trimmed of blanks; CR-LF is accepted;
// - the file is at most max_bytes (reading /dev/zero ends with an error, not a full memory).
// Every error names the file and the line (and the column where one is at fault).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace daq {

struct CsvOptions {
  bool decimal_comma = false;
  std::size_t max_bytes = std::size_t{256} << 20;
};

class CsvTable {
 public:
  // Throws cal::InputError: cannot open, over max_bytes, no header, a row with another
  // number of cells than the header, a column named twice.
  static CsvTable read(const std::string& path, const CsvOptions& options = {});
  static CsvTable parse(std::string_view text, const std::string& source_name,
                        const CsvOptions& options = {});

  bool has(std::string_view column) const;
  // Throws cal::InputError naming the file and the header's line if the column is missing.
  void require(std::initializer_list<std::string_view> columns) const;
  std::size_t rows() const { return lines_.size(); }
  std::size_t line(std::size_t row) const { return lines_[row]; }  // 1-based line in the file
  const std::string& source() const { return source_; }
  std::size_t header_line() const { return header_line_; }

  std::string_view text(std::size_t row, std::string_view column) const;
  // A finite number; throws cal::InputError "FILE:LINE: column NAME: 'TEXT' is not a number".
  double number(std::size_t row, std::string_view column) const;
  // All of a column's numbers.
  std::vector<double> numbers(std::string_view column) const;
  // InputError "FILE:LINE: WHAT" for the row.
  [[noreturn]] void fail(std::size_t row, const std::string& what) const;

 private:
  struct Cell {  // a trimmed cell of text_: 8 bytes per cell, whatever its length
    std::uint32_t begin = 0, size = 0;
  };
  std::size_t index(std::string_view column) const;
  std::string_view cell(std::size_t row, std::size_t column) const;
  std::string source_;
  CsvOptions options_;
  std::unique_ptr<std::string> text_;  // owned apart, so that moving the table keeps the cells
  std::size_t header_line_ = 0;
  std::vector<std::string> columns_;
  std::vector<Cell> cells_;  // rows x columns_, row-major
  std::vector<std::size_t> lines_;
};

// The strict number syntax above; nullopt when `text` is not such a number or not finite.
std::optional<double> parse_decimal(std::string_view text, bool decimal_comma = false);

}  // namespace daq
