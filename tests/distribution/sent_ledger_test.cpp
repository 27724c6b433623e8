// SentLedger: when a map point's full record (descriptor, viewing direction, distance range)
// must go again on a topic, and when its position alone will do.
#include "distribution/sent_ledger.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hiveslam::distribution {
namespace {

using communication::Topic;

PointRecord point() {
  PointRecord p;
  p.id = 7;
  p.full = true;
  p.descriptor.fill(0x5a);
  p.normal = Eigen::Vector3d(0, 0, 1);
  p.min_distance = 0.5;
  p.max_distance = 4.0;
  return p;
}

const AppearanceTolerance kTolerance{3.0, 0.03, 10};

TEST(SentLedger, APointGoesInFullOncePerTopic) {
  SentLedger ledger;
  EXPECT_TRUE(ledger.needsFull(Topic::LmMap, point(), kTolerance));
  EXPECT_FALSE(ledger.needsFull(Topic::LmMap, point(), kTolerance));
  EXPECT_TRUE(ledger.needsFull(Topic::LcMap, point(), kTolerance));  // each topic its own receivers
  EXPECT_TRUE(ledger.sent(Topic::LmMap, 7));
  EXPECT_FALSE(ledger.sent(Topic::TrKeyframes, 7));
}

TEST(SentLedger, SmallChangesInWhatMatchingUsesGoAsPositionOnly) {
  SentLedger ledger;
  ledger.mark(Topic::LmMap, point());  // sent with a keyframe
  PointRecord p = point();
  p.descriptor[0] ^= 0xff;  // 8 bits
  p.normal = Eigen::Vector3d(0, std::sin(2.0 * M_PI / 180), std::cos(2.0 * M_PI / 180));
  p.max_distance *= 1.02;
  p.min_distance *= 0.98;
  EXPECT_FALSE(ledger.needsFull(Topic::LmMap, p, kTolerance));
}

TEST(SentLedger, ADescriptorDirectionOrRangeChangedPastTheToleranceGoesAgain) {
  auto changed = [](auto change) {
    SentLedger ledger;
    ledger.needsFull(Topic::LmMap, point(), kTolerance);
    PointRecord p = point();
    change(p);
    const bool again = ledger.needsFull(Topic::LmMap, p, kTolerance);
    // Recorded as sent: the same record is not due a second time.
    return again && !ledger.needsFull(Topic::LmMap, p, kTolerance);
  };
  EXPECT_TRUE(changed([](PointRecord& p) { p.descriptor[0] ^= 0xff, p.descriptor[1] ^= 0x07; }));  // 11 bits
  EXPECT_TRUE(changed([](PointRecord& p) {
    p.normal = Eigen::Vector3d(0, std::sin(4.0 * M_PI / 180), std::cos(4.0 * M_PI / 180));
  }));
  EXPECT_TRUE(changed([](PointRecord& p) { p.max_distance *= 1.05; }));
  EXPECT_TRUE(changed([](PointRecord& p) { p.min_distance *= 0.95; }));
}

TEST(SentLedger, DriftBelowTheToleranceAddsUpAgainstWhatWasSent) {
  // Compared with what the receivers hold, not with the last record seen: many small turns
  // make one large one.
  SentLedger ledger;
  ledger.needsFull(Topic::LmMap, point(), kTolerance);
  int sent_again = 0;
  for (int deg = 1; deg <= 8; ++deg) {
    PointRecord p = point();
    p.normal = Eigen::Vector3d(0, std::sin(deg * M_PI / 180), std::cos(deg * M_PI / 180));
    sent_again += ledger.needsFull(Topic::LmMap, p, kTolerance);
  }
  EXPECT_EQ(sent_again, 2);  // at 4 and 8 degrees
}

}  // namespace
}  // namespace hiveslam::distribution
