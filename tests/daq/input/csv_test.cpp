// The measurement CSV reader (csv_table.hpp), which every `daq analyse` input and `daq
// compensate` goes through: each silent misread of issue 15 is now an error naming the file
// and line, and the decimal comma is read only when asked for.
#include <gtest/gtest.h>

#include <fstream>

#include "cal/analysis/error.hpp"
#include "csv_table.hpp"
#include "measurement_csv.hpp"

namespace {

using daq::CsvOptions;
using daq::CsvTable;
using daq::parse_decimal;

std::string error_of(std::string_view text, CsvOptions o = {}) {
  try {
    const auto t = CsvTable::parse(text, "in.csv", o);
    for (std::size_t r = 0; r < t.rows(); ++r) t.number(r, "deviation_um");
  } catch (const cal::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Csv, PlainDecimalsOnly) {
  EXPECT_EQ(parse_decimal("1.5"), 1.5);
  EXPECT_EQ(parse_decimal("-0.25e-3"), -0.25e-3);
  EXPECT_EQ(parse_decimal("+4"), 4.0);
  EXPECT_EQ(parse_decimal(".5"), 0.5);
  EXPECT_EQ(parse_decimal("5."), 5.0);
  EXPECT_EQ(parse_decimal("4,000", true), 4.0);  // the decimal comma, when asked for
  for (const char* bad : {"", "-", ".", "1.5abc", "0x10", "0x1p3", "inf", "nan", "Infinity", "1e",
                          "1e+", "1.2.3", "1 000", "1,5", "--1", "1e999", " 1"})
    EXPECT_EQ(parse_decimal(bad), std::nullopt) << bad;
  EXPECT_EQ(parse_decimal(std::string_view("1.5\0"
                                           "7",
                                           5)),
            std::nullopt);                                // embedded NUL
  EXPECT_EQ(parse_decimal("4.000", true), std::nullopt);  // a point in a comma file
}

TEST(Csv, ExtraCellsAreRefusedNotIgnored) {
  // A decimal-comma file read as points: "0,4,000" is three cells under a two-column header.
  // Before: the third cell was ignored and the deviation read as 4 -> 0 um of straightness.
  EXPECT_EQ(error_of("position_mm,deviation_um\n0,0,000\n100,4,000\n"),
            "in.csv:2: 3 cells, the header (line 1) has 2 columns (a decimal comma? give "
            "--decimal-comma and separate the cells by ';')");
  EXPECT_EQ(error_of("position_mm,deviation_um\n0,1\n100\n"),
            "in.csv:3: 1 cells, the header (line 1) has 2 columns (a decimal comma? give "
            "--decimal-comma and separate the cells by ';')");
  // Asked for, the same data reads as the numbers they are.
  const auto t = CsvTable::parse("position_mm;deviation_um\n0;0,000\n100;4,000\n", "in.csv",
                                 {.decimal_comma = true});
  EXPECT_EQ(t.numbers("deviation_um"), (std::vector<double>{0.0, 4.0}));
}

TEST(Csv, GarbageHexAndNulsAreRefusedWithFileAndLine) {
  EXPECT_EQ(error_of("position_mm,deviation_um\n0,1.5abc\n"),
            "in.csv:2: column deviation_um: '1.5abc' is not a number");
  EXPECT_EQ(error_of("position_mm,deviation_um\n# comment\n\n0,0x1A\n"),
            "in.csv:4: column deviation_um: '0x1A' is not a number");
  constexpr char with_nul[] =
      "position_mm,deviation_um\n0,1.5\0"
      "99\n";
  EXPECT_EQ(error_of(std::string(with_nul, sizeof with_nul - 1)),
            "in.csv:2: column deviation_um: '1.5\\x0099' is not a number");
  EXPECT_EQ(error_of("position_mm,deviation_um\r\n0,nan\r\n"),
            "in.csv:2: column deviation_um: 'nan' is not a number");
  EXPECT_EQ(error_of("position_mm,deviation_um\n0,1e999\n"),
            "in.csv:2: column deviation_um: '1e999' is not a number");
  EXPECT_EQ(error_of("position_mm,position_mm\n"),
            "in.csv:1: the header names column 'position_mm' twice");
  EXPECT_EQ(error_of(""), "in.csv: empty file, no header line");
  EXPECT_EQ(error_of("a,b\n1,2\n"),
            "in.csv:1: the header has no column 'deviation_um' (it has: "
            "a, b)");
}

TEST(Csv, TheMeasurementFileToo) {
  // The ISO 230-2 columns through the same reader: extra named columns are fine, extra cells
  // are not; a run number must be a plain positive integer.
  const auto m = daq::parse_measurements(
      "target_mm,run,direction,deviation_um,note\n0,1,up,1.25,x\n0,1,down,-0.5,y\n", "m.csv");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[1].deviation_um, -0.5);
  auto err = [](std::string_view text) {
    try {
      daq::parse_measurements(text, "m.csv");
    } catch (const cal::InputError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(err("target_mm,run,direction,deviation_um\n0,1,up,1,25\n"),
            "m.csv:2: 5 cells, the header (line 1) has 4 columns (a decimal comma? give "
            "--decimal-comma and separate the cells by ';')");
  EXPECT_EQ(err("target_mm,run,direction,deviation_um\n0,0x1,up,1\n"),
            "m.csv:2: column run: '0x1' is not a run number >= 1");
  EXPECT_EQ(err("target_mm,run,direction,deviation_um\n0,1,sideways,1\n"),
            "m.csv:2: column direction: 'sideways' is not up or down");
}

TEST(Csv, FilesAreBoundedAndDevicesToo) {
  // /dev/zero has no end and no line break: the reader stops at its limit with an error.
  try {
    CsvTable::read("/dev/zero", {.max_bytes = 1 << 20});
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_STREQ(e.what(), "/dev/zero: over the 1 MiB limit of a measurement file");
  }
  EXPECT_THROW(CsvTable::read("/nonexistent/in.csv"), cal::InputError);
}

}  // namespace
