// Attocube IDS3010 JSON-RPC codec: requests as attocube's own wrappers write them, answers as
// the device sends them (result[0] the error code, displacements in picometres), then every
// kind of bad answer. Expected values by hand in the comments.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "codec_test_util.hpp"
#include "ids3010/codec.hpp"

namespace {

using namespace cal::drivers::codec;

TEST(IdsCodec, RequestsCarryTheMethodParamsAndIncreasingIds) {
  IdsCodec c;
  const auto a = nlohmann::json::parse(c.encode(IdsMethod::get_axes_displacement));
  EXPECT_EQ(a["jsonrpc"], "2.0");
  EXPECT_EQ(a["method"], "com.attocube.ids.displacement.getAxesDisplacement");
  EXPECT_EQ(a["params"], nlohmann::json::array());
  EXPECT_EQ(a["id"], 1);
  const IdsParam axis[] = {std::int64_t{2}};
  const auto line = c.encode(IdsMethod::get_axis_displacement, axis);
  EXPECT_EQ(line.back(), '\n');  // newline-terminated, one object per line
  const auto b = nlohmann::json::parse(line);
  EXPECT_EQ(b["method"], "com.attocube.ids.displacement.getAxisDisplacement");
  EXPECT_EQ(b["params"], nlohmann::json::array({2}));
  EXPECT_EQ(b["id"], 2);
  EXPECT_EQ(c.pending(), 2u);
  EXPECT_EQ(method_name(IdsMethod::ecu_get_pressure), "com.attocube.ecu.getPressureInHPa");
  const IdsParam bad_axis[] = {std::int64_t{3}};
  EXPECT_THROW(c.encode(IdsMethod::get_axis_displacement, bad_axis), cal::InputError);
  EXPECT_THROW(c.encode(IdsMethod::get_axes_displacement, axis), cal::InputError);  // no params
}

TEST(IdsCodec, DisplacementsInPicometresBecomeMetres) {
  IdsCodec c;
  c.encode(IdsMethod::get_axes_displacement);
  std::vector<IdsResponse> frames;
  std::vector<CodecError> errors;
  // 123456789012 pm = 0.123456789012 m; -4567890 pm = -4.56789 um.
  c.feed(R"({"jsonrpc":"2.0","result":[0,123456789012,-4567890,0],"id":1})"
         "\n",
         frames, errors);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_TRUE(errors.empty());
  EXPECT_EQ(frames[0].error_code, 0);
  EXPECT_DOUBLE_EQ(*frames[0].displacement_m[0], 0.123456789012);
  EXPECT_DOUBLE_EQ(*frames[0].displacement_m[1], -4.56789e-6);
  EXPECT_DOUBLE_EQ(*frames[0].displacement_m[2], 0.0);
  EXPECT_EQ(c.pending(), 0u);
}

TEST(IdsCodec, EnvironmentUnitModeAndFlags) {
  IdsCodec c;
  c.encode(IdsMethod::ecu_get_temperature);       // id 1
  c.encode(IdsMethod::ecu_get_pressure);          // id 2
  c.encode(IdsMethod::ecu_get_humidity);          // id 3
  c.encode(IdsMethod::ecu_get_refractive_index);  // id 4
  c.encode(IdsMethod::get_current_mode);          // id 5
  c.encode(IdsMethod::ecu_get_connected);         // id 6
  // Answers out of order, matched by id. 1013.25 hPa = 101325 Pa.
  const auto d = codec_test::feed_whole(
      std::move(c), R"({"jsonrpc":"2.0","result":[0,1013.25],"id":2})"
                    "\n"
                    R"({"jsonrpc":"2.0","result":[0,20.5],"id":1})"
                    "\n"
                    R"({"jsonrpc":"2.0","result":[0,45.0],"id":3})"
                    "\n"
                    R"({"jsonrpc":"2.0","result":[0,1.000271],"id":4})"
                    "\n"
                    R"({"jsonrpc":"2.0","result":[0,"measurement running"],"id":5})"
                    "\n"
                    R"({"jsonrpc":"2.0","result":[0,true],"id":6})"
                    "\n");
  ASSERT_EQ(d.frames.size(), 6u);
  EXPECT_DOUBLE_EQ(*d.frames[0].pressure_pa, 101325.0);
  EXPECT_EQ(d.frames[1].method, IdsMethod::ecu_get_temperature);
  EXPECT_DOUBLE_EQ(*d.frames[1].temperature_degc, 20.5);
  EXPECT_DOUBLE_EQ(*d.frames[2].humidity_pct_rh, 45.0);
  EXPECT_DOUBLE_EQ(*d.frames[3].refractive_index, 1.000271);
  EXPECT_EQ(d.frames[4].mode, "measurement running");
  EXPECT_EQ(d.frames[5].flag, true);
}

TEST(IdsCodec, DeviceErrorsAreAnswersNotCodecErrors) {
  IdsCodec c;
  c.encode(IdsMethod::get_axes_displacement);
  c.encode(IdsMethod::start_measurement);
  const auto d = codec_test::feed_whole(
      std::move(c),
      R"({"jsonrpc":"2.0","result":[7],"id":1})"  // beam lost: no values
      "\n"
      R"({"jsonrpc":"2.0","error":{"code":-32601,"message":"Method not found"},"id":2})"
      "\n");
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_EQ(d.frames[0].error_code, 7);
  EXPECT_FALSE(d.frames[0].displacement_m[0]);
  EXPECT_EQ(d.frames[1].error_code, -32601);
  EXPECT_EQ(d.frames[1].error_message, "Method not found");
  EXPECT_EQ(d.stats.errors(), 0u);
}

TEST(IdsCodec, BadAnswersAreCountedByKindAndNamed) {
  IdsCodec c;
  for (int i = 0; i < 5; ++i) c.encode(IdsMethod::get_axes_displacement);  // ids 1..5
  c.encode(IdsMethod::ecu_get_pressure);                                   // id 6
  const auto d = codec_test::feed_whole(
      std::move(c),
      "not json\n"                                       // malformed
      "{\"id\":1,\"result\":[0,1,2,3]}\x01\n"            // control byte: garbage
      R"({"jsonrpc":"2.0","result":[0,1,2,3],"id":99})"  // unknown id
      "\n"
      R"({"jsonrpc":"2.0","result":[0,1,2],"id":2})"  // 2 values of 3
      "\n"
      R"({"jsonrpc":"2.0","result":[0,"x",2,3],"id":3})"  // not a number
      "\n"
      R"({"jsonrpc":"2.0","result":[0,20000000000000,0,0],"id":4})"  // 20 m > 10 m
      "\n"
      R"({"jsonrpc":"2.0","result":[0,2000.0],"id":6})"  // 2000 hPa
      "\n"
      R"({"jsonrpc":"2.0","result":[0,5,6,7],"id":5})"  // good
      "\n");
  EXPECT_EQ(d.stats.garbage, 1u);
  EXPECT_EQ(d.stats.malformed, 4u);
  EXPECT_EQ(d.stats.out_of_range, 2u);
  // The out-of-range answers still come as frames, without the refused value.
  ASSERT_EQ(d.frames.size(), 4u);
  EXPECT_DOUBLE_EQ(*d.frames.back().displacement_m[2], 7e-12);
  bool named = false;
  for (const auto& e : d.errors)
    named |= e.description.find("response id 99 matches no pending request") != std::string::npos;
  EXPECT_TRUE(named);
}

TEST(IdsCodec, SplitAtAnyByteAndReplayedRequests) {
  const std::string answers = R"({"jsonrpc":"2.0","result":[0,1000,2000,3000],"id":1})"
                              "\n"
                              R"({"jsonrpc":"2.0","result":[0,20.5],"id":2})"
                              "\n";
  auto make = [] {
    IdsCodec c;
    c.encode(IdsMethod::get_axes_displacement);
    c.encode(IdsMethod::ecu_get_temperature);
    return c;
  };
  const auto whole = codec_test::feed_whole(make(), answers);
  const auto bytewise = codec_test::feed_bytewise(make(), answers);
  ASSERT_EQ(bytewise.frames.size(), 2u);
  EXPECT_EQ(whole.stats, bytewise.stats);
  EXPECT_DOUBLE_EQ(*bytewise.frames[0].displacement_m[2], 3e-9);
  // Replay: the codec learns the recorded requests from the bytes that were sent.
  IdsCodec replay;
  IdsCodec live;
  std::string sent = live.encode(IdsMethod::get_axes_displacement);  // id 1, then id 2:
  sent += live.encode(IdsMethod::ecu_get_temperature);               // two statements fix the order
  replay.note_requests(as_bytes(sent));
  EXPECT_EQ(replay.pending(), 2u);
  std::vector<IdsResponse> frames;
  replay.feed(answers, frames);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].method, IdsMethod::ecu_get_temperature);
}

