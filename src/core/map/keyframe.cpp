#include "core/map/keyframe.hpp"

#include <algorithm>
#include <unordered_map>

#include "core/map/map_point.hpp"

namespace hiveslam::core {

std::vector<KeyFrame*> KeyFrame::bestCovisible(size_t n) const {
  std::vector<std::pair<int, KeyFrame*>> v;
  for (const auto& [kf, w] : covisibility)
    if (!kf->bad) v.emplace_back(w, kf);
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second->id < b.second->id); });
  std::vector<KeyFrame*> out;
  for (size_t i = 0; i < v.size() && i < n; ++i) out.push_back(v[i].second);
  return out;
}

void KeyFrame::updateConnections() {
  // A hash map: this runs for every keyframe of every local map a node applies, and the
  // ordered map's insertions were most of its cost. Nothing below depends on the order (the
  // strongest neighbour breaks ties by id).
  std::unordered_map<KeyFrame*, int> counts;
  counts.reserve(64);
  for (const auto& p : points) {
    if (!p || p->bad) continue;
    for (const auto& [kf, idx] : p->observations)
      if (kf != this && !kf->bad) ++counts[kf];
  }
  // Drop this keyframe from its old neighbours, then connect with weights of at least 15
  // (or the strongest one when none reaches it).
  for (auto& [kf, w] : covisibility) kf->covisibility.erase(this);
  covisibility.clear();
  KeyFrame* strongest = nullptr;
  int strongest_w = 0;
  for (const auto& [kf, w] : counts) {
    if (w > strongest_w || (w == strongest_w && strongest && kf->id < strongest->id)) {
      strongest = kf;
      strongest_w = w;
    }
    if (w >= 15) {
      covisibility[kf] = w;
      kf->covisibility[this] = w;
    }
  }
  if (covisibility.empty() && strongest) {
    covisibility[strongest] = strongest_w;
    strongest->covisibility[this] = strongest_w;
  }
  if (!parent && strongest && strongest->id < id) {
    parent = strongest;
    strongest->children.insert(this);
  }
}

int KeyFrame::trackedPoints(int min_observations) const {
  int n = 0;
  for (const auto& p : points)
    if (p && !p->bad && static_cast<int>(p->observations.size()) >= min_observations) ++n;
  return n;
}

}  // namespace hiveslam::core
