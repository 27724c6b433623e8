// What a node takes from an announcement: a peer only when every field means something.
#include "communication/dds/node_announcement.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hiveslam::communication {
namespace {

hiveslam_msgs::msg::NodeInfo valid() {
  PeerInfo p;
  p.node = 7;
  p.name = "lm";
  p.task = Task::Mapping;
  p.hosted = 2 | 4;
  p.incarnation = 123;
  p.cores = 2;
  p.load = 0.5f;
  p.seen = {3, 1, 3};
  return toIdl(p);
}

TEST(NodeAnnouncement, AValidOneRoundTripsWithItsSeenListInIdOrder) {
  std::string why;
  const auto p = fromIdl(valid(), why);
  ASSERT_TRUE(p) << why;
  EXPECT_EQ(p->node, 7);
  EXPECT_EQ(p->name, "lm");
  EXPECT_EQ(p->task, Task::Mapping);
  EXPECT_EQ(p->hosted, 6);
  EXPECT_EQ(p->incarnation, 123u);
  EXPECT_EQ(p->seen, (std::vector<uint16_t>{1, 3}));
}

TEST(NodeAnnouncement, FieldsThatMeanNothingDropIt) {
  auto check = [](auto&& spoil, const char* expected) {
    auto m = valid();
    spoil(m);
    std::string why;
    EXPECT_FALSE(fromIdl(m, why)) << expected;
    EXPECT_NE(why.find(expected), std::string::npos) << why;
  };
  check([](auto& m) { m.version(3); }, "version 3");
  check([](auto& m) { m.task(3); }, "task 3");
  check([](auto& m) { m.hosted(8); }, "hosted tasks 8");
  check([](auto& m) { m.name(std::string(kMaxNodeNameBytes + 1, 'x')); }, "a name of 65 bytes");
  check([](auto& m) { m.load(std::numeric_limits<float>::quiet_NaN()); }, "load");
  check([](auto& m) { m.load(-1.f); }, "load");
}

}  // namespace
}  // namespace hiveslam::communication
