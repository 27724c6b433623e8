#include "core/optim/map_ba_problem.hpp"

#include <algorithm>
#include <unordered_map>

namespace hiveslam::core {

MapBaProblem buildMapBaProblem(const Map& map, const std::vector<double>& level_scales) {
  MapBaProblem out;
  // By id, so that the same map always gives the same problem (repeatable runs).
  for (const auto& [id, k] : map.keyframes)
    if (!k->bad) out.keyframes.push_back(k.get());
  std::sort(out.keyframes.begin(), out.keyframes.end(), [](KeyFrame* a, KeyFrame* b) { return a->id < b->id; });
  if (out.keyframes.empty()) return out;
  BaProblem& ba = out.problem;
  ba.K = out.keyframes.front()->frame.K;
  std::unordered_map<const KeyFrame*, int> index;
  for (KeyFrame* k : out.keyframes) {
    index[k] = static_cast<int>(ba.poses.size());
    ba.poses.push_back({Eigen::Quaterniond(k->T_cw.linear()), k->T_cw.translation(), k == map.origin});
  }
  for (const auto& [id, p] : map.points)
    if (!p->bad && p->observations.size() >= 2) out.points.push_back(p.get());
  std::sort(out.points.begin(), out.points.end(), [](MapPoint* a, MapPoint* b) { return a->id < b->id; });
  for (size_t i = 0; i < out.points.size(); ++i) {
    MapPoint* p = out.points[i];
    for (const auto& [k, idx] : p->observations) {
      auto it = index.find(k);
      if (it == index.end()) continue;
      const auto& kp = k->frame.keypoints[static_cast<size_t>(idx)];
      ba.observations.push_back({it->second, static_cast<int>(i), k->frame.points[static_cast<size_t>(idx)],
                                 1.0 / level_scales[static_cast<size_t>(kp.octave)]});
      out.sources.emplace_back(k, idx);
    }
    ba.points.push_back({p->position, false});
  }
  return out;
}

}  // namespace hiveslam::core
