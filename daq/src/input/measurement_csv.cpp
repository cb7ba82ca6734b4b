#include "measurement_csv.hpp"

#include <fmt/format.h>

#include <charconv>

#include "cal/analysis/error.hpp"

namespace daq {
namespace {

int run_number(const CsvTable& t, std::size_t row) {
  const auto s = t.text(row, "run");
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || v < 1)
    t.fail(row, fmt::format("column run: '{}' is not a run number >= 1", s.substr(0, 40)));
  return v;
}

cal::iso230_2::Direction direction(const CsvTable& t, std::size_t row) {
  const auto s = t.text(row, "direction");
  if (s == "up" || s == "+" || s == "forward" || s == "fwd") return cal::iso230_2::Direction::up;
  if (s == "down" || s == "-" || s == "backward" || s == "bwd" || s == "reverse")
    return cal::iso230_2::Direction::down;
  t.fail(row, fmt::format("column direction: '{}' is not up or down", s.substr(0, 40)));
}

std::vector<cal::iso230_2::Measurement> measurements(const CsvTable& t) {
  t.require({"target_mm", "run", "direction", "deviation_um"});
  if (t.rows() == 0)
    throw cal::InputError(fmt::format("{}: header but no measurements", t.source()));
  std::vector<cal::iso230_2::Measurement> out;
  for (std::size_t r = 0; r < t.rows(); ++r)
    out.push_back(
        {t.number(r, "target_mm"), run_number(t, r), direction(t, r), t.number(r, "deviation_um")});
  return out;
}

}  // namespace

std::vector<cal::iso230_2::Measurement> parse_measurements(std::string_view text,
                                                           const std::string& name,
                                                           const CsvOptions& options) {
  return measurements(CsvTable::parse(text, name, options));
}

std::vector<cal::iso230_2::Measurement> read_measurements(const std::string& path,
                                                          const CsvOptions& options) {
  return measurements(CsvTable::read(path, options));
}

}  // namespace daq
