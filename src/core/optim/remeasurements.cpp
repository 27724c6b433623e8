#include "core/optim/remeasurements.hpp"

#include <algorithm>

#include "core/map/keyframe.hpp"
#include "core/map/map_point.hpp"
#include "core/optim/map_ba_problem.hpp"

namespace hiveslam::core {

void mergeRemeasurements(Remeasurements& into, const Remeasurements& from) {
  for (const auto& [keyframe, entries] : from) into[keyframe] = entries;
}

std::vector<int> pointAnchors(const MapBaProblem& mp) {
  const BaProblem& ba = mp.problem;
  std::vector<int> anchor(ba.points.size(), -1);
  for (size_t o = 0; o < ba.observations.size(); ++o) {
    int& a = anchor[static_cast<size_t>(ba.observations[o].point)];
    if (a < 0 || mp.sources[o].first->id < mp.sources[static_cast<size_t>(a)].first->id) a = static_cast<int>(o);
  }
  return anchor;
}

RemeasurementUse applyRemeasurements(MapBaProblem& mp, const Remeasurements& r) {
  RemeasurementUse use;
  const std::vector<int> anchor = pointAnchors(mp);
  for (size_t o = 0; o < mp.sources.size(); ++o) {
    const auto& [kf, idx] = mp.sources[o];
    const size_t point = static_cast<size_t>(mp.problem.observations[o].point);
    const size_t a = static_cast<size_t>(anchor[point]);
    if (a == o) continue;  // anchors are kept as found everywhere
    const auto it = r.find(kf->id);
    const Remeasurement* e = nullptr;
    if (it != r.end()) {
      const auto& entries = it->second;
      const auto found = std::lower_bound(entries.begin(), entries.end(), static_cast<uint32_t>(idx),
                                          [](const Remeasurement& m, uint32_t k) { return m.keypoint < k; });
      if (found != entries.end() && found->keypoint == static_cast<uint32_t>(idx)) e = &*found;
    }
    if (!e) {
      ++use.not_measured;
      continue;
    }
    if (e->point != mp.points[point]->id) {
      ++use.other_point;
      continue;
    }
    const auto& [anchor_kf, anchor_idx] = mp.sources[a];
    if (e->anchor_keyframe != anchor_kf->id || e->anchor_keypoint != static_cast<uint32_t>(anchor_idx)) {
      ++use.other_anchor;
      continue;
    }
    mp.problem.observations[o].uv = kf->frame.points[static_cast<size_t>(idx)] + e->shift.cast<double>();
    ++use.applied;
  }
  return use;
}

size_t remeasurementCount(const Remeasurements& r) {
  size_t n = 0;
  for (const auto& [keyframe, entries] : r) n += entries.size();
  return n;
}

}  // namespace hiveslam::core