TEST(IdsCodec, PendingRequestsAreBounded) {
  IdsCodec c;
  for (std::size_t i = 0; i < IdsCodec::max_pending + 10; ++i)
    c.encode(IdsMethod::get_axes_displacement);
  EXPECT_EQ(c.pending(), IdsCodec::max_pending);
  std::vector<IdsResponse> frames;
  c.feed(R"({"jsonrpc":"2.0","result":[0,1,2,3],"id":1})"
         "\n",
         frames);  // the oldest were forgotten: id 1 no longer matches
  EXPECT_TRUE(frames.empty());
  EXPECT_EQ(c.stats().malformed, 1u);
}

// An answered request's map node is used again for the next request (issue 32): a request
// noted again under an id still pending replaces the first (the answer is read as the second
// method's), and the bound still forgets the oldest.
TEST(IdsCodec, ReusedRequestNodesKeepTheLastRequestOfAnId) {
  IdsCodec c;
  const auto request = [](std::string_view method, int id) {
    return fmt::format(
        R"({{"jsonrpc":"2.0","method":"com.attocube.{}","params":[],"id":{},"api":2}})"
        "\n",
        method, id);
  };
  const auto note = [&](std::string_view method, int id) {
    const std::string line = request(method, id);
    c.note_requests(std::as_bytes(std::span(line)));
  };
  std::vector<IdsResponse> frames;
  note("sen.displacement.getAxesDisplacement", 1);
  c.feed(R"({"jsonrpc":"2.0","result":[0,1000,2000,3000],"id":1})"
         "\n",
         frames);  // answered: its node is kept for the next request
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(c.pending(), 0u);
  note("ecu.getTemperatureInDegrees", 2);  // into the kept node
  note("sen.displacement.getAxesDisplacement", 9);
  c.feed(R"({"jsonrpc":"2.0","result":[0,1,1,1],"id":9})"
         "\n",
         frames);                                   // answered: a node kept again
  note("sen.displacement.getAxesDisplacement", 2);  // id 2 again, in the kept node: replaces it
  EXPECT_EQ(c.pending(), 1u);
  c.feed(R"({"jsonrpc":"2.0","result":[0,20,0,0],"id":2})"
         "\n",
         frames);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].method, IdsMethod::get_axes_displacement);
  EXPECT_DOUBLE_EQ(*frames[2].displacement_m[0], 20e-12);  // 20 pm, not 20 degC
  EXPECT_FALSE(frames[2].temperature_degc.has_value());
  // Past the bound (the first of these into the node kept from id 2's answer): the oldest go.
  for (int id = 3; id < 3 + static_cast<int>(IdsCodec::max_pending) + 10; ++id)
    note("sen.displacement.getAxesDisplacement", id);
  EXPECT_EQ(c.pending(), IdsCodec::max_pending);
  c.feed(R"({"jsonrpc":"2.0","result":[0,1,2,3],"id":3})"
         "\n",
         frames);  // the oldest were forgotten: id 3 no longer matches
  EXPECT_EQ(frames.size(), 3u);
  EXPECT_EQ(c.stats().malformed, 1u);
  const int last = 2 + static_cast<int>(IdsCodec::max_pending) + 10;
  c.feed(fmt::format(R"({{"jsonrpc":"2.0","result":[0,5,6,7],"id":{}}})"
                     "\n",
                     last),
         frames);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_DOUBLE_EQ(*frames[3].displacement_m[2], 7e-12);
}

