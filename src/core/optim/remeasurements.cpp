#include "core/optim/remeasurements.hpp"

#include <algorithm>

#include "core/map/keyframe.hpp"
#include "core/optim/map_ba_problem.hpp"

namespace hiveslam::core {

void mergeRemeasurements(Remeasurements& into, const Remeasurements& from) {
  for (const auto& [keyframe, entries] : from) into[keyframe] = entries;
}

size_t applyRemeasurements(MapBaProblem& mp, const Remeasurements& r) {
  size_t applied = 0;
  for (size_t o = 0; o < mp.sources.size(); ++o) {
    const auto& [kf, idx] = mp.sources[o];
    const auto it = r.find(kf->id);
    if (it == r.end()) continue;
    const auto& entries = it->second;
    const auto e = std::lower_bound(entries.begin(), entries.end(), static_cast<uint32_t>(idx),
                                    [](const Remeasurement& m, uint32_t k) { return m.keypoint < k; });
    if (e == entries.end() || e->keypoint != static_cast<uint32_t>(idx)) continue;
    mp.problem.observations[o].uv = kf->frame.points[static_cast<size_t>(idx)] + e->shift.cast<double>();
    ++applied;
  }
  return applied;
}

size_t remeasurementCount(const Remeasurements& r) {
  size_t n = 0;
  for (const auto& [keyframe, entries] : r) n += entries.size();
  return n;
}

}  // namespace hiveslam::core
