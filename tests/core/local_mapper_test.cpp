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

}  // namespace
}  // namespace hiveslam::core