TEST(IdsDecode, ACaptureOfBothDirectionsAsAttocubesClientWritesThem) {
  // IDS-APIs python/ACS.py writes json.dumps(request) with no terminator and reads each answer
  // with readline() on a socket file opened with newline='\r\n': a TCP stream capture has
  // each request and its answer on one line, the line ending CR LF. 1e12 pm = 1 m; the
  // displacements here: 1,500,000 pm = 1.5e-6 m, -250 pm, 0. Nothing is left out or misread:
  // three readings from the first answer, the ECU temperature from the second.
  const std::string capture =
      R"({"jsonrpc": "2.0", "method": "com.attocube.ids.displacement.getAxesDisplacement", )"
      R"("api": 2, "id": 7})"
      R"({"jsonrpc":"2.0","result":[0,1500000,-250,0],"id":7})"
      "\r\n"
      R"({"jsonrpc": "2.0", "method": "com.attocube.ecu.getTemperatureInDegrees", "api": 2, )"
      R"("id": 8}{"jsonrpc":"2.0","result":[0,20.5],"id":8})"
      "\r\n";
  namespace d = cal::drivers;
  d::codec::CodecStats stats;
  const auto items = codec_test::decode_whole("ids3010", capture, &stats);
  std::vector<d::DecodedItem> readings;
  for (const auto& i : items) {
    EXPECT_NE(i.kind, d::DecodedItem::Kind::error) << i.text;
    if (i.kind == d::DecodedItem::Kind::reading) readings.push_back(i);
  }
  ASSERT_EQ(readings.size(), 4u);
  EXPECT_DOUBLE_EQ(readings[0].value, 1.5e-6);
  EXPECT_DOUBLE_EQ(readings[1].value, -250e-12);
  EXPECT_EQ(readings[1].channel, 1);
  EXPECT_EQ(readings[3].quantity, d::Quantity::air_temperature_degc);
  EXPECT_DOUBLE_EQ(readings[3].value, 20.5);
  EXPECT_EQ(stats.errors(), 0u);
}

