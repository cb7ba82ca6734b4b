// Every JSON input parsed with its depth bounded and its errors named (daq/src/json_input.hpp),
// and the values of `daq ballbar calibrate` checked (daq/src/bar_calibration_input.hpp).
#include "json_input.hpp"

#include <gtest/gtest.h>

#include <string>

#include "bar_calibration_input.hpp"
#include "cal/analysis/error.hpp"

namespace {

using cal::daq::parse_json_input;
using cal::daq::parse_stored_json;

std::string nested(std::size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); }

std::string error_of(std::string_view text) {
  try {
    parse_json_input(text, "in.json");
  } catch (const cal::InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(JsonInput, DepthIsBoundedWithLineAndByte) {
  EXPECT_EQ(parse_json_input(nested(64), "in.json").dump().size(), 128u);
  EXPECT_EQ(error_of(nested(65)), "in.json: line 1, byte 64: JSON nested deeper than 64 levels");
  EXPECT_EQ(error_of("{\n \"a\": " + nested(100000) + "}"),
            "in.json: line 2, byte 71: JSON nested deeper than 64 levels");
  // Brackets inside strings are text, not nesting (escaped quotes included).
  EXPECT_EQ(parse_json_input("[\"" + std::string(100, '[') + "\\\"\"]", "in.json").size(), 1u);
}

TEST(JsonInput, ErrorsNameTheInput) {
  EXPECT_EQ(error_of("{\"a\": 1,}").rfind("in.json: not valid JSON (parse error at line 1", 0), 0u)
      << error_of("{\"a\": 1,}");
  EXPECT_NE(error_of("{\"by\": \"M\xFCller\"}").find("in.json: not valid JSON"), std::string::npos);
  EXPECT_NE(error_of("[1e999]").find("in.json: not valid JSON"), std::string::npos);
}

TEST(JsonInput, StoredDocumentsTooDeepAreDiscarded) {
  EXPECT_TRUE(parse_stored_json(nested(100000)).is_discarded());
  EXPECT_TRUE(parse_stored_json("{").is_discarded());
  EXPECT_EQ(parse_stored_json("{\"a\": [1]}")["a"][0], 1);
}

TEST(JsonInput, OutputReplacesBytesThatAreNotUtf8) {
  const nlohmann::json j{{"by", "M\xFCller"}};
  EXPECT_THROW((void)j.dump(), nlohmann::json::type_error);
  EXPECT_EQ(cal::daq::dump_output(j), "{\"by\":\"M\xEF\xBF\xBDller\"}");
}

std::string calibration_error(daq::BarCalibrationInput in) {
  try {
    daq::check_bar_calibration(in, 1'795'000'000);  // 2026-11
  } catch (const cal::InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(BarCalibrationInput, AbsurdValuesAreRefusedWithTheReason) {
  const daq::BarCalibrationInput ok{.nominal_mm = 100, .calibrator_mm = 100, .reading_mm = 0};
  EXPECT_EQ(calibration_error(ok), "accepted");
  auto far = ok;
  far.nominal_mm = far.calibrator_mm = 1e300;
  EXPECT_NE(calibration_error(far).find("a bar is longer than 0 and at most 100 m"),
            std::string::npos);
  auto cold = ok;
  cold.temperature_degc = -300;
  EXPECT_NE(calibration_error(cold).find("--temperature-degc -300: outside -50 .. 100 degC"),
            std::string::npos);
  auto ancient = ok;
  ancient.date = "0026-01-05";
  EXPECT_NE(calibration_error(ancient).find("before 1990 or in the future"), std::string::npos);
  auto future = ok;
  future.date = "2027-01-05";
  EXPECT_NE(calibration_error(future).find("before 1990 or in the future"), std::string::npos);
  auto dated = ok;
  dated.date = "2026-01-05T08:30";
  EXPECT_EQ(daq::check_bar_calibration(dated, 1'795'000'000), 1'767'601'800'000);
}

}  // namespace
