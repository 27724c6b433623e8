// Culled keyframes and tracked frames keep their poses relative to live keyframes; a correction
// that moves and rescales the map (a merge, a loop correction) must carry them along exactly as
// it carries the live map, or the trajectory shows the old scale wherever frames referred to a
// culled keyframe.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/loop/map_correction.hpp"
#include "core/slot_frame.hpp"

namespace hiveslam::core {
namespace {

// Six keyframes 0.3 m apart along x, all looking down +z at a wall of points 3-5 m away; each
// sees the points within 1.2 m of its own x. One slot per point keeps the bookkeeping trivial.
struct Corridor {
  Map map{1};
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  std::vector<std::shared_ptr<MapPoint>> points;

  Corridor() {
    for (int i = 0; i < 120; ++i) {
      const Eigen::Vector3d X(-1.0 + 0.03 * i, 0.2 * std::sin(i), 3.0 + 2.0 * ((i * 7) % 11) / 10.0);
      points.push_back(std::make_shared<MapPoint>(1000 + static_cast<Id>(i), X, 1));
      map.add(points.back());
    }
    for (int k = 0; k < 6; ++k) {
      const Frame f = testing::slotFrame(points.size());
      Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
      T_cw.translation() = -Eigen::Vector3d(0.3 * k, 0, 0);
      auto kf = std::make_shared<KeyFrame>(static_cast<Id>(k + 1), f, T_cw);
      map.add(kf);
      for (size_t i = 0; i < points.size(); ++i)
        if (std::abs(points[i]->position.x() - 0.3 * k) < 1.2) Map::observe(*kf, static_cast<int>(i), points[i]);
      kfs.push_back(kf);
    }
    map.origin = kfs[0].get();
    for (auto& kf : kfs) kf->updateConnections();
  }
};

Sim3 someSimilarity() {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
          Eigen::Vector3d(0.4, -1.0, 2.0), 1.04};
}

// T_cw after moving the world by S (x -> S x).
Eigen::Isometry3d moved(const Eigen::Isometry3d& T_cw, const Sim3& S) { return (Sim3(T_cw) * S.inverse()).toPose(); }

void expectPose(const Eigen::Isometry3d& want, const Eigen::Isometry3d& got, const char* what) {
  EXPECT_LT((want.translation() - got.translation()).norm(), 1e-9) << what;
  EXPECT_LT(Eigen::AngleAxisd(want.linear().transpose() * got.linear()).angle(), 1e-9) << what;
}

// rigid: the correction comes as rigid poses and moved points (global BA; a merge as another
// node receives it); otherwise as similarity poses (the essential graph).
void culledKeyframesFollowAScaledMove(bool rigid) {
  Corridor c;
  // Cull keyframes 2 and then 3: keyframe 2's closest live neighbour is culled in turn.
  const Eigen::Isometry3d T2 = c.kfs[2]->T_cw, T3 = c.kfs[3]->T_cw;
  Eigen::Isometry3d T_frame = T3;
  T_frame.translation() += Eigen::Vector3d(-0.05, 0.01, 0.02);
  c.map.erase(*c.kfs[2]);
  c.map.erase(*c.kfs[3]);
  ASSERT_TRUE(c.kfs[2]->bad && c.kfs[3]->bad);
  ASSERT_NE(c.kfs[2]->anchor, nullptr);
  const RelativePose frame = c.kfs[3]->relative(T_frame);
  expectPose(T2, c.kfs[2]->pose(), "keyframe 2 before");
  expectPose(T_frame, c.kfs[3]->poseOf(frame), "frame before");

  const Sim3 S = someSimilarity();
  PoseCorrection correction;
  for (const auto& [id, kf] : c.map.keyframes) {
    correction.before[kf.get()] = Sim3(kf->T_cw);
    correction.after[kf.get()] = rigid ? Sim3(moved(kf->T_cw, S)) : Sim3(kf->T_cw) * S.inverse();
  }
  if (rigid)
    for (const auto& [id, p] : c.map.points) correction.points[p.get()] = S * p->position;
  applyCorrection(c.map, correction, {1.0});

  expectPose(moved(T2, S), c.kfs[2]->pose(), "keyframe 2");
  expectPose(moved(T3, S), c.kfs[3]->pose(), "keyframe 3");
  expectPose(moved(T_frame, S), c.kfs[3]->poseOf(frame), "frame");
  EXPECT_NEAR(c.kfs[3]->scale(), S.s, 1e-9);
}

TEST(MapCorrection, CulledKeyframesFollowARigidCorrectionWithMovedPoints) { culledKeyframesFollowAScaledMove(true); }

TEST(MapCorrection, CulledKeyframesFollowASimilarityCorrection) { culledKeyframesFollowAScaledMove(false); }

// A global BA solves on copies without the lock. Meanwhile a local BA moves keyframe 4, and local
// mapping makes keyframe 5 (a child of 4) and a new point, both posed on 4 where it is now.
// When the global BA lands, 5 and the point must keep their place relative to 4 as it was then,
// not as it was when the copies were taken (that baked each such local BA into the children).
TEST(MapCorrection, WhatIsMadeDuringAGlobalBaFollowsItsParentFromWhereItIsNow) {
  Corridor c;
  KeyFrame* kf4 = c.kfs[4].get();
  KeyFrame* kf5 = c.kfs[5].get();
  if (kf5->parent) kf5->parent->children.erase(kf5);
  kf5->parent = kf4;
  kf4->children.insert(kf5);
  // Seen by 4 and 5 (slot 0 is free in both): it moves with 4, its oldest observer.
  auto fresh = std::make_shared<MapPoint>(5000, Eigen::Vector3d(1.5, 0.1, 3.5), 1);
  c.map.add(fresh);
  Map::observe(*kf4, 0, fresh);
  Map::observe(*kf5, 0, fresh);
  // The copies: keyframes 0-4 as they are now.
  PoseCorrection correction;
  const Sim3 S = {Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d(0, 1, 1).normalized())),
                  Eigen::Vector3d(0.3, -0.2, 0.5), 1.0};
  for (int k = 0; k <= 4; ++k) {
    correction.before[c.kfs[k].get()] = Sim3(c.kfs[k]->T_cw);
    correction.after[c.kfs[k].get()] = Sim3(moved(c.kfs[k]->T_cw, S));
  }
  // The local BA lands: keyframe 4 moves; keyframe 5 and the point were posed on it after.
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  delta.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  delta.translation() = Eigen::Vector3d(0.02, -0.01, 0.03);
  kf4->T_cw = delta * kf4->T_cw;
  const Eigen::Isometry3d T_54 = kf5->T_cw * kf4->T_cw.inverse();
  const Eigen::Vector3d fresh_in_4 = kf4->T_cw * fresh->position;
  applyCorrection(c.map, correction, {1.0});

  expectPose(moved(correction.before.at(kf4).toPose(), S), kf4->T_cw, "keyframe 4 takes the global BA's pose");
  expectPose(T_54, kf5->T_cw * kf4->T_cw.inverse(), "keyframe 5 relative to 4");
  EXPECT_LT((kf4->T_cw * fresh->position - fresh_in_4).norm(), 1e-9) << "the new point relative to 4";
}

