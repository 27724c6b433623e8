#include "distribution/state_integrator.hpp"

#include <algorithm>
#include <cstring>
#include <set>
#include <unordered_set>

#include "core/loop/map_correction.hpp"
#include "core/mapping/keyframe_insertion.hpp"

namespace hiveslam::distribution {

namespace {

// Highest counter value per creating node among `ids`: objects of that node below it were
// known to the sender when it took its snapshot.
std::unordered_map<uint16_t, Id> newestByNode(const std::vector<Id>& ids) {
  std::unordered_map<uint16_t, Id> newest;
  for (Id id : ids) {
    auto& n = newest[core::IdGenerator::node(id)];
    n = std::max(n, id);
  }
  return newest;
}

bool olderThanSnapshot(Id id, const std::unordered_map<uint16_t, Id>& newest) {
  auto it = newest.find(core::IdGenerator::node(id));
  return it != newest.end() && id < it->second;
}

}  // namespace

std::shared_ptr<core::Map> StateIntegrator::mapFor(Id id) {
  if (auto m = slam_.findMap(id)) return m->merged_into.load() ? nullptr : m;
  auto m = std::make_shared<core::Map>(id);
  m->journal_on = true;
  slam_.addMap(m);
  return m;
}

void StateIntegrator::applyPoint(core::Map& map, const PointRecord& r, bool authoritative) {
  auto it = map.points.find(r.id);
  std::shared_ptr<core::MapPoint> p;
  if (it != map.points.end()) {
    p = it->second;
    p->position = r.position;
  } else {
    if (!r.full) return;  // its full record is on the way (or it was erased meanwhile)
    // Erased here; the sender had not heard of it yet. Brought back, it would live on as a
    // duplicate of the point that replaced it, and only here.
    if (!authoritative && observer_.erasedPoint(r.id)) return;
    p = std::make_shared<core::MapPoint>(r.id, r.position, r.first_keyframe);
    map.add(p);
  }
  if (r.full) {
    p->descriptor = cv::Mat(1, 32, CV_8U);
    std::memcpy(p->descriptor.ptr<uint8_t>(), r.descriptor.data(), 32);
    p->normal = r.normal;
    p->min_distance = r.min_distance;
    p->max_distance = r.max_distance;
  }
}

bool StateIntegrator::relink(core::Map& map, core::KeyFrame& kf, const KeyFrameRecord& r) {
  if (!r.links) return false;
  bool changed = false;
  std::vector<std::shared_ptr<core::MapPoint>> want(kf.points.size());
  for (const auto& [i, pid] : r.matches) {
    if (i >= want.size()) continue;
    if (auto it = map.points.find(pid); it != map.points.end()) want[i] = it->second;
  }
  for (size_t i = 0; i < want.size(); ++i) {
    auto& have = kf.points[i];
    if (have == want[i]) continue;
    changed = true;
    if (have) {
      have->observations.erase(&kf);
      have.reset();
    }
  }
  for (size_t i = 0; i < want.size(); ++i) {
    if (!want[i] || kf.points[i] == want[i]) continue;
    changed = true;
    // The point may still be linked at another keypoint of this keyframe (not in the record).
    if (auto o = want[i]->observations.find(&kf); o != want[i]->observations.end())
      kf.points[static_cast<size_t>(o->second)].reset();
    core::Map::observe(kf, static_cast<int>(i), want[i]);
  }
  if (r.parent != kNoId && (!kf.parent || kf.parent->id != r.parent)) {
    if (auto it = map.keyframes.find(r.parent); it != map.keyframes.end() && it->second.get() != &kf) {
      if (kf.parent) kf.parent->children.erase(&kf);
      kf.parent = it->second.get();
      kf.parent->children.insert(&kf);
    }
  }
  for (Id l : r.loop_edges)
    if (auto it = map.keyframes.find(l); it != map.keyframes.end()) {
      kf.loop_edges.insert(it->second.get());
      it->second->loop_edges.insert(&kf);
    }
  return changed;
}

void StateIntegrator::applyErasures(core::Map& map, const MapRecord& m) {
  for (const auto& [old, by] : m.replaced_points) {
    auto o = map.points.find(old);
    if (o == map.points.end()) continue;
    auto b = map.points.find(by);
    if (b != map.points.end())
      map.replace(*o->second, b->second);
    else
      map.erase(*o->second);
  }
  for (Id id : m.erased_points)
    if (auto it = map.points.find(id); it != map.points.end()) map.erase(*it->second);
  for (Id id : m.erased_keyframes)
    if (auto it = map.keyframes.find(id); it != map.keyframes.end()) {
      core::KeyFrame* kf = it->second.get();
      map.erase(*kf);
      slam_.database().erase(kf);
    }
}

std::shared_ptr<core::KeyFrame> StateIntegrator::makeKeyframe(const KeyFrameRecord& r) const {
  auto kf = std::make_shared<core::KeyFrame>(r.id, r.frame, r.T_cw);
  if (const auto* v = slam_.vocabulary(); v && !v->empty()) v->transform(kf->frame.descriptors, kf->bow, kf->bow_features);
  kf->made_in_epoch = r.made_in_epoch;
  kf->T_made_from = r.T_made_from;
  return kf;
}

StateIntegrator::Added StateIntegrator::addKeyframe(const KeyFrameMessage& m) {
  Added out;
  auto map = mapFor(m.keyframe.map);
  if (!map) return out;
  // Features and bag of words are computed before the lock.
  std::vector<std::shared_ptr<core::KeyFrame>> companions;
  for (const auto& c : m.companions) companions.push_back(makeKeyframe(c));
  auto kf = makeKeyframe(m.keyframe);
  {
    std::lock_guard lock(map->mutex);
    if (map->keyframes.count(kf->id)) return out;
    for (const auto& p : m.points) applyPoint(*map, p);
    for (size_t i = 0; i < companions.size(); ++i) {
      auto& c = companions[i];
      if (map->keyframes.count(c->id)) continue;
      map->add(c);
      slam_.database().add(c.get(), map.get());
      relink(*map, *c, m.companions[i]);
      if (!map->origin) map->origin = c.get();
    }
    if (m.keyframe.made_from != kNoId)
      if (auto it = map->keyframes.find(m.keyframe.made_from); it != map->keyframes.end())
        kf->made_from = it->second.get();
    // Links as the sender had them; local mapping's insertion makes the observations.
    for (const auto& [i, pid] : m.keyframe.matches)
      if (auto it = map->points.find(pid); it != map->points.end() && i < kf->points.size()) kf->points[i] = it->second;
    if (!map->origin) map->origin = kf.get();
    for (auto& c : companions) c->updateConnections();
    for (const auto& s : m.stats)
      if (auto it = map->points.find(s.id); it != map->points.end()) {
        it->second->visible = std::max(it->second->visible, static_cast<int>(s.visible));
        it->second->found = std::max(it->second->found, static_cast<int>(s.found));
      }
  }
  for (const auto& p : m.points) observer_.record(p);
  for (const auto& c : m.companions) observer_.record(c);
  observer_.record(m.keyframe);
  out.map = map;
  out.keyframe = kf;
  return out;
}

void StateIntegrator::applyLocal(const MapRecord& m, bool stale) {
  auto map = slam_.findMap(m.map);
  if (!map || map->merged_into.load()) return;
  std::lock_guard lock(map->mutex);
  if (stale) {
    for (const auto& p : m.points)
      if (!map->points.count(p.id)) {
        applyPoint(*map, p);
        observer_.record(p);
      }
    applyErasures(*map, m);
    for (Id id : m.erased_keyframes) observer_.eraseKeyframe(id);
    for (Id id : m.erased_points) observer_.erasePoint(id);
    for (const auto& [old, by] : m.replaced_points) observer_.erasePoint(old);
    return;
  }
  observer_.record(m);
  for (const auto& p : m.points) applyPoint(*map, p);
  // Covisibility is rebuilt only where links changed: most of a window's keyframes come with a
  // new pose and the same points, and rebuilding them all was most of this node's map
  // handling at TR.
  std::set<core::KeyFrame*, core::ById> relinked;  // by id: the rebuild order is the same on every node
  for (const auto& k : m.keyframes) {
    auto it = map->keyframes.find(k.id);
    if (it == map->keyframes.end()) continue;
    it->second->T_cw = k.T_cw;
    if (relink(*map, *it->second, k)) relinked.insert(it->second.get());
  }
  const auto observers = [&](Id point) {
    if (auto it = map->points.find(point); it != map->points.end())
      for (const auto& [kf, i] : it->second->observations) relinked.insert(kf);
  };
  for (const auto& [old, by] : m.replaced_points) {
    observers(old);
    observers(by);
  }
  for (Id id : m.erased_points) observers(id);
  applyErasures(*map, m);
  for (core::KeyFrame* kf : relinked)
    if (!kf->bad) kf->updateConnections();
}

void StateIntegrator::applyGlobal(const std::vector<MapRecord>& batches, bool authoritative) {
  if (batches.empty()) return;
  if (authoritative)
    for (const auto& b : batches) observer_.revive(b);
  for (const auto& b : batches) observer_.record(b);
  auto map = slam_.findMap(batches.front().map);
  if (!map || map->merged_into.load()) return;
  // Maps merged into this one move over first, as they are (the records below re-pose them).
  for (const auto& b : batches)
    for (Id merged : b.merged_maps) {
      auto other = slam_.findMap(merged);
      if (!other || other == map || other->merged_into.load()) continue;
      std::scoped_lock both(map->mutex, other->mutex);
      map->absorb(*other);
      slam_.database().moveMap(other.get(), map.get());
    }
  std::lock_guard lock(map->mutex);
  // One correction: covered keyframes go to their new poses, the others follow their ancestors.
  core::PoseCorrection c;
  std::vector<Id> kf_ids, point_ids;
  for (const auto& b : batches) {
    for (const auto& k : b.keyframes) {
      kf_ids.push_back(k.id);
      if (auto it = map->keyframes.find(k.id); it != map->keyframes.end()) {
        c.before[it->second.get()] = core::Sim3(it->second->T_cw);
        c.after[it->second.get()] = core::Sim3(k.T_cw);
      }
    }
    for (const auto& p : b.points) {
      point_ids.push_back(p.id);
      if (auto it = map->points.find(p.id); it != map->points.end()) c.points[it->second.get()] = p.position;
    }
  }
  core::applyCorrection(*map, c, slam_.scales());
  for (const auto& b : batches)
    for (const auto& p : b.points) applyPoint(*map, p, authoritative);
  for (const auto& b : batches)
    for (const auto& k : b.keyframes)
      if (auto it = map->keyframes.find(k.id); it != map->keyframes.end()) {
        it->second->T_cw = k.T_cw;
        relink(*map, *it->second, k);
      }
  for (const auto& b : batches) applyErasures(*map, b);
  if (authoritative) {
    // What the sender no longer has (culled or fused while this node was not listening) goes,
    // except what it could not have known yet when it took the snapshot.
    const auto newest_kf = newestByNode(kf_ids);
    const auto newest_point = newestByNode(point_ids);
    const std::unordered_set<Id> kfs(kf_ids.begin(), kf_ids.end()), pts(point_ids.begin(), point_ids.end());
    std::vector<core::KeyFrame*> gone_kfs;
    for (const auto& [id, k] : map->keyframes)
      if (!kfs.count(id) && olderThanSnapshot(id, newest_kf) && k.get() != map->origin) gone_kfs.push_back(k.get());
    for (core::KeyFrame* k : gone_kfs) {
      map->erase(*k);
      slam_.database().erase(k);
    }
    std::vector<core::MapPoint*> gone_points;
    for (const auto& [id, p] : map->points)
      if (!pts.count(id) && olderThanSnapshot(id, newest_point)) gone_points.push_back(p.get());
    for (core::MapPoint* p : gone_points) map->erase(*p);
    observer_.prune(kfs, pts, [&](Id id) { return olderThanSnapshot(id, newest_kf) || olderThanSnapshot(id, newest_point); });
  }
  for (const auto& [id, k] : map->keyframes) k->updateConnections();
}

}  // namespace hiveslam::distribution
