#include "distribution/state_integrator.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <optional>
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

// A map first heard of from another node; its erasures are journalled like a map made here.
std::shared_ptr<core::Map> receivedMap(Id id) {
  auto m = std::make_shared<core::Map>(id);
  m->journal_on = true;
  return m;
}

}  // namespace

std::shared_ptr<core::Map> StateIntegrator::mapFor(Id id) {
  if (auto m = slam_.findMap(id)) return m->merged_into.load() ? nullptr : m;
  auto m = receivedMap(id);
  slam_.addMap(m);
  return m;
}

bool StateIntegrator::applyPoint(core::Map& map, const PointRecord& r, bool authoritative) {
  auto it = map.points.find(r.id);
  std::shared_ptr<core::MapPoint> p;
  if (it != map.points.end()) {
    p = it->second;
    p->position = r.position;
  } else {
    if (!r.full) return false;  // its full record is on the way (or it was erased meanwhile)
    // Erased here; the sender had not heard of it yet. Brought back, it would live on as a
    // duplicate of the point that replaced it, and only here.
    if (!authoritative && observer_.erasedPoint(r.id)) return false;
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
  return true;
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
  kf->made_pose.T_c_k = r.T_made_from;  // its scale, this node's, is set once the map is locked
  return kf;
}

void StateIntegrator::noteEpoch(const core::Map& map, uint64_t label) {
  Frame f;
  f.core_epoch = map.epoch;
  f.scales.reserve(map.keyframes.size());
  for (const auto& [id, kf] : map.keyframes) f.scales.emplace(id, kf->scale());
  for (const auto& kf : map.retired) f.scales.emplace(kf->id, kf->scale());  // tracking posed some from these
  std::lock_guard lock(epochs_mutex_);
  auto& frames = epochs_[map.id];
  frames[label] = std::move(f);
  // A sender can be several updates behind: a global map takes a second or more to send, and
  // a loop brings two (the correction, then its global BA) on top of any periodic global BA.
  while (frames.size() > kLabelsKept) frames.erase(frames.begin());
}

const StateIntegrator::Frame* StateIntegrator::frameOf(const core::Map& map, uint64_t label) const {
  auto it = epochs_.find(map.id);
  if (it == epochs_.end()) return nullptr;
  auto f = it->second.find(label);
  return f == it->second.end() ? nullptr : &f->second;
}

uint64_t StateIntegrator::label(const core::Map& map) const {
  std::lock_guard lock(epochs_mutex_);
  auto it = epochs_.find(map.id);
  return it == epochs_.end() || it->second.empty() ? 0 : it->second.rbegin()->first;
}

bool StateIntegrator::stale(const core::Map& map, uint64_t label) const {
  std::lock_guard lock(epochs_mutex_);
  if (const Frame* f = frameOf(map, label)) return f->core_epoch != map.epoch;
  // Before any global map, every node holds the map in the frame it was made in (core epoch
  // 0 everywhere). Labels only grow: one below those kept is older than all of them (taking
  // it as current left bigloop's last keyframes without the last loop's correction, 48 mm
  // off); any other unknown label is ahead of this node (held back by the caller).
  if (label == 0) return map.epoch != 0;
  auto it = epochs_.find(map.id);
  return it != epochs_.end() && !it->second.empty() && label < it->second.begin()->first;
}

bool StateIntegrator::current(const core::Map& map, uint64_t label) const {
  std::lock_guard lock(epochs_mutex_);
  if (const Frame* f = frameOf(map, label)) return f->core_epoch == map.epoch;
  return label == 0 && map.epoch == 0;
}

StateIntegrator::Added StateIntegrator::addKeyframe(const KeyFrameMessage& m, uint64_t label) {
  Added out;
  auto map = mapFor(m.keyframe.map);
  // Posed in a map that has been merged into another here since: the sender had not applied
  // the merge yet. It goes into the merged map, carried from the keyframe it was posed from
  // as a stale one is (dropped, it lived on at TR alone: a CI run ended with TR one keyframe
  // ahead of LM and LC).
  std::shared_ptr<core::Map> posed_in;
  if (!map) {
    posed_in = slam_.findMap(m.keyframe.map);
    if (posed_in) map = slam_.findMap(posed_in->resolve()->id);
    if (!map || map->merged_into.load()) return out;
  }
  // Features and bag of words are computed before the lock.
  std::vector<std::shared_ptr<core::KeyFrame>> companions;
  for (const auto& c : m.companions) companions.push_back(makeKeyframe(c));
  auto kf = makeKeyframe(m.keyframe);
  std::vector<PointRecord> applied;  // as they went into the map, for S_full
  applied.reserve(m.points.size());
  {
    std::lock_guard lock(map->mutex);
    if (auto it = map->keyframes.find(kf->id); it != map->keyframes.end()) {
      out.map = map;
      out.keyframe = it->second;
      out.held = true;
      return out;
    }
    if (observer_.erasedKeyframe(kf->id)) {
      // Erased here before its message was taken: culled after a hand-over snapshot brought
      // it, or its erasure came first on the map topic. It stays erased (made again, it was
      // alive in this map only); routed marked bad, it is acknowledged, not mapped.
      kf->bad = true;
      out.map = map;
      out.keyframe = kf;
      return out;
    }
    if (m.keyframe.made_from != kNoId)
      if (auto it = map->keyframes.find(m.keyframe.made_from); it != map->keyframes.end())
        kf->made_from = it->second.get();
    // Whether it missed a correction is told by its label, not by the core's epoch counter it
    // was made with, which counts differently on each node; from here on the core's counter
    // tells whether it waits in this node's queue through one.
    kf->made_in_epoch = map->epoch;
    if (kf->made_from) kf->made_pose.scale = kf->made_from->scale();  // the record's is the label's frame
    // The made_from keyframe's scale() in the frame the label stood for; unknown for a merged
    // map's label this node never noted.
    std::optional<double> then;
    if (kf->made_from) {
      std::lock_guard epochs(epochs_mutex_);
      if (const Frame* f = frameOf(posed_in ? *posed_in : *map, label)) {
        auto s = f->scales.find(kf->made_from->id);
        then = s != f->scales.end() ? s->second : 1.0;
      } else if (!posed_in || label == 0) {
        then = 1.0;  // before the map's first correction
      }
    }
    if (posed_in && !then) {
      spdlog::warn("keyframe {} of node {}, posed in map {} before its merge, dropped: nothing here to carry it by", kf->id,
                   core::IdGenerator::node(kf->id), posed_in->id);
      return out;
    }
    if (posed_in || stale(*map, label)) {
      if (then) {
        const double change = kf->made_from->scale() / *then;
        kf->T_cw = kf->made_from->poseOf({kf->made_pose.T_c_k, *then});
        kf->made_pose = kf->made_from->relative(kf->T_cw);
        for (auto p : m.points)
          if (!map->points.count(p.id)) {
            // The same point seen from the keyframe, in the current frame and scale.
            p.position = kf->T_cw.inverse() * (change * (m.keyframe.T_cw * p.position));
            if (!applyPoint(*map, p)) continue;
            applied.push_back(p);
            ++stale_points_carried_;
          }
      }
      // else: nothing to carry it by; its new points wait for a fresh record, and the
      // keyframe's pose for the sender's next local map.
    } else {
      for (const auto& p : m.points)
        if (applyPoint(*map, p)) applied.push_back(p);
    }
    for (size_t i = 0; i < companions.size(); ++i) {
      auto& c = companions[i];
      if (map->keyframes.count(c->id)) continue;
      map->add(c);
      slam_.database().add(c.get(), map.get());
      relink(*map, *c, m.companions[i]);
      if (!map->origin) map->origin = c.get();
    }
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
  for (const auto& p : applied) observer_.record(p, map->id);
  for (const auto& c : m.companions) observer_.record(c);
  KeyFrameRecord placed = m.keyframe;
  placed.map = map->id;
  placed.T_cw = kf->T_cw;
  observer_.record(placed);
  out.map = map;
  out.keyframe = kf;
  return out;
}

std::vector<StateIntegrator::Added> StateIntegrator::addMissing(const std::vector<MapRecord>& batches) {
  std::vector<const KeyFrameRecord*> full;
  for (const auto& b : batches)
    for (const auto& k : b.keyframes)
      if (k.full) full.push_back(&k);
  std::sort(full.begin(), full.end(), [](auto* a, auto* b) { return a->id < b->id; });
  std::vector<Added> out;
  if (full.empty() || !slam_.findMap(batches.front().map)) return out;
  for (const KeyFrameRecord* k : full) {
    KeyFrameMessage m;
    m.keyframe = *k;
    if (auto added = addKeyframe(m, batches.front().epoch); added.keyframe && !added.held)
      out.push_back(std::move(added));
  }
  return out;
}

std::vector<PointRecord> StateIntegrator::carryNewPoints(const core::Map& map, const MapRecord& m) {
  // The points were triangulated in the frame the sender had (before it applied this node's
  // latest global map, or after it applied one still on its way here), like the window
  // keyframes' poses in the same record. Each is carried through a window keyframe held here:
  // the one that made it, else the first one.
  std::unordered_map<Id, const Eigen::Vector3d*> recorded;
  for (const auto& q : m.points) recorded.emplace(q.id, &q.position);
  struct Carry {
    Eigen::Isometry3d T_was, T_is;
    double scale = 1.0;
  };
  std::unordered_map<Id, Carry> carries;  // by keyframe
  const Carry* first = nullptr;
  for (const auto& k : m.keyframes) {
    auto it = map.keyframes.find(k.id);
    if (it == map.keyframes.end()) continue;
    const core::KeyFrame& here = *it->second;
    Carry c{k.T_cw, here.pose()};
    // The correction may have rescaled the map around the keyframe: how far the record's
    // points it sees are from it here, against in the record (as core::applyCorrection
    // measures a rigid correction's scale).
    std::vector<double> ratios;
    for (const auto& q : here.points) {
      if (!q || q->bad) continue;
      auto r = recorded.find(q->id);
      if (r == recorded.end()) continue;
      const double was = (c.T_was * *r->second).norm(), is = (c.T_is * q->position).norm();
      if (was > 1e-9 && is > 1e-9) ratios.push_back(is / was);
    }
    if (ratios.size() >= 8) {
      auto mid = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
      std::nth_element(ratios.begin(), mid, ratios.end());
      c.scale = *mid;
    }
    const Carry& stored = carries.emplace(k.id, c).first->second;
    if (!first) first = &stored;
  }
  std::vector<PointRecord> out;
  if (!first) return out;
  for (const auto& p : m.points) {
    if (map.points.count(p.id)) continue;
    auto by = carries.find(p.first_keyframe);
    const Carry& c = by != carries.end() ? by->second : *first;
    out.push_back(p);
    out.back().position = c.T_is.inverse() * (c.scale * (c.T_was * p.position));
  }
  stale_points_carried_ += out.size();
  return out;
}

void StateIntegrator::takeNewPoints(core::Map& map, const MapRecord& m) {
  // Points no keyframe here can carry come with the sender's next record in this frame.
  for (const auto& p : carryNewPoints(map, m))
    if (applyPoint(map, p)) observer_.record(p, m.map);
}

void StateIntegrator::takeStale(core::Map& map, const MapRecord& m) {
  takeNewPoints(map, m);
  applyErasures(map, m);
  // S_full loses what the map lost: an erasure in the map alone left S_full listing a keyframe
  // the map no longer had.
  for (Id id : m.erased_keyframes) observer_.eraseKeyframe(id);
  for (Id id : m.erased_points) observer_.erasePoint(id);
  for (const auto& [old, by] : m.replaced_points) observer_.erasePoint(old);
}

void StateIntegrator::applyLocal(const MapRecord& m) {
  auto map = slam_.findMap(m.map);
  if (!map || map->merged_into.load()) return;
  std::lock_guard lock(map->mutex);
  if (stale(*map, m.epoch)) {
    takeStale(*map, m);
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

void StateIntegrator::applyAhead(const MapRecord& m) {
  auto map = slam_.findMap(m.map);
  if (!map || map->merged_into.load()) return;
  std::lock_guard lock(map->mutex);
  if (current(*map, m.epoch)) return;  // its global map is in: it is applied as it is
  takeNewPoints(*map, m);
  // Links name points by id: they hold in any frame. Tracking finds points through the
  // keyframes that see them, so the new points are of use only linked.
  std::set<core::KeyFrame*, core::ById> relinked;
  for (const auto& k : m.keyframes)
    if (auto it = map->keyframes.find(k.id); it != map->keyframes.end() && relink(*map, *it->second, k))
      relinked.insert(it->second.get());
  for (core::KeyFrame* kf : relinked)
    if (!kf->bad) kf->updateConnections();
}

bool StateIntegrator::covers(const std::vector<MapRecord>& update, const std::vector<MapRecord>& snapshot) {
  std::vector<Id> ids;
  for (const auto& b : update)
    for (const auto& k : b.keyframes) ids.push_back(k.id);
  const std::unordered_set<Id> held(ids.begin(), ids.end());
  const auto newest = newestByNode(ids);
  for (const auto& b : snapshot)
    for (const auto& k : b.keyframes)
      if (olderThanSnapshot(k.id, newest) && !held.count(k.id)) return false;
  return true;
}

void StateIntegrator::adoptGlobal(const std::vector<MapRecord>& batches) {
  if (batches.empty()) return;
  {
    std::lock_guard lock(epochs_mutex_);
    epochs_.erase(batches.front().map);
  }
  applyGlobal(batches, true, true);
}

bool StateIntegrator::applyGlobal(const std::vector<MapRecord>& batches, bool authoritative, bool whole) {
  if (batches.empty()) return false;
  const uint64_t epoch = batches.front().epoch;
  // LC's relay, labelled with LC's latest published update, can still be older than LC's map:
  // a merge or loop correction is in the map from the moment it is made and gets its label a
  // moment later. Taken, it erased the merged map's keyframes (CI: 11.6% ATE).
  const auto left = [&](const core::Map& m) { return authoritative && !whole && stale(m, epoch); };
  if (auto m = slam_.findMap(batches.front().map)) {
    std::lock_guard lock(m->mutex);
    if (left(*m)) return false;
  }
  // Keyframes sent with their features (a snapshot for a node that joined) that this node
  // does not hold yet are made here; bags of words before the lock. Such a snapshot may bring
  // a map this node has never seen. Every node reading the map topic gets the newcomer's
  // snapshot, and holds nearly all of it: only the missing keyframes are made.
  std::vector<const KeyFrameRecord*> with_features;
  for (const auto& b : batches)
    for (const auto& k : b.keyframes)
      if (k.full) with_features.push_back(&k);
  // A map new here joins the atlas only once it is filled: a newcomer's keyframes wait for the
  // map to exist (DistributedNode::awaitMap), and one let in while the snapshot's bags of words
  // were computed became the empty map's origin and first keyframe.
  auto map = slam_.findMap(batches.front().map);
  const bool new_map = !map && !with_features.empty();
  if (new_map) map = receivedMap(batches.front().map);
  if (!map || map->merged_into.load()) return false;
  std::vector<std::pair<std::shared_ptr<core::KeyFrame>, const KeyFrameRecord*>> fresh;
  if (!with_features.empty()) {
    {
      std::lock_guard lock(map->mutex);
      std::erase_if(with_features, [&](const KeyFrameRecord* k) { return map->keyframes.count(k->id) > 0; });
    }
    for (const KeyFrameRecord* k : with_features) fresh.emplace_back(makeKeyframe(*k), k);
  }
  // Maps merged into this one move over first, as they are (the records below re-pose them).
  for (const auto& b : batches)
    for (Id merged : b.merged_maps) {
      auto other = slam_.findMap(merged);
      if (!other || other == map || other->merged_into.load()) continue;
      std::scoped_lock both(map->mutex, other->mutex);
      map->absorb(*other);
      slam_.database().moveMap(other.get(), map.get());
    }
  std::unique_lock lock(map->mutex);
  if (left(*map)) {
    // It left that frame since the check above: what is new is taken, as from a stale local
    // map, and the caller goes on as for an ignored update.
    for (const auto& b : batches) takeStale(*map, b);
    return false;
  }
  // S_full takes the update only now that the map does: recorded before the check above, an
  // update then ignored brought back into S_full keyframes this node had culled since (a stale
  // global map of LC's, at TR after a 30 s partition: TR's S_full listed two keyframes its map
  // no longer had).
  if (authoritative)
    for (const auto& b : batches) observer_.revive(b);
  for (const auto& b : batches) observer_.record(b);
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
  std::erase_if(fresh, [&](const auto& f) { return map->keyframes.count(f.first->id) > 0; });
  if (!fresh.empty()) spdlog::info("map {}: {} keyframes from a snapshot", map->id, fresh.size());
  for (const auto& [kf, r] : fresh) {
    kf->made_in_epoch = map->epoch;  // mapped already: no queue here to wait through a correction
    map->add(kf);
    slam_.database().add(kf.get(), map.get());
    if (!map->origin && kf->id == batches.front().origin) map->origin = kf.get();
  }
  for (const auto& [kf, r] : fresh)
    if (auto it = map->keyframes.find(r->made_from); r->made_from != kNoId && it != map->keyframes.end()) {
      kf->made_from = it->second.get();
      kf->made_pose.scale = kf->made_from->scale();
    }
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
    // except what it could not have known yet when it took the snapshot. One rule for the map
    // and for S_full. (The map once judged points by the snapshot's points alone, S_full by
    // both: a point both rules did not agree on stayed in the SLAM map only, and LC ended a
    // CI run with one point more than LM.)
    // - A keyframe was known to the sender if the snapshot holds a newer keyframe of its node:
    //   each node's keyframes reach the sender in order, one by one through its mapping queue.
    // - A point, if the snapshot holds a newer object of its node (points and keyframes share
    //   each node's id counter, and points come with or after the keyframe that made them).
    //   Keyframes judged that way too lost a new map's second keyframe: the snapshot held the
    //   first and the points it brought, numbered after the second.
    std::vector<Id> ids = kf_ids;
    ids.insert(ids.end(), point_ids.begin(), point_ids.end());
    const auto newest = newestByNode(ids), newest_keyframe = newestByNode(kf_ids);
    const auto keyframe_known = [&](Id id) { return olderThanSnapshot(id, newest_keyframe); };
    // - A point of a node that has left: all it ever sends is in (a mapping node that died
    //   left points at LC that TR, the gateway after it, never got: one more at LC).
    const auto point_known = [&](Id id) {
      return olderThanSnapshot(id, newest) || departed_(core::IdGenerator::node(id));
    };
    const std::unordered_set<Id> kfs(kf_ids.begin(), kf_ids.end()), pts(point_ids.begin(), point_ids.end());
    std::vector<core::KeyFrame*> gone_kfs;
    for (const auto& [id, k] : map->keyframes)
      if (!kfs.count(id) && keyframe_known(id) && k.get() != map->origin) gone_kfs.push_back(k.get());
    for (core::KeyFrame* k : gone_kfs) {
      map->erase(*k);
      slam_.database().erase(k);
    }
    std::vector<core::MapPoint*> gone_points;
    for (const auto& [id, p] : map->points)
      if (!pts.count(id) && point_known(id)) gone_points.push_back(p.get());
    for (core::MapPoint* p : gone_points) map->erase(*p);
    observer_.prune(batches.front(), kfs, pts, keyframe_known, point_known);
  }
  for (const auto& [id, k] : map->keyframes) k->updateConnections();
  noteEpoch(*map, epoch);
  lock.unlock();
  if (new_map) slam_.addMap(map);
  return true;
}

}  // namespace hiveslam::distribution
