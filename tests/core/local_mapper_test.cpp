// A keyframe can be in its map before local mapping takes its job: a mapping node that joins
// gets it first in the hand-over snapshot, and a tracking node that takes mapping back holds
// the keyframes it sent. Culled as a neighbour meanwhile, it must stay out when its turn comes:
// put back, it lived on in that node's map alone, erased at every other node and in the node's
// own S_full (an ASan run ended with TR a keyframe short of the mapping node).
#include <gtest/gtest.h>

#include "core/mapping/keyframe_insertion.hpp"
#include "core/mapping/local_mapper.hpp"
#include "core/slot_frame.hpp"

namespace hiveslam::core {
namespace {

// Four keyframes 0.2 m apart along x, looking down +z at points 3-5 m away, each seeing all.
struct Row {
  std::shared_ptr<Map> map = std::make_shared<Map>(1);
  std::vector<std::shared_ptr<KeyFrame>> kfs;

  Row() {
    std::vector<std::shared_ptr<MapPoint>> points;
    for (int i = 0; i < 60; ++i) {
      const Eigen::Vector3d X(-1.0 + 0.04 * i, 0.2 * std::sin(i), 3.0 + 2.0 * ((i * 7) % 11) / 10.0);
      points.push_back(std::make_shared<MapPoint>(1000 + static_cast<Id>(i), X, 1));
      map->add(points.back());
    }
    for (int k = 0; k < 4; ++k) {
      const Frame f = testing::slotFrame(points.size());
      Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
      T_cw.translation() = -Eigen::Vector3d(0.2 * k, 0, 0);
      auto kf = std::make_shared<KeyFrame>(static_cast<Id>(k + 1), f, T_cw);
      map->add(kf);
      for (size_t i = 0; i < points.size(); ++i) Map::observe(*kf, static_cast<int>(i), points[i]);
      kfs.push_back(kf);
    }
    map->origin = kfs[0].get();
    for (auto& kf : kfs) kf->updateConnections();
  }
};

TEST(LocalMapper, AKeyframeCulledBeforeItsTurnStaysOutOfTheMap) {
  Row row;
  const std::shared_ptr<KeyFrame> waiting = row.kfs[2];
  {
    std::lock_guard lock(row.map->mutex);
    row.map->erase(*waiting);  // culled while its own job waited in the queue
  }
  ASSERT_TRUE(waiting->bad);
  ASSERT_FALSE(row.map->keyframes.count(waiting->id));

  IdGenerator ids(1);
  LocalMapper mapper(SlamSettings{}, ids, std::vector<double>(8, 1.0));
  bool acknowledged = false;
  mapper.process(row.map, waiting, nullptr, [&] { acknowledged = true; });
  EXPECT_FALSE(row.map->keyframes.count(waiting->id)) << "mapping brought the culled keyframe back";
  EXPECT_TRUE(acknowledged) << "its maker would wait for an acknowledgement that never comes";
  EXPECT_EQ(mapper.stats().keyframes_processed, 0);

  // Nor does inserting it (a loop-closing node's route) bring it back.
  std::lock_guard lock(row.map->mutex);
  insertKeyframe(*row.map, *waiting, std::vector<double>(8, 1.0), nullptr);
  EXPECT_FALSE(row.map->keyframes.count(waiting->id));
  for (const auto& [id, p] : row.map->points) EXPECT_FALSE(p->observations.count(waiting.get())) << "point " << id;
}

// Two copies of one keyframe can be made at a loop-closing node: one from its keyframe message
// (the keyframe subscriber's thread), one from a hand-over snapshot that brings keyframes the
// node lacks (the map handler's), each made while the other was not in the map yet. The second
// to be inserted once linked to itself the points the first did not see (observations are keyed
// by id, so the others kept the first), and the first's neighbours; freed with its message, it
// left them pointing at freed memory (a CI run's LC crashed in MapPoint::update two seconds
// after such a snapshot).
TEST(LocalMapper, ASecondCopyOfAMappedKeyframeLinksNothing) {
  Row row;
  KeyFrame& mapped = *row.kfs[3];
  // The map's copy has lost some of its points since (fused or culled); the message's has them.
  const auto links = mapped.points;
  for (size_t i = 0; i < 10; ++i) {
    mapped.points[i]->observations.erase(&mapped);
    mapped.points[i].reset();
  }
  const auto copyOf = [&] {
    auto copy = std::make_shared<KeyFrame>(mapped.id, mapped.frame, mapped.T_cw);
    copy->points = links;
    return copy;
  };
  const auto linked = [&](const KeyFrame* copy) {
    int n = 0;
    for (const auto& [id, p] : row.map->points)
      for (const auto& [kf, i] : p->observations) n += kf == copy;
    for (const auto& kf : row.kfs)
      for (const auto& [other, w] : kf->covisibility) n += other == copy;
    return n;
  };
  const std::vector<double> scales(8, 1.0);
  auto copy = copyOf();
  {
    std::lock_guard lock(row.map->mutex);
    insertKeyframe(*row.map, *copy, scales, nullptr);
  }
  EXPECT_EQ(row.map->keyframes.at(mapped.id).get(), &mapped);
  EXPECT_TRUE(copy->bad) << "whoever holds the copy would go on mapping with it";
  EXPECT_EQ(linked(copy.get()), 0) << "points or keyframes of the map link to the copy";

  // Local mapping, given a copy, maps nothing with it and acknowledges it.
  IdGenerator ids(1);
  LocalMapper mapper(SlamSettings{}, ids, scales);
  auto second = copyOf();
  const size_t points = row.map->points.size();
  bool acknowledged = false;
  mapper.process(row.map, second, nullptr, [&] { acknowledged = true; });
  EXPECT_TRUE(acknowledged);
  EXPECT_EQ(mapper.stats().keyframes_processed, 0);
  EXPECT_EQ(row.map->points.size(), points);
  EXPECT_EQ(linked(second.get()), 0);
}

}  // namespace
}  // namespace hiveslam::core