TEST(IdsCodec, JsonObjectsOfALineBracesInStringsAndStrayText) {
  using cal::drivers::codec::json_objects;
  EXPECT_EQ(json_objects(R"({"a":"}{"} {"b":{"c":1}})"),
            (std::vector<std::string_view>{R"({"a":"}{"})", R"({"b":{"c":1}})"}));
  EXPECT_EQ(json_objects(R"(junk{"a":1}{"b":)"),
            (std::vector<std::string_view>{"junk", R"({"a":1})", R"({"b":)"}));
  EXPECT_TRUE(json_objects(" \t").empty());
}

// The requests replay learns are recognised in one pass where they are as encode() writes them
// and through the JSON parser otherwise; every form must be learnt exactly as the parser reads
// it (the reference below is the parser and every method's full name, as before the fast path).
struct Learnt {
  bool known = false;
  std::int64_t id = 0;
  IdsMethod method{};
  IdsApi api{};
  std::vector<std::int64_t> params;
};

Learnt reference_request(std::string_view line) {
  const auto j = nlohmann::json::parse(line, nullptr, false);
  Learnt l;
  if (j.is_discarded() || !j.is_object() || !j.contains("id") || !j.contains("method") ||
      !j["id"].is_number_integer() || !j["method"].is_string())
    return l;
  for (int m = 0; m <= static_cast<int>(IdsMethod::error_number_to_string) && !l.known; ++m)
    for (const IdsApi api : {IdsApi::ids, IdsApi::sen})
      if (method_name(static_cast<IdsMethod>(m), api) == j["method"].get<std::string>()) {
        l = {true, j["id"].get<std::int64_t>(), static_cast<IdsMethod>(m), api, {}};
        if (j.contains("params") && j["params"].is_array())
          for (const auto& e : j["params"])
            if (e.is_number_integer()) l.params.push_back(e.get<std::int64_t>());
        break;
      }
  return l;
}

