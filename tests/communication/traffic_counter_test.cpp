// Every node's report reads its traffic off the TrafficCounter: what it sent and received per
// topic, and what never went out or never came (distribution's end-of-run checks start there).
#include <gtest/gtest.h>

#include "communication/traffic_counter.hpp"

namespace hiveslam::communication {
namespace {

TEST(TrafficCounter, CountsEachTopicBothWaysWithItsLossesAndFailedWrites) {
  TrafficCounter c;
  c.sent(Topic::LmMap, 1000);
  c.sent(Topic::LmMap, 500);
  c.received(Topic::TrKeyframes, 200);
  c.lost(Topic::LmMap, 3);
  c.writeFailed(Topic::LmMap);
  c.lost(Topic::LcMap, 2);  // a topic that lost packets and carried none still shows

  const TrafficReport r = c.report();
  ASSERT_EQ(r.count(topicName(Topic::LmMap)), 1u);
  const TopicTraffic& map = r.at(topicName(Topic::LmMap));
  EXPECT_EQ(map.bytes_out, 1500u);
  EXPECT_EQ(map.messages_out, 2u);
  EXPECT_EQ(map.messages_in, 0u);
  EXPECT_EQ(map.messages_lost, 3u);
  EXPECT_EQ(map.writes_failed, 1u);
  EXPECT_EQ(r.at(topicName(Topic::TrKeyframes)).bytes_in, 200u);
  EXPECT_EQ(r.at(topicName(Topic::LcMap)).messages_lost, 2u);
  EXPECT_EQ(r.count(topicName(Topic::LmKeyframes)), 0u);  // unused topics stay out
}

}  // namespace
}  // namespace hiveslam::communication
