#include "core/place/keyframe_database.hpp"

#include <algorithm>
#include <map>

namespace hiveslam::core {

void KeyframeDatabase::add(KeyFrame* kf, Map* map) {
  std::lock_guard lock(mutex_);
  if (!map_of_.emplace(kf, map).second) return;
  for (const auto& [w, x] : kf->bow) index_[w].push_back(kf);
}

void KeyframeDatabase::erase(KeyFrame* kf) {
  std::lock_guard lock(mutex_);
  if (!map_of_.erase(kf)) return;
  for (const auto& [w, x] : kf->bow) {
    auto it = index_.find(w);
    if (it == index_.end()) continue;
    auto& list = it->second;
    if (auto at = std::find(list.begin(), list.end(), kf); at != list.end()) list.erase(at);
  }
}

void KeyframeDatabase::moveMap(Map* from, Map* to) {
  std::lock_guard lock(mutex_);
  for (auto& [kf, m] : map_of_)
    if (m == from) m = to;
}

size_t KeyframeDatabase::size() const {
  std::lock_guard lock(mutex_);
  return map_of_.size();
}

std::vector<PlaceCandidate> KeyframeDatabase::query(const place::BowVector& bow,
                                                    const std::unordered_set<Id>& exclude) const {
  std::lock_guard lock(mutex_);
  // Ordered by id so that ties resolve the same way on every run.
  std::map<KeyFrame*, int, ById> common;
  for (const auto& [w, x] : bow) {
    auto it = index_.find(w);
    if (it == index_.end()) continue;
    for (KeyFrame* kf : it->second)
      if (!exclude.count(kf->id)) ++common[kf];
  }
  int most = 0;
  for (const auto& [kf, n] : common) most = std::max(most, n);
  std::vector<PlaceCandidate> out;
  for (const auto& [kf, n] : common) {
    if (n < 0.8 * most) continue;
    out.push_back({kf, map_of_.at(kf), n, place::scoreL1(bow, kf->bow)});
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.score > b.score; });
  return out;
}

}  // namespace hiveslam::core