TEST(IdsCodec, RecordedRequestsAreLearntAsTheJsonParserReadsThem) {
  const std::string_view lines[] = {
      // As encode() writes them, both generations, the ECU, params.
      R"({"jsonrpc":"2.0","method":"com.attocube.sen.displacement.getAxesDisplacement","params":[],"id":41,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ids.displacement.getAxisDisplacement","params":[2],"id":42,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.system.errorNumberToString","params":[1,-7],"id":43,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.getPressureInHPa","params":[],"id":44,"api":2})",
      // attocube's client (spaces, "api" before "id", no params), members in any order.
      R"({"jsonrpc": "2.0", "method": "com.attocube.ecu.getTemperatureInDegrees", "api": 2, "id": 45})",
      R"( { "id" : 46 , "method" : "com.attocube.sen.system.getCurrentMode" } )",
      // Params the parser does not count: a fraction, an exponent, a boolean, a string.
      R"({"method":"com.attocube.system.errorNumberToString","params":[1.0,2e0,3],"id":47})",
      R"({"method":"com.attocube.system.errorNumberToString","params":[true,"x",5],"id":48})",
      // Only the parser can read these: an escape in the name, a nested value, a BOM.
      R"({"method":"com.attocube.ecu.get\u0045nabled","id":49})",
      R"({"method":"com.attocube.ecu.getConnected","id":50,"extra":{"a":[1]}})",
      "\xEF\xBB\xBF{\"method\":\"com.attocube.ecu.enable\",\"id\":51}",
      // Duplicate keys: the parser keeps the last.
      R"({"method":"nothing.known","id":52,"method":"com.attocube.ecu.getHumidityInPercent"})",
      // Ids: 18 and 19 digits (int64), negative, a fraction, an exponent, too large for int64.
      R"({"method":"com.attocube.ecu.getRefractiveIndex","id":123456789012345678})",
      R"({"method":"com.attocube.ecu.getRefractiveIndex","id":1234567890123456789})",
      R"({"method":"com.attocube.ecu.getRefractiveIndex","id":-5})",
      R"({"method":"com.attocube.ecu.getRefractiveIndex","id":53.0})",
      R"({"method":"com.attocube.ecu.getRefractiveIndex","id":1e2})",
      R"({"method":"com.attocube.ecu.getRefractiveIndex","id":99999999999999999999})",
      // Not requests of ours, or not JSON: ignored.
      R"({"jsonrpc":"2.0","method":"com.attocube.ids.displacement.getAxesDisplacementX","id":54})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","id":"55"})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable"})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","id":56} trailing)",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","id":057})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","id":58,})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.en\u0000able","id":59})",
      "{\"method\":\"com.attocube.ecu.enable\",\"id\":60,\"x\":\"\xC3\x28\"}",  // bad UTF-8
      R"([{"method":"com.attocube.ecu.enable","id":61}])",
  };
  for (const std::string_view line : lines) {
    SCOPED_TRACE(line);
    const Learnt expected = reference_request(line);
    IdsCodec c;
    const std::string sent = std::string(line) + "\n";
    c.note_requests(std::as_bytes(std::span(sent)));
    ASSERT_EQ(c.pending(), expected.known ? 1u : 0u);
    if (!expected.known) continue;
    EXPECT_EQ(c.last_id(), std::max<std::int64_t>(0, expected.id));
    std::vector<IdsResponse> frames;
    c.feed(fmt::format(R"({{"jsonrpc":"2.0","result":[3],"id":{}}})"
                       "\n",
                       expected.id),
           frames);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].method, expected.method);
    EXPECT_EQ(frames[0].api, expected.api);
    EXPECT_EQ(frames[0].params, expected.params);
    EXPECT_EQ(frames[0].error_code, 3);
  }
}

using codec_test::bits;
using codec_test::strtod_shifted;

