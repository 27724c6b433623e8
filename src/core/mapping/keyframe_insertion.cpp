#include "core/mapping/keyframe_insertion.hpp"

namespace hiveslam::core {

void insertKeyframe(Map& map, KeyFrame& kf, const std::vector<double>& scales, KeyframeDatabase* database) {
  if (kf.bad) return;  // culled while it waited (see the header)
  if (auto it = map.keyframes.find(kf.id); it != map.keyframes.end() && it->second.get() != &kf) {
    kf.bad = true;  // another copy of it is mapped (see the header)
    return;
  }
  // The map moved (loop correction, global BA) while this keyframe waited in a queue: it moves
  // with the keyframe tracking posed it against.
  if (kf.made_in_epoch != map.epoch && kf.made_from) kf.T_cw = kf.made_from->poseOf(kf.made_pose);
  kf.made_in_epoch = map.epoch;
  if (!map.keyframes.count(kf.id)) {
    map.add(kf.shared_from_this());
    // In the database as soon as it is in the map: relocalization finds it even without loop
    // closing.
    if (database) database->add(&kf, &map);
  }
  for (size_t i = 0; i < kf.points.size(); ++i) {
    auto& p = kf.points[i];
    if (!p) continue;
    if (p->bad) {
      p.reset();
      continue;
    }
    if (!p->observations.count(&kf)) {
      Map::observe(kf, static_cast<int>(i), p);
      p->update(scales);
    }
  }
  kf.updateConnections();
}

}  // namespace hiveslam::core
