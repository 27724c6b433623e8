#include "core/map/map.hpp"

namespace hiveslam::core {

void Map::observe(KeyFrame& kf, int index, const std::shared_ptr<MapPoint>& p) {
  kf.points[static_cast<size_t>(index)] = p;
  p->observations[&kf] = index;
}

void Map::erase(MapPoint& p) {
  // Only a point of this map: a module still holding a point of a map merged into another (or
  // already erased) must not mark it bad there while it stays listed and linked.
  auto it = points.find(p.id);
  if (it == points.end() || it->second.get() != &p) return;
  p.bad = true;
  for (const auto& [kf, idx] : p.observations) kf->points[static_cast<size_t>(idx)].reset();
  p.observations.clear();
  erased_points.push_back(it->second);
  points.erase(it);
  if (journal_on) journal.erased_points.push_back(p.id);
}

void Map::replace(MapPoint& old, const std::shared_ptr<MapPoint>& by) {
  if (&old == by.get()) return;
  auto mine = [&](const MapPoint& p) {
    auto it = points.find(p.id);
    return it != points.end() && it->second.get() == &p;
  };
  if (!mine(old) || !mine(*by)) return;
  for (const auto& [kf, idx] : old.observations) {
    if (by->observations.count(kf)) {
      kf->points[static_cast<size_t>(idx)].reset();  // already sees `by` at another keypoint
    } else {
      observe(*kf, idx, by);
    }
  }
  by->visible += old.visible;
  by->found += old.found;
  old.observations.clear();
  old.bad = true;
  auto it = points.find(old.id);
  erased_points.push_back(it->second);
  points.erase(it);
  if (journal_on) journal.replaced_points.emplace_back(old.id, by->id);
}

void Map::absorb(Map& other) {
  for (auto& [id, k] : other.keyframes) keyframes[id] = k;
  for (auto& [id, p] : other.points) points[id] = p;
  retired.insert(retired.end(), other.retired.begin(), other.retired.end());
  erased_points.insert(erased_points.end(), other.erased_points.begin(), other.erased_points.end());
  other.keyframes.clear();
  other.points.clear();
  other.retired.clear();
  other.erased_points.clear();
  ++other.epoch;
  other.merged_into = this;
}

void Map::erase(KeyFrame& kf) {
  if (&kf == origin) return;  // the origin anchors the map's coordinate frame
  auto it = keyframes.find(kf.id);
  if (it == keyframes.end() || it->second.get() != &kf) return;  // not (or no longer) this map's
  // The anchor is the live keyframe sharing the most points: a close neighbour, where the
  // spanning tree parent can be one that is far away by now (culled parents pass their children
  // up the tree), and a correction that bends or rescales the map between them would carry
  // over.
  KeyFrame* anchor = kf.parent;
  int most = 0;
  for (const auto& [other, w] : kf.covisibility)
    if (!other->bad && (w > most || (w == most && anchor && other->id < anchor->id))) {
      anchor = other;
      most = w;
    }
  if (anchor) {
    kf.from_anchor = anchor->relative(kf.T_cw);
    kf.anchor = anchor;
  }
  kf.bad = true;
  for (auto& p : kf.points)
    if (p) {
      p->observations.erase(&kf);
      p.reset();
    }
  for (auto& [other, w] : kf.covisibility) other->covisibility.erase(&kf);
  for (KeyFrame* other : kf.loop_edges) other->loop_edges.erase(&kf);
  kf.loop_edges.clear();
  // Children are re-parented to this keyframe's parent (keeps the spanning tree connected).
  for (KeyFrame* child : kf.children) {
    child->parent = kf.parent;
    if (kf.parent) kf.parent->children.insert(child);
  }
  if (kf.parent) kf.parent->children.erase(&kf);
  kf.children.clear();
  retired.push_back(it->second);
  keyframes.erase(it);
  if (journal_on) journal.erased_keyframes.push_back(kf.id);
}

}  // namespace hiveslam::core