TEST(IdsCodec, ReadingsAreTheirDecimalsInSiBitForBit) {
  // Picometre counts as the device writes them (both answer layouts, a blank after '{' for the
  // one-pass scanner, an escaped string for the JSON parser) are n / 10^12 m correctly rounded:
  // strtod("<n>e-12"), not n x 1e-12 (one ulp off for about 14 %).
  std::mt19937_64 rng(1129);
  std::uniform_int_distribution<std::int64_t> pm(-10'000'000'000'000, 10'000'000'000'000);
  const char* forms[] = {R"({{"jsonrpc":"2.0","result":[0,{},{},{}],"id":1}})",
                         R"({{"id":1,"jsonrpc":"2.0","result":[0,{},{},{}]}})",
                         R"({{ "jsonrpc":"2.0","result":[0,{},{},{}],"id":1}})",
                         R"({{"jsonrpc":"2.0","note":"a\"b","result":[0,{},{},{}],"id":1}})"};
  std::size_t product_missed = 0, n = 0;
  for (int i = 0; i < 20'000; ++i) {
    const std::int64_t v[3] = {pm(rng), pm(rng), pm(rng)};
    for (const char* form : forms) {
      IdsCodec c;
      c.encode(IdsMethod::get_axes_displacement);
      std::vector<IdsResponse> frames;
      std::vector<CodecError> errors;
      c.feed(fmt::format(fmt::runtime(form), v[0], v[1], v[2]) + "\n", frames, errors);
      ASSERT_EQ(frames.size(), 1u) << form;
      ASSERT_TRUE(errors.empty()) << form;
      for (int a = 0; a < 3; ++a) {
        const double want = strtod_shifted(std::to_string(v[a]), -12);
        ASSERT_TRUE(frames[0].displacement_m[a]);
        ASSERT_EQ(bits(*frames[0].displacement_m[a]), bits(want)) << form << " " << v[a];
      }
    }
    for (const std::int64_t x : v) {
      product_missed += static_cast<double>(x) * 1e-12 != strtod_shifted(std::to_string(x), -12);
      ++n;
    }
  }
  EXPECT_GT(product_missed, n / 20);
  // The ECU's pressure in hPa: 1024.09 hPa is 102409 Pa exactly; 1024.09 x 100 is
  // 102408.99999999999.
  IdsCodec c;
  c.encode(IdsMethod::ecu_get_pressure);
  c.encode(IdsMethod::ecu_get_pressure);
  std::vector<IdsResponse> frames;
  c.feed(R"({"jsonrpc":"2.0","result":[0,1024.09],"id":1})"
         "\n"
         R"({"jsonrpc":"2.0","note":"a\"b","result":[0,1024.4],"id":2})"
         "\n",
         frames);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(*frames[0].pressure_pa, 102409.0);
  EXPECT_EQ(*frames[1].pressure_pa, 102440.0);  // through the JSON parser
  EXPECT_NE(1024.09 * 100.0, 102409.0);         // what the codec stored before
  EXPECT_NE(1024.4 * 100.0, 102440.0);
}