// A global BA that rescales the map (its free scale wandered), sent as rigid poses and moved
// points. Keyframe 5 keeps only five points the BA moved (the rest culled or fused away), too
// few to measure its own scale change: it takes the map's, and a frame posed on it lands where
// the correction puts it. Left at no change, the frame kept its offset from the keyframe at the
// old scale (a lossy-link run: a map eighty times smaller, frames a metre off).
TEST(MapCorrection, AKeyframeWithTooFewMovedPointsTakesTheMapsScaleChange) {
  Corridor c;
  KeyFrame* kf5 = c.kfs[5].get();
  Eigen::Isometry3d T_frame = kf5->T_cw;
  T_frame.translation() += Eigen::Vector3d(-0.08, 0.02, 0.05);
  const RelativePose frame = kf5->relative(T_frame);
  const Sim3 S = {Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())), Eigen::Vector3d(0.1, 0, 0.2),
                  1.0 / 80};
  PoseCorrection correction;
  for (const auto& kf : c.kfs) {
    correction.before[kf.get()] = Sim3(kf->T_cw);
    correction.after[kf.get()] = Sim3(moved(kf->T_cw, S));
  }
  int kept = 0;
  for (const auto& p : kf5->points)
    if (p && kept++ < 5) correction.points[p.get()] = S * p->position;
  for (const auto& [id, p] : c.map.points)
    if (!p->observations.count(kf5)) correction.points[p.get()] = S * p->position;
  applyCorrection(c.map, correction, {1.0});

  EXPECT_NEAR(kf5->scale(), S.s, 1e-9);
  expectPose(moved(T_frame, S), kf5->poseOf(frame), "the frame posed on keyframe 5");
}

TEST(MapCorrection, ACulledKeyframeFollowsItsClosestNeighbourNotADistantParent) {
  Corridor c;
  // Keyframe 5's spanning tree parent is made the far origin; it shares the most points with 4.
  c.kfs[5]->parent->children.erase(c.kfs[5].get());
  c.kfs[5]->parent = c.kfs[0].get();
  c.map.erase(*c.kfs[5]);
  EXPECT_EQ(c.kfs[5]->anchor, c.kfs[4].get());
}


