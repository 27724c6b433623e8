// Culling must not tear the keyframe chain apart in a turn (core/mapping/keyframe_gap.hpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/map/map.hpp"
#include "core/mapping/keyframe_gap.hpp"
#include "core/slot_frame.hpp"

namespace hiveslam::core {
namespace {

// Keyframes turning about the vertical (y) axis, `degrees` apart and `seconds` apart, all seeing
// the same points, so that each is covisible with every other.
struct Turn {
  std::shared_ptr<Map> map = std::make_shared<Map>(1);
  std::vector<std::shared_ptr<KeyFrame>> kfs;

  Turn(int n, double degrees, double seconds) {
    std::vector<std::shared_ptr<MapPoint>> points;
    for (int i = 0; i < 40; ++i) {
      points.push_back(std::make_shared<MapPoint>(100 + static_cast<Id>(i), Eigen::Vector3d(0.1 * i - 2.0, 0.0, 4.0), 1));
      map->add(points.back());
    }
    for (int k = 0; k < n; ++k) {
      Frame f = testing::slotFrame(points.size());
      f.timestamp = 10.0 + seconds * k;
      Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
      T_cw.linear() = Eigen::AngleAxisd(degrees * k * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
      auto kf = std::make_shared<KeyFrame>(static_cast<Id>(k + 1), f, T_cw);
      map->add(kf);
      for (size_t i = 0; i < points.size(); ++i) Map::observe(*kf, static_cast<int>(i), points[i]);
      kfs.push_back(kf);
    }
    for (auto& kf : kfs) kf->updateConnections();
  }
};

TEST(KeyframeGap, ViewAngleIsBetweenOpticalAxes) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d yaw = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(viewAngleDegrees(I, yaw), 0.3 * 180.0 / M_PI, 1e-9);
  EXPECT_NEAR(viewAngleDegrees(I, roll), 0.0, 1e-6) << "a roll about the axis turns no view away";
  EXPECT_NEAR(viewAngleDegrees(I, I), 0.0, 1e-6);
}

TEST(KeyframeGap, AngleBetweenTheNeighboursDecides) {
  Turn turn(3, 8.0, 0.2);  // the neighbours of the middle one are 16 degrees apart
  const KeyFrame& middle = *turn.kfs[1];
  EXPECT_TRUE(cullingLeavesGap(middle, 15.0));
  EXPECT_FALSE(cullingLeavesGap(middle, 17.0));
  EXPECT_FALSE(cullingLeavesGap(middle, 0.0)) << "no limit: culling as before";
}

TEST(KeyframeGap, TimeAloneTearsNoGap) {
  Turn turn(3, 0.0, 2.0);  // 4 s between the neighbours, looking the same way
  EXPECT_FALSE(cullingLeavesGap(*turn.kfs[1], 10.0));
}

TEST(KeyframeGap, TheNearestLiveNeighboursCount) {
  Turn turn(4, 6.0, 0.2);
  // Second keyframe: neighbours 1 and 3 are 12 degrees apart.
  EXPECT_FALSE(cullingLeavesGap(*turn.kfs[1], 15.0));
  // With the third culled, the second's neighbours are 1 and 4: 18 degrees.
  {
    std::lock_guard lock(turn.map->mutex);
    turn.map->erase(*turn.kfs[2]);
  }
  turn.kfs[1]->updateConnections();
  EXPECT_TRUE(cullingLeavesGap(*turn.kfs[1], 15.0));
}

TEST(KeyframeGap, AnEndOfTheChainLeavesNoGap) {
  Turn turn(3, 20.0, 1.0);
  EXPECT_FALSE(cullingLeavesGap(*turn.kfs[0], 15.0));
  EXPECT_FALSE(cullingLeavesGap(*turn.kfs[2], 15.0));
}

}  // namespace
}  // namespace hiveslam::core
