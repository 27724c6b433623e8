#include "core/map/follow_merges.hpp"

namespace hiveslam::core {

LockedMap lockFollowingMerges(std::shared_ptr<Map>& map, const std::function<std::shared_ptr<Map>(const Map*)>& find) {
  LockedMap locked{std::unique_lock(map->mutex)};
  // Each hop unlocks: the atlas's lock is never taken under a map's. A merge that goes on
  // merging (A into B, B into C meanwhile) is followed; 8 hops bound a map the finder never finds.
  for (int hops = 0; map->merged_into.load() && find && hops < 8; ++hops) {
    const Map* into = map->resolve();
    locked.lock.unlock();
    if (auto next = find(into)) {
      map = std::move(next);
      locked.moved = true;
    }
    locked.lock = std::unique_lock(map->mutex);
  }
  return locked;
}

std::unique_lock<std::mutex> lockFollowingMerges(Map*& map) {
  map = map->resolve();
  std::unique_lock lock(map->mutex);
  // Merged again between resolve() and the lock.
  while (map->merged_into.load()) {
    lock.unlock();
    map = map->resolve();
    lock = std::unique_lock(map->mutex);
  }
  return lock;
}

}  // namespace hiveslam::core