// After a merge the absorbed map's origin is a root without a parent and no longer the origin:
// the node that merged can cull it, and the global map it then sends leaves it out. Where that
// map arrives, the keyframe (and the frames tracking posed from it) must move with its
// neighbours, not stay in the absorbed map's old frame.
void aRootLeftOutOfTheCorrectionMovesWithItsNeighbours(bool rigid) {
  Corridor c;
  KeyFrame* root = c.kfs[0].get();
  ASSERT_EQ(root->parent, nullptr);
  c.map.origin = c.kfs[5].get();  // the map that absorbed it has its own origin
  Eigen::Isometry3d T_frame = root->T_cw;
  T_frame.translation() += Eigen::Vector3d(0.03, -0.01, 0.02);
  const RelativePose frame = root->relative(T_frame);
  const Eigen::Isometry3d T_root = root->T_cw;
  const Sim3 S = someSimilarity();
  PoseCorrection correction;
  for (const auto& [id, kf] : c.map.keyframes) {
    if (kf.get() == root) continue;
    correction.before[kf.get()] = Sim3(kf->T_cw);
    correction.after[kf.get()] = rigid ? Sim3(moved(kf->T_cw, S)) : Sim3(kf->T_cw) * S.inverse();
  }
  if (rigid)
    for (const auto& [id, p] : c.map.points) correction.points[p.get()] = S * p->position;
  applyCorrection(c.map, correction, {1.0});
  expectPose(moved(T_root, S), root->pose(), "the root");
  expectPose(moved(T_frame, S), root->poseOf(frame), "a frame posed from it");
  // Culled here afterwards (the sender no longer has it), it stays where it now is.
  c.map.erase(*root);
  expectPose(moved(T_root, S), root->pose(), "the culled root");
}

TEST(MapCorrection, AMergedMapsRootLeftOutOfARigidCorrectionMovesWithItsNeighbours) {
  aRootLeftOutOfTheCorrectionMovesWithItsNeighbours(true);
}

TEST(MapCorrection, AMergedMapsRootLeftOutOfASimilarityCorrectionMovesWithItsNeighbours) {
  aRootLeftOutOfTheCorrectionMovesWithItsNeighbours(false);
}

// A point whose last observer was culled has nothing to follow a correction by. Left where it
// was, it stayed in the old frame (blackout's 3-node runs ended with dozens such points, some
// behind the frames that had tracked them); it leaves the map, and the erasure is journalled for
// the other nodes. A point the correction places (a global BA's) stays, observed or not.
TEST(MapCorrection, APointNoKeyframeSeesLeavesTheMapAtACorrection) {
  Corridor c;
  c.map.journal_on = true;
  // The last point (x = 2.57) is seen by the last keyframe only.
  MapPoint* lonely = c.points.back().get();
  ASSERT_EQ(lonely->observations.size(), 1u);
  KeyFrame* only = lonely->observations.begin()->first;
  ASSERT_NE(only, c.map.origin);
  c.map.erase(*only);
  ASSERT_TRUE(lonely->observations.empty());
  // Point 1 is unseen too but placed by the correction.
  MapPoint* placed = c.points[1].get();
  for (auto [kf, i] : std::vector<std::pair<KeyFrame*, int>>(placed->observations.begin(), placed->observations.end())) {
    kf->points[static_cast<size_t>(i)].reset();
    placed->observations.erase(kf);
  }
  ASSERT_TRUE(placed->observations.empty());
  std::vector<Id> unseen;  // the lonely point among them: the last keyframe saw a few alone
  for (const auto& p : c.points)
    if (p->observations.empty() && p.get() != placed) unseen.push_back(p->id);
  const Eigen::Vector3d seen_before = c.points[60]->position;

  const Sim3 S = someSimilarity();
  PoseCorrection correction;
  for (const auto& [id, kf] : c.map.keyframes) {
    correction.before[kf.get()] = Sim3(kf->T_cw);
    correction.after[kf.get()] = Sim3(kf->T_cw) * S.inverse();
  }
  correction.points[placed] = S * placed->position;
  applyCorrection(c.map, correction, {1.0});

  EXPECT_TRUE(lonely->bad);
  EXPECT_EQ(c.map.points.count(lonely->id), 0u);
  std::vector<Id> erased = c.map.journal.erased_points;
  std::sort(erased.begin(), erased.end());
  EXPECT_EQ(erased, unseen);
  EXPECT_FALSE(placed->bad);
  EXPECT_EQ(c.map.points.count(placed->id), 1u);
  EXPECT_LT((c.points[60]->position - S * seen_before).norm(), 1e-9);
}

}  // namespace
}  // namespace hiveslam::core