// The answers are read in one pass where they are as the device and the twin write them, and
// through the JSON parser otherwise: each value must come out as the parser reads it.
TEST(IdsCodec, AnswersReadInOnePassGiveTheParsersValues) {
  // Picometres within the 10 m bound: integers, fractions, exponents, a subnormal product.
  const std::string_view values[] = {"0",
                                     "-0",
                                     "1500000",
                                     "-250",
                                     "0.5",
                                     "-0.0",
                                     "1.5e3",
                                     "2E-2",
                                     "9999999999999",
                                     "4503599627370497.5e-3",
                                     "0.30000000000000004",
                                     "1e-300"};
  for (const std::string_view v : values) {
    SCOPED_TRACE(v);
    // The number in metres: its text with the exponent moved by -12, read by strtod.
    const double expected_m = strtod_shifted(std::string(v), -12);
    for (const auto* form :
         {R"({{"jsonrpc":"2.0","result":[0,{},0,0],"id":1}})",
          R"({{"id":1,"jsonrpc":"2.0","result":[0,{},0,0]}})",
          R"( {{ "jsonrpc" : "2.0" , "result" : [ 0 , {} , 0 , 0 ] , "id" : 1 }} )"}) {
      IdsCodec c;
      c.encode(IdsMethod::get_axes_displacement);
      std::vector<IdsResponse> frames;
      std::vector<CodecError> errors;
      c.feed(fmt::format(fmt::runtime(form), v) + "\n", frames, errors);
      ASSERT_EQ(frames.size(), 1u) << form;
      ASSERT_TRUE(frames[0].displacement_m[0].has_value());
      EXPECT_EQ(*frames[0].displacement_m[0], expected_m) << form;  // bit for bit
      EXPECT_TRUE(errors.empty());
    }
  }
  // result[0] with 18 digits (read in one pass) and more (left to the parser).
  for (const std::string_view code :
       {"123456789012345678", "-123456789012345678", "1234567890123456789", "9223372036854775807",
        "-9223372036854775808"}) {
    SCOPED_TRACE(code);
    IdsCodec c;
    c.encode(IdsMethod::get_axes_displacement);
    std::vector<IdsResponse> frames;
    c.feed(fmt::format(R"({{"jsonrpc":"2.0","result":[{},1,2,3],"id":1}})"
                       "\n",
                       code),
           frames);
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].error_code, nlohmann::json::parse(code).get<std::int64_t>());
  }
  // The error paths are those of the parser, with its texts.
  const std::pair<std::string_view, std::string_view> bad[] = {
      {R"({"jsonrpc":"2.0","result":[0,1e400,0,0],"id":1})", "not a JSON object"},
      {R"({"jsonrpc":"2.0","result":[0,01,0,0],"id":1})", "not a JSON object"},
      {R"({"jsonrpc":"2.0","result":[0,1,0,0],"id":1,})", "not a JSON object"},
      {R"({"jsonrpc":"2.0","result":[0,1,0,0],"id":2})", "response id 2 matches no pending"},
      {R"({"jsonrpc":"2.0","result":[],"id":1})", "has no result array with an error code"},
      {R"({"jsonrpc":"2.0","result":[0.0,1,2,3],"id":1})", "has no result array"},
      {R"({"jsonrpc":"2.0","result":[0,1,2],"id":1})", "result has 2 values, 3 expected"},
      {R"({"jsonrpc":"2.0","result":[0,1,2,3e13],"id":1})", "axis 2 displacement (m) = 30"},
      {R"({"jsonrpc":"2.0","result":[0,1,"2",3],"id":1})",
       "axis 1 displacement (m) is not a number"},
      {"{\"jsonrpc\":\"2.0\",\"result\":[0,1,2,3],\"id\":1}\x01", "control bytes"},
      {R"({"jsonrpc":"2.0","result":[0,1,2,3],"id":1.0})", "without an integer id"},
  };
  for (const auto& [line, text] : bad) {
    SCOPED_TRACE(line);
    IdsCodec c;
    c.encode(IdsMethod::get_axes_displacement);
    std::vector<IdsResponse> frames;
    std::vector<CodecError> errors;
    c.feed(std::string(line) + "\n", frames, errors);
    ASSERT_FALSE(errors.empty());
    EXPECT_NE(errors[0].description.find(text), std::string::npos) << errors[0].description;
  }
  // A flag and a text answered with numbers: the parser's errors, the frame still emitted.
  IdsCodec c;
  c.encode(IdsMethod::ecu_get_connected);
  c.encode(IdsMethod::get_current_mode);
  std::vector<IdsResponse> frames;
  std::vector<CodecError> errors;
  c.feed(
      "{\"jsonrpc\":\"2.0\",\"result\":[0,1],\"id\":1}\n"
      "{\"jsonrpc\":\"2.0\",\"result\":[0,2],\"id\":2}\n",
      frames, errors);
  ASSERT_EQ(frames.size(), 2u);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].description, "IDS: flag result is not a boolean");
  EXPECT_EQ(errors[1].description, "IDS: text result is not a string");
  EXPECT_FALSE(frames[0].flag.has_value());
}

// Replay matches the request and answer lines in the device's own byte layouts without a scan
// of keys (issue 32). The same line with a blank after its '{' is the same JSON and is read the
// general way (FlatScanner, else the parser): both must give the same requests learnt, frames
// and errors, for every id, params and result form, taken or refused.
std::string described(const IdsResponse& r) {
  std::string s = fmt::format("id {} method {} api {} params [{}] rpc_error {} code {} '{}'", r.id,
                              static_cast<int>(r.method), static_cast<int>(r.api),
                              fmt::join(r.params, ","), r.rpc_error, r.error_code, r.text);
  for (const auto& d : r.displacement_m) s += d ? fmt::format(" {:.17g}", *d) : " -";
  for (const auto& v : {r.temperature_degc, r.pressure_pa, r.humidity_pct_rh, r.refractive_index})
    s += v ? fmt::format(" {:.17g}", *v) : " -";
  return s;
}

