// The covisibility graph: a keyframe's neighbours are the keyframes sharing at least 15 of its
// points (or the one sharing most when none does), weighted by the count, on both sides, and
// listed by keyframe id whatever order they came in.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/map/map.hpp"
#include "core/slot_frame.hpp"

namespace hiveslam::core {
namespace {

std::shared_ptr<KeyFrame> keyframe(Id id, size_t slots) {
  return std::make_shared<KeyFrame>(id, testing::slotFrame(slots), Eigen::Isometry3d::Identity());
}

std::vector<Id> ids(const FlatMapById<KeyFrame, int>& m) {
  std::vector<Id> out;
  for (const auto& [kf, w] : m) out.push_back(kf->id);
  return out;
}

TEST(FlatMapById, IteratesByIdWhateverTheInsertionOrder) {
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  for (Id id = 0; id < 40; ++id) kfs.push_back(keyframe(id * 7 % 40, 1));  // ids shuffled
  std::shuffle(kfs.begin(), kfs.end(), std::mt19937(3));
  FlatMapById<KeyFrame, int> m;
  for (const auto& kf : kfs) m[kf.get()] = static_cast<int>(kf->id) * 2;
  std::vector<Id> expected(40);
  for (Id id = 0; id < 40; ++id) expected[id] = id;
  EXPECT_EQ(ids(m), expected);
  for (const auto& kf : kfs) {
    ASSERT_EQ(m.count(kf.get()), 1u);
    EXPECT_EQ(m.at(kf.get()), static_cast<int>(kf->id) * 2);
    EXPECT_EQ(m.find(kf.get())->first, kf.get());
  }
  // Assigning again overwrites; erasing by key and by position keeps the rest in order.
  m[kfs[0].get()] = -1;
  EXPECT_EQ(m.size(), 40u);
  EXPECT_EQ(m.at(kfs[0].get()), -1);
  EXPECT_EQ(m.erase(kfs[1].get()), 1u);
  EXPECT_EQ(m.erase(kfs[1].get()), 0u);
  m.erase(m.find(kfs[2].get()));
  EXPECT_EQ(m.size(), 38u);
  EXPECT_EQ(m.count(kfs[1].get()), 0u);
  EXPECT_EQ(m.find(kfs[2].get()), m.end());
  EXPECT_THROW(m.at(kfs[2].get()), std::out_of_range);
  EXPECT_TRUE(std::is_sorted(m.begin(), m.end(), [](const auto& a, const auto& b) { return a.first->id < b.first->id; }));
}

// A keyframe seeing 100 points; neighbour k (k = 1..n) sees the first `shared(k)` of them.
struct Star {
  Map map{1};
  std::shared_ptr<KeyFrame> centre;
  std::vector<std::shared_ptr<KeyFrame>> others;
  std::vector<std::shared_ptr<MapPoint>> points;

  Star(int n, int (*shared)(int)) {
    centre = keyframe(100000, 100);
    map.add(centre);
    for (int i = 0; i < 100; ++i) {
      points.push_back(std::make_shared<MapPoint>(500000 + static_cast<Id>(i), Eigen::Vector3d(0, 0, 1), centre->id));
      map.add(points.back());
      Map::observe(*centre, i, points.back());
    }
    // Made in reverse id order, so that neither address nor creation order is id order.
    for (int k = n; k >= 1; --k) {
      auto kf = keyframe(static_cast<Id>(k), 100);
      map.add(kf);
      for (int i = 0; i < shared(k); ++i) Map::observe(*kf, i, points[static_cast<size_t>(i)]);
      others.push_back(kf);
    }
    std::reverse(others.begin(), others.end());  // others[k - 1] has id k
  }
};

TEST(Covisibility, WeightsAreSharedPointsKeptFromFifteenOnBothSides) {
  Star s(30, [](int k) { return k; });  // neighbour k shares k points
  s.centre->updateConnections();
  std::vector<Id> expected;
  for (Id k = 15; k <= 30; ++k) expected.push_back(k);
  EXPECT_EQ(ids(s.centre->covisibility), expected);
  for (int k = 1; k <= 30; ++k) {
    KeyFrame* o = s.others[static_cast<size_t>(k - 1)].get();
    if (k >= 15) {
      EXPECT_EQ(s.centre->covisibility.at(o), k);
      EXPECT_EQ(o->covisibility.at(s.centre.get()), k);
    } else {
      EXPECT_EQ(o->covisibility.count(s.centre.get()), 0u);
    }
  }
  // The strongest neighbour with a lower id becomes the spanning tree parent.
  EXPECT_EQ(s.centre->parent, s.others[29].get());

  // An erased neighbour leaves both sides; an erased point lowers the weights it was part of.
  s.map.erase(*s.others[29]);
  s.map.erase(*s.points[0]);
  s.centre->updateConnections();
  expected.pop_back();
  expected.erase(expected.begin());  // 15 shared 15 points, one of them now gone
  EXPECT_EQ(ids(s.centre->covisibility), expected);
  EXPECT_EQ(s.centre->covisibility.at(s.others[20].get()), 20);
  EXPECT_EQ(s.others[14]->covisibility.count(s.centre.get()), 0u);
}

TEST(Covisibility, WithoutFifteenSharedPointsTheStrongestNeighbourStaysLinked) {
  Star s(10, [](int k) { return k == 4 || k == 7 ? 9 : 3; });  // ties at 9: the lower id wins
  s.centre->updateConnections();
  EXPECT_EQ(ids(s.centre->covisibility), std::vector<Id>{4});
  EXPECT_EQ(s.centre->covisibility.at(s.others[3].get()), 9);
  EXPECT_EQ(s.others[3]->covisibility.at(s.centre.get()), 9);
}

TEST(Covisibility, ManyNeighboursAreAllCounted) {
  // Past the counting table's first size (256 slots, half full at most).
  Star s(600, [](int k) { return 15 + k % 80; });
  s.centre->updateConnections();
  ASSERT_EQ(s.centre->covisibility.size(), 600u);
  for (int k = 1; k <= 600; ++k) EXPECT_EQ(s.centre->covisibility.at(s.others[static_cast<size_t>(k - 1)].get()), 15 + k % 80);
  // The same counts again from a table that has grown.
  s.centre->updateConnections();
  EXPECT_EQ(s.centre->covisibility.size(), 600u);
}

}  // namespace
}  // namespace hiveslam::core
