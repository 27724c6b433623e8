#pragma once
// The map whose contents a map holds now, locked. A map merged into another (by this node, or by
// another node's merge applied here) stays in the atlas, emptied, with `merged_into` set: its
// keyframes and points live on in the map it went into, in that map's frame. Work queued or
// begun in the old map (tracking's next frame, a keyframe on its way to mapping or to the wire)
// goes on in the new one.
#include <functional>
#include <memory>
#include <mutex>

#include "core/map/map.hpp"

namespace hiveslam::core {

struct LockedMap {
  std::unique_lock<std::mutex> lock;
  bool moved = false;  // `map` was replaced by the map it was merged into
};

// Locks `map`, or the map it was merged into since, followed through at most 8 merges, and
// replaces `map` with it. `find` gives a map's shared pointer (the atlas's) and is called with
// no map locked; where it finds none, the map stays where it is.
LockedMap lockFollowingMerges(std::shared_ptr<Map>& map, const std::function<std::shared_ptr<Map>(const Map*)>& find);

// The same for a plain pointer, which merged maps keep valid (they stay in the atlas).
std::unique_lock<std::mutex> lockFollowingMerges(Map*& map);

}  // namespace hiveslam::core
