// A codec's refusal reaches the run's events (it used to be dropped: a TEMPer whose probe does
// not answer gave no value and no word), the first few in full, then one line for the rest.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "runner.hpp"

namespace {

using cal::drivers::codec::CodecError;
using cal::drivers::codec::ErrorKind;

TEST(CodecErrorsAsEvents, TheFirstAreToldInFullThenOneLineSaysTheRestAreCounted) {
  std::vector<std::string> events;
  auto on_error = daq::codec_errors_as_events(
      "TEMPer on hid:1-2", [&events](const std::string& e) { events.push_back(e); });
  const CodecError no_answer{
      .kind = ErrorKind::out_of_range,
      .offset = 16,
      .description = "sensor 1: ff ff: the sensor did not answer (probe unplugged or broken)"};
  for (int k = 0; k < 10; ++k) on_error(no_answer);
  ASSERT_EQ(events.size(), static_cast<std::size_t>(daq::kListedCodecErrors) + 1);
  EXPECT_EQ(events[0],
            "TEMPer on hid:1-2: refused at byte 16: sensor 1: ff ff: the sensor did not answer "
            "(probe unplugged or broken)");
  EXPECT_EQ(events.back(),
            "TEMPer on hid:1-2: more refused data; further codec errors are counted, not listed");
}

TEST(CodecErrorsAsEvents, NoEventHandlerIsNoCall) {
  auto on_error = daq::codec_errors_as_events("gauge", {});
  EXPECT_NO_THROW(on_error(CodecError{}));  // an empty handler would throw bad_function_call
}

}  // namespace
