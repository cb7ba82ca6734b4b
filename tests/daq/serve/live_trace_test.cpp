// The live circle's trace as the page receives it (serve/live_trace.hpp): each message carries
// the points of about the last 0.4 s of messages from where they start, so the page rebuilds the
// whole trace from the messages alone while it skips none for longer; a new test starts a new
// epoch. Times are given, never waited for.
#include "serve/live_trace.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

namespace {

using daq::CircleLive;
using daq::serve::LiveTraceFeed;
using nlohmann::json;
using namespace std::chrono_literals;

CircleLive with_points(std::size_t ccw, std::size_t cw) {
  CircleLive s;
  s.state = "measuring";
  s.samples = 100;
  // A point a degree, the deviation a hundredth of its index (µm): exact after the 0.01 rounding.
  for (std::size_t i = 0; i < ccw; ++i) {
    const auto k = static_cast<double>(i);
    s.ccw.emplace_back(k, 0.01 * k);
  }
  for (std::size_t i = 0; i < cw; ++i) {
    const auto k = static_cast<double>(i);
    s.cw.emplace_back(-k, -0.01 * k);
  }
  return s;
}

// What a page does with a message's arc (page.html, followTrace): keep up to `from`, add the
// points; false when the message starts beyond what it has (it would fetch the whole).
bool follow(std::vector<json>& have, const json& arc) {
  const auto from = arc["from"].get<std::size_t>();
  if (from > have.size()) return false;
  have.resize(from);
  for (const auto& p : arc["points"]) have.push_back(p);
  return true;
}

TEST(LiveTraceFeed, EachMessageCarriesTheLastPointsOnly) {
  LiveTraceFeed feed;
  const auto t0 = LiveTraceFeed::Clock::time_point{} + 100s;
  feed.update(with_points(10, 0), 1);
  auto m = feed.page_json(t0);
  // The first message of a trace: all of it (10 points, from 0).
  EXPECT_EQ(m["trace"]["ccw"]["n"], 10);
  EXPECT_EQ(m["trace"]["ccw"]["from"], 0);
  EXPECT_EQ(m["trace"]["ccw"]["points"].size(), 10u);
  EXPECT_EQ(m["trace"]["ccw"]["points"][3], json({3.0, 0.03}));
  EXPECT_EQ(m["schema"], "caldaq.live-circle.v1");
  EXPECT_EQ(m["state"], "measuring");
  // 30 points a message, every 0.1 s: from the size at the message 0.4 s or more before.
  for (int k = 1; k <= 6; ++k) {
    feed.update(with_points(10 + 30 * k, 0), 1);
    m = feed.page_json(t0 + k * 100ms);
  }
  // At 0.6 s: the message of 0.2 s had 70 points (10 + 2 x 30): 190 - 70 = 120 points sent.
  EXPECT_EQ(m["trace"]["ccw"]["n"], 190);
  EXPECT_EQ(m["trace"]["ccw"]["from"], 70);
  EXPECT_EQ(m["trace"]["ccw"]["points"].size(), 120u);
  EXPECT_EQ(m["trace"]["ccw"]["points"][0], json({70.0, 0.7}));
  EXPECT_EQ(m["trace"]["cw"]["n"], 0);
  // Nothing new for 0.4 s: nothing sent (the message then no longer changes).
  for (int k = 7; k <= 11; ++k) m = feed.page_json(t0 + k * 100ms);
  EXPECT_EQ(m["trace"]["ccw"]["from"], 190);
  EXPECT_TRUE(m["trace"]["ccw"]["points"].empty());
}

TEST(LiveTraceFeed, APageThatSkipsMessagesBuildsTheWholeTrace) {
  LiveTraceFeed feed;
  const auto t0 = LiveTraceFeed::Clock::time_point{} + 100s;
  std::vector<json> ccw, cw;
  std::size_t n = 0;
  for (int k = 0; k < 40; ++k) {
    n += 17;
    feed.update(with_points(n, n / 2), 7);
    const auto m = feed.page_json(t0 + k * 100ms);
    if (k % 3 != 0) continue;  // the page sees one message in three (0.3 s apart)
    ASSERT_TRUE(follow(ccw, m["trace"]["ccw"])) << "message " << k;
    ASSERT_TRUE(follow(cw, m["trace"]["cw"])) << "message " << k;
  }
  // The last message seen was k = 39: n = 680 points, 340 in cw.
  const auto whole = feed.whole();
  EXPECT_EQ(ccw.size(), 680u);
  EXPECT_EQ(json(ccw), whole["ccw"]);
  EXPECT_EQ(json(cw), whole["cw"]);
}

TEST(LiveTraceFeed, APageThatMissedMoreIsToldSoAndANewTestIsANewEpoch) {
  LiveTraceFeed feed;
  const auto t0 = LiveTraceFeed::Clock::time_point{} + 100s;
  for (int k = 0; k < 10; ++k) {
    feed.update(with_points(20 * (k + 1), 0), 3);
    feed.page_json(t0 + k * 100ms);
  }
  // A page connecting now has nothing: the message starts past it (it asks for the whole).
  auto m = feed.page_json(t0 + 1s);
  std::vector<json> none;
  EXPECT_FALSE(follow(none, m["trace"]["ccw"]));
  const auto epoch = m["trace"]["epoch"];
  EXPECT_EQ(feed.whole()["epoch"], epoch);
  // The set's next test: the trace starts again, a new epoch, sent from 0.
  feed.update(with_points(5, 0), 3);
  m = feed.page_json(t0 + 1100ms);
  EXPECT_NE(m["trace"]["epoch"], epoch);
  EXPECT_EQ(m["trace"]["ccw"]["from"], 0);
  EXPECT_EQ(m["trace"]["ccw"]["points"].size(), 5u);
  // Another run (its id): a new epoch too, though its trace did not shrink.
  const auto second = m["trace"]["epoch"];
  feed.update(with_points(6, 0), 4);
  EXPECT_NE(feed.page_json(t0 + 1200ms)["trace"]["epoch"], second);
  feed.clear();
  EXPECT_TRUE(feed.empty());
}

}  // namespace
