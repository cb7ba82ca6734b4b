// The strict measurement CSV reader (see csv_table.hpp).
#include "csv_table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>

#include "cal/analysis/error.hpp"

namespace daq {
namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

bool digit(char c) { return c >= '0' && c <= '9'; }

// Shows a cell in a message: control bytes (a NUL, say) as \xNN, long cells cut.
std::string shown(std::string_view s) {
  std::string out;
  for (unsigned char c : s.substr(0, 40)) {
    if (c < 0x20 || c == 0x7f)
      out += fmt::format("\\x{:02x}", c);
    else
      out += static_cast<char>(c);
  }
  return s.size() > 40 ? out + "..." : out;
}

}  // namespace

std::optional<double> parse_decimal(std::string_view s, bool decimal_comma) {
  const char point = decimal_comma ? ',' : '.';
  std::string plain;  // what from_chars reads: always with a '.'
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) plain += s[i++] == '-' ? "-" : "";
  std::size_t digits = 0;
  for (; i < s.size() && digit(s[i]); ++i, ++digits) plain += s[i];
  if (i < s.size() && s[i] == point) {
    plain += '.';
    for (++i; i < s.size() && digit(s[i]); ++i, ++digits) plain += s[i];
  }
  if (digits == 0) return std::nullopt;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    plain += 'e';
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) plain += s[i++];
    std::size_t exponent_digits = 0;
    for (; i < s.size() && digit(s[i]); ++i, ++exponent_digits) plain += s[i];
    if (exponent_digits == 0) return std::nullopt;
  }
  if (i != s.size()) return std::nullopt;  // trailing text, a NUL, a second point ...
  double v = 0;
  const auto [end, ec] = std::from_chars(plain.data(), plain.data() + plain.size(), v);
  if (ec != std::errc{} || end != plain.data() + plain.size() || !std::isfinite(v))
    return std::nullopt;  // out of range (1e999) included
  return v;
}

CsvTable CsvTable::read(const std::string& path, const CsvOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw cal::InputError(fmt::format("{}: cannot open: {}", path, std::strerror(errno)));
  std::string text;
  std::array<char, 1 << 16> buffer{};
  // Read in pieces up to the limit: a device file (/dev/zero) has no size to ask for.
  while (in.read(buffer.data(), buffer.size()) || in.gcount() > 0) {
    text.append(buffer.data(), static_cast<std::size_t>(in.gcount()));
    if (text.size() > options.max_bytes)
      throw cal::InputError(fmt::format("{}: over the {} MiB limit of a measurement file", path,
                                        options.max_bytes >> 20));
  }
  if (in.bad()) throw cal::InputError(fmt::format("{}: read error", path));
  return parse(text, path, options);
}

CsvTable CsvTable::parse(std::string_view text, const std::string& name,
                         const CsvOptions& options) {
  if (text.size() > options.max_bytes || text.size() > UINT32_MAX)
    throw cal::InputError(fmt::format("{}: over the {} MiB limit of a measurement file", name,
                                      options.max_bytes >> 20));
  CsvTable t;
  t.source_ = name;
  t.options_ = options;
  t.text_ = std::make_unique<std::string>(text);
  const std::string& all = *t.text_;
  const char separator = options.decimal_comma ? ';' : ',';
  std::vector<Cell> row;
  std::size_t line_no = 0;
  for (std::size_t start = 0; start < all.size();) {
    const std::size_t eol = std::min(all.find('\n', start), all.size());
    ++line_no;
    std::size_t b = start, e = eol;
    while (b < e && blank(all[b])) ++b;
    while (e > b && blank(all[e - 1])) --e;
    start = eol + 1;
    if (b == e || all[b] == '#') continue;
    row.clear();
    for (std::size_t c = b;;) {
      const std::size_t sep = std::min(all.find(separator, c), e);
      std::size_t cb = c, ce = sep;
      while (cb < ce && blank(all[cb])) ++cb;
      while (ce > cb && blank(all[ce - 1])) --ce;
      row.push_back({static_cast<std::uint32_t>(cb), static_cast<std::uint32_t>(ce - cb)});
      if (sep >= e) break;
      c = sep + 1;
    }
    if (t.columns_.empty()) {
      t.header_line_ = line_no;
      for (const auto& c : row) {
        std::string col = all.substr(c.begin, c.size);
        if (std::find(t.columns_.begin(), t.columns_.end(), col) != t.columns_.end())
          throw cal::InputError(
              fmt::format("{}:{}: the header names column '{}' twice", name, line_no, shown(col)));
        t.columns_.push_back(std::move(col));
      }
      continue;
    }
    if (row.size() != t.columns_.size())
      throw cal::InputError(fmt::format(
          "{}:{}: {} cells, the header (line {}) has {} columns{}", name, line_no, row.size(),
          t.header_line_, t.columns_.size(),
          options.decimal_comma
              ? ""
              : " (a decimal comma? give --decimal-comma and separate the cells by ';')"));
    t.cells_.insert(t.cells_.end(), row.begin(), row.end());
    t.lines_.push_back(line_no);
  }
  if (t.columns_.empty())
    throw cal::InputError(fmt::format("{}: empty file, no header line", name));
  return t;
}

bool CsvTable::has(std::string_view column) const {
  return std::find(columns_.begin(), columns_.end(), column) != columns_.end();
}

void CsvTable::require(std::initializer_list<std::string_view> columns) const {
  for (const auto c : columns) index(c);
}

std::size_t CsvTable::index(std::string_view column) const {
  const auto it = std::find(columns_.begin(), columns_.end(), column);
  if (it == columns_.end())
    throw cal::InputError(fmt::format("{}:{}: the header has no column '{}' (it has: {})", source_,
                                      header_line_, column, fmt::join(columns_, ", ")));
  return static_cast<std::size_t>(it - columns_.begin());
}

std::string_view CsvTable::cell(std::size_t row, std::size_t column) const {
  const Cell& c = cells_[row * columns_.size() + column];
  return std::string_view(*text_).substr(c.begin, c.size);
}

std::string_view CsvTable::text(std::size_t row, std::string_view column) const {
  return cell(row, index(column));
}

double CsvTable::number(std::size_t row, std::string_view column) const {
  const auto s = text(row, column);
  if (const auto v = parse_decimal(s, options_.decimal_comma)) return *v;
  fail(row, fmt::format("column {}: '{}' is not a number{}", column, shown(s),
                        options_.decimal_comma ? " (decimal comma expected)" : ""));
}

std::vector<double> CsvTable::numbers(std::string_view column) const {
  std::vector<double> out;
  out.reserve(rows());
  for (std::size_t r = 0; r < rows(); ++r) out.push_back(number(r, column));
  return out;
}

void CsvTable::fail(std::size_t row, const std::string& what) const {
  throw cal::InputError(fmt::format("{}:{}: {}", source_, lines_[row], what));
}

}  // namespace daq