std::string replayed(std::string_view request, std::string_view answer, bool spaced) {
  const auto respace = [&](std::string_view line) {
    std::string s(line);
    if (spaced && !s.empty() && s[0] == '{') s.insert(1, " ");
    return s + "\n";
  };
  IdsCodec c;
  const std::string sent = respace(request);
  c.note_requests(std::as_bytes(std::span(sent)));
  std::string out = fmt::format("pending {} last id {}\n", c.pending(), c.last_id());
  std::vector<IdsResponse> frames;
  std::vector<CodecError> errors;
  c.feed(respace(answer), frames, errors);
  for (const auto& f : frames) out += described(f) + "\n";
  for (const auto& e : errors) out += fmt::format("error {}\n", static_cast<int>(e.kind));
  return out;
}

TEST(IdsCodec, LinesMatchedByteForByteGiveWhatTheGeneralReaderGives) {
  const std::string_view displacement = "com.attocube.sen.displacement.getAxesDisplacement";
  const std::vector<std::string> requests = {
      fmt::format(R"({{"jsonrpc":"2.0","method":"{}","params":[],"id":7,"api":2}})", displacement),
      fmt::format(R"({{"jsonrpc":"2.0","method":"{}","params":[],"id":7,"api":2}})",
                  "com.attocube.ids.displacement.getAxesDisplacement"),
      R"({"jsonrpc":"2.0","method":"com.attocube.system.errorNumberToString","params":[0,-3],"id":7,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ids.displacement.getAxisDisplacement","params":[2],"id":7,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ids.displacement.getAxisDisplacement","params":[1.5],"id":7,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ids.displacement.getAxisDisplacement","params":[01],"id":7,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.system.errorNumberToString","params":[1,2,3,4,5,6,7,8,9],"id":7,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","params":[],"id":-0,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","params":[],"id":123456789012345678,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","params":[],"id":1234567890123456789,"api":2})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","params":[],"id":7,"api":3})",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","params":[],"id":7,"api":2}  )",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.enable","params":[],"id":7,"api":2}x)",
      R"({"jsonrpc":"2.0","method":"com.attocube.ecu.en\able","params":[],"id":7,"api":2})",
      R"({"jsonrpc":"2.0","method":"nothing.known","params":[],"id":7,"api":2})",
  };
  const std::vector<std::string_view> ids = {
      "7", "-0", "123456789012345678", "1234567890123456789", "07", "7.0"};
  const std::vector<std::string_view> results = {"0,-864831475,0,0",
                                                 "0,1.5e3,-2E-2,0.30000000000000004",
                                                 "0",
                                                 "",
                                                 "3",
                                                 "0,1,2,3,4,5,6,7",
                                                 "0,1,2,3,4,5,6,7,8",
                                                 "0,99999999999999999999,0,0",
                                                 "0, 1,2,3",
                                                 "0,-,0,0",
                                                 "0,1.,0,0",
                                                 "0,1e,0,0",
                                                 "0,\"a\",0,0",
                                                 "0,1e999,0,0"};
  std::size_t compared = 0;
  for (const auto& request : requests)
    for (const auto id : ids)
      for (const auto result : results)
        for (const auto* form : {R"({{"id":{},"jsonrpc":"2.0","result":[{}]}})",
                                 R"({{"jsonrpc":"2.0","result":[{}],"id":{}}})"}) {
          // The second with the CR the device ends its lines with (CR LF).
          const bool id_first = form[3] == 'i';
          const std::string answer = id_first ? fmt::format(fmt::runtime(form), id, result)
                                              : fmt::format(fmt::runtime(form), result, id) + "\r";
          SCOPED_TRACE(request + " / " + answer);
          EXPECT_EQ(replayed(request, answer, false), replayed(request, answer, true));
          ++compared;
        }
  EXPECT_EQ(compared, requests.size() * ids.size() * results.size() * 2);
  // The device's own line is matched and read: a displacement in metres.
  EXPECT_NE(replayed(requests[0],
                     R"({"id":7,"jsonrpc":"2.0","result":[0,-864831475,0,0]})"
                     "\r",
                     false)
                .find(" -0.00086483147"),
            std::string::npos);
}

}  // namespace
