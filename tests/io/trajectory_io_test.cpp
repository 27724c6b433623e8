#include <gtest/gtest.h>

#include <fstream>

#include "common/error.hpp"
#include "io/trajectory_io.hpp"
#include "temp_dir.hpp"

namespace hiveslam::io {
namespace {

Trajectory sample() {
  Trajectory t;
  for (int i = 0; i < 5; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0.5 * i, -0.25 * i, 1.0 + 0.1 * i);
    t.add(1403636579.763555 + 0.05 * i, T);
  }
  return t;
}

class TrajectoryRoundTrip : public ::testing::TestWithParam<TrajectoryFormat> {};

TEST_P(TrajectoryRoundTrip, WriteThenReadGivesThePoses) {
  testing::TempDir dir;
  const auto format = GetParam();
  const auto file = dir / (format == TrajectoryFormat::Euroc ? "t.csv" : "t.txt");
  const Trajectory t = sample();
  writeTrajectory(file, t, format);
  EXPECT_EQ(detectTrajectoryFormat(file), format);
  const Trajectory back = readTrajectory(file);
  ASSERT_EQ(back.size(), t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    if (format != TrajectoryFormat::Kitti) {
      EXPECT_NEAR(back.stamps[i], t.stamps[i], 1e-6);
    }
    EXPECT_LT((back.poses[i].translation() - t.poses[i].translation()).norm(), 1e-8);
    EXPECT_LT((back.poses[i].linear() - t.poses[i].linear()).norm(), 1e-8);
  }
}

INSTANTIATE_TEST_SUITE_P(Formats, TrajectoryRoundTrip,
                         ::testing::Values(TrajectoryFormat::Tum, TrajectoryFormat::Euroc,
                                           TrajectoryFormat::Kitti));

TEST(TrajectoryIo, ReadsTumWithCommentsAndUnnormalizedQuaternions) {
  testing::TempDir dir;
  std::ofstream(dir / "t.txt") << "# timestamp x y z qx qy qz qw\n\n1.0 1 2 3 0 0 0 2\n2.0 4 5 6 0 0 2 0\n";
  const Trajectory t = readTrajectory(dir / "t.txt");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_DOUBLE_EQ(t.stamps[1], 2.0);
  EXPECT_TRUE(t.poses[0].linear().isApprox(Eigen::Matrix3d::Identity()));
  // Quaternion (x y z w) = (0 0 1 0): 180 degrees about z.
  EXPECT_NEAR(t.poses[1].linear()(0, 0), -1.0, 1e-12);
  EXPECT_EQ(t.poses[1].translation(), Eigen::Vector3d(4, 5, 6));
}

TEST(TrajectoryIo, EurocStampsAreNanoseconds) {
  testing::TempDir dir;
  std::ofstream(dir / "gt.csv") << "#timestamp,px,py,pz,qw,qx,qy,qz,vx,vy,vz\n"
                                  "1403636579763555584,1,2,3,1,0,0,0,0,0,0\n";
  const Trajectory t = readTrajectory(dir / "gt.csv");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_NEAR(t.stamps[0], 1403636579.763555584, 1e-6);
}

TEST(TrajectoryIo, MalformedLineNamesFileAndLine) {
  testing::TempDir dir;
  std::ofstream(dir / "t.txt") << "1.0 1 2 3 0 0 0 1\n2.0 1 2 x 0 0 0 1\n";
  try {
    readTrajectory(dir / "t.txt");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.txt:2"), std::string::npos) << e.what();
  }
}

TEST(TrajectoryIo, WrongColumnCountIsAnError) {
  testing::TempDir dir;
  std::ofstream(dir / "t.txt") << "1.0 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 1\n";
  EXPECT_THROW(readTrajectory(dir / "t.txt", TrajectoryFormat::Tum), InputError);
  EXPECT_THROW(readTrajectory(dir / "missing.txt"), InputError);
}

}  // namespace
}  // namespace hiveslam::io
