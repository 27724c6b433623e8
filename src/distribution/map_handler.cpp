#include "distribution/map_handler.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "common/thread_name.hpp"
#include "distribution/packet.hpp"
#include "distribution/state_capture.hpp"

namespace hiveslam::distribution {

using communication::Topic;
using Clock = std::chrono::steady_clock;

namespace {

size_t linksHash(const KeyFrameRecord& r) {
  size_t h = std::hash<Id>()(r.parent);
  for (const auto& [i, p] : r.matches) h = h * 1000003u ^ (std::hash<Id>()(p) + i);
  for (Id l : r.loop_edges) h = h * 1000003u ^ std::hash<Id>()(l);
  return h;
}

// Appends what `into` lacks, in order (a replacement chain a->b, b->c must stay in order).
template <typename T>
void appendNew(const std::vector<T>& from, std::vector<T>& into) {
  std::set<T> have(into.begin(), into.end());
  for (const T& x : from)
    if (have.insert(x).second) into.push_back(x);
}

// Moves the map's journal of erasures into `m` (after what `m` carries already). An id that is
// alive again (erased, then brought back by an update from a node that had not heard of the
// erasure yet) is left out: the record's own points and keyframes say it exists, and a
// receiver applying both would drop it while the sender keeps it. The caller holds the map's
// mutex.
void takeJournal(core::Map& map, MapRecord& m) {
  appendNew(map.journal.erased_keyframes, m.erased_keyframes);
  appendNew(map.journal.erased_points, m.erased_points);
  appendNew(map.journal.replaced_points, m.replaced_points);
  map.journal = {};
  auto alivePoint = [&](core::Id id) {
    auto it = map.points.find(id);
    return it != map.points.end() && !it->second->bad;
  };
  auto aliveKeyframe = [&](core::Id id) {
    auto it = map.keyframes.find(id);
    return it != map.keyframes.end() && !it->second->bad;
  };
  std::erase_if(m.erased_points, alivePoint);
  std::erase_if(m.erased_keyframes, aliveKeyframe);
  std::erase_if(m.replaced_points, [&](const auto& r) { return alivePoint(r.first); });
}

}  // namespace

MapHandler::MapHandler(communication::Transport& transport, StateIntegrator& integrator, Observer& observer,
                       SentLedger& ledger, const DistributionSettings& settings, uint16_t node, Hooks hooks)
    : transport_(transport),
      integrator_(integrator),
      observer_(observer),
      ledger_(ledger),
      settings_(settings),
      node_(node),
      hooks_(std::move(hooks)) {
  thread_ = std::thread([this] {
    nameThisThread("map-handler");
    loop();
  });
}

MapHandler::~MapHandler() { finish(); }

void MapHandler::finish() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !thread_.joinable()) return;
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool MapHandler::idle() const {
  std::lock_guard lock(mutex_);
  if (busy_ || !inbox_.empty() || !globals_.empty()) return false;
  for (const auto& [id, o] : outgoing_)
    if (!o.dirty.empty() || !o.dirty_points.empty()) return false;
  return true;
}

void MapHandler::incoming(communication::Message&& m, Topic topic) {
  {
    std::lock_guard lock(mutex_);
    inbox_.push_back({std::move(m), topic, {}});
  }
  wake_.notify_all();
}

void MapHandler::afterIncoming(std::function<void()> f) {
  {
    std::lock_guard lock(mutex_);
    inbox_.push_back({{}, {}, std::move(f)});
  }
  wake_.notify_all();
}

void MapHandler::markDirty(const std::shared_ptr<core::Map>& map, const core::KeyFrame& kf, Topic topic, int window,
                           bool acknowledge) {
  // A keyframe culled meanwhile still goes into the dirty set when acknowledged (the batch
  // skips it, the acknowledgement goes out): its maker waits for the word.
  std::vector<core::Id> kfs{kf.id}, points;
  {
    std::lock_guard lock(map->mutex);
    if (kf.bad && !acknowledge) return;
    if (!kf.bad) {
      std::vector<const core::KeyFrame*> changed{&kf};
      for (const core::KeyFrame* n : kf.bestCovisible(static_cast<size_t>(window < 0 ? settings_.local_window : window))) {
        changed.push_back(n);
        kfs.push_back(n->id);
      }
      for (const core::KeyFrame* k : changed)
        for (const auto& p : k->points)
          if (p && !p->bad) points.push_back(p->id);
      // The other observers of kf's points go too, without their points: triangulation and
      // fusion gave them observations of kf's points, and a point's observers are read off the
      // keyframes' matches. Sent with kf alone, a point triangulated between kf and a neighbour
      // had one observer at TR until the neighbour's record came after local BA, so TR's
      // reference keyframes counted fewer well-observed points than the standalone system's
      // (offline sweep, in the turn: 283 against 362) and asked for fewer keyframes.
      std::set<core::Id> in(kfs.begin(), kfs.end());
      for (const auto& p : kf.points)
        if (p && !p->bad)
          for (const auto& [o, idx] : p->observations)
            if (!o->bad && in.insert(o->id).second) kfs.push_back(o->id);
    }
  }
  {
    std::lock_guard lock(mutex_);
    auto& o = outgoing_[map->id];
    o.map = map;
    o.topic = topic;
    o.dirty.insert(kfs.begin(), kfs.end());
    o.dirty_points.insert(points.begin(), points.end());
    if (acknowledge) o.mapped.insert(kf.id);
    o.batch = 0;
  }
  wake_.notify_all();
}

void MapHandler::sendGlobal(const std::shared_ptr<core::Map>& map, uint64_t epoch, Topic topic,
                            std::vector<core::Id> merged_maps, bool full, Newcomer newcomer) {
  {
    std::lock_guard lock(mutex_);
    // A newer global update of the map replaces one still waiting to go out; one already
    // going out is finished first (see loop()). What a replaced one would have announced (the
    // maps it merged, the map's erasures) goes with the newer one: a receiver that never hears
    // of a merge keeps the merged map apart, one that never hears of an erasure keeps the point.
    GlobalJob g;
    g.map = map;
    g.epoch = epoch;
    g.topic = topic;
    g.merged = std::move(merged_maps);
    g.full = full;
    g.reader_deadline = Clock::now() + std::chrono::milliseconds(settings_.handover_wait_ms);
    g.newcomer = std::move(newcomer);
    for (auto it = globals_.begin(); it != globals_.end();)
      if (it->map == map && it->topic == topic && it->batches.empty()) {  // not begun
        carryOver(*it, g);
        it = globals_.erase(it);
      } else {
        ++it;
      }
    globals_.push_back(std::move(g));
  }
  wake_.notify_all();
}

void MapHandler::loop() {
  Clock::time_point next_local = Clock::now(), next_global = Clock::now();
  std::unique_lock lock(mutex_);
  while (true) {
    busy_ = false;
    const auto now = Clock::now();
    const bool local_pending =
        std::any_of(outgoing_.begin(), outgoing_.end(), [](const auto& o) { return !o.second.dirty.empty() || !o.second.dirty_points.empty(); });
    if (!inbox_.empty()) {
      Inbound in = std::move(inbox_.front());
      inbox_.pop_front();
      busy_ = true;
      lock.unlock();
      if (in.after)
        in.after();
      else
        handleIncoming(in.message, in.topic);
      lock.lock();
      continue;
    }
    if (!globals_.empty() && now >= next_global) {
      GlobalJob g = std::move(globals_.front());
      globals_.pop_front();
      busy_ = true;
      lock.unlock();
      const auto reads = [&](Topic t) { return transport_.peerReads(t, g.newcomer.node); };
      const auto ready = [&] {
        return std::all_of(g.newcomer.reads.begin(), g.newcomer.reads.end(), reads) &&
               (!hooks_.settled || hooks_.settled());
      };
      if (g.newcomer.node && g.batches.empty() && now < g.reader_deadline && !ready()) {
        lock.lock();
        globals_.push_front(std::move(g));
        next_global = Clock::now() + std::chrono::milliseconds(10);
        continue;
      }
      try {
        if (g.batches.empty()) {
          captureGlobal(g);
          if (g.newcomer.node)
            spdlog::info("node {}: map {} goes to node {} ({} batches)", node_, g.map->id, g.newcomer.node, g.batches.size());
        }
        if (g.next < g.batches.size()) {
          MapRecord& b = g.batches[g.next++];
          trimForSending(b, g.topic, g.full);
          observer_.record(b);
          transport_.publish(g.topic, pack(b, node_, 0, b.map, b.epoch));
          if (g.next == g.batches.size()) ++global_sent_;
        }
      } catch (const std::exception& e) {
        spdlog::error("map handler: {}", e.what());
        g.next = g.batches.size();
      }
      lock.lock();
      // Unfinished: it goes back to the front, ahead of any newer update of the map that came
      // meanwhile. A receiver drops an update it did not get whole, so one cut short for a newer
      // one is lost work, and where updates come faster than a whole map takes to send (global
      // BAs back to back on a large map: 14 batches 100 ms apart, a global BA every 1.2 s) none
      // ever arrived: 12 in a row at the end of a 3-node bigloop run.
      const int gap = g.topic == Topic::LcMap ? settings_.lc_global_batch_gap_ms : settings_.global_batch_gap_ms;
      if (g.next < g.batches.size()) globals_.push_front(std::move(g));
      next_global = Clock::now() + std::chrono::milliseconds(gap);
      continue;
    }
    // An acknowledgement does not wait for the gap (DistributionSettings::local_batch_gap_ms).
    const auto acknowledging = std::find_if(outgoing_.begin(), outgoing_.end(), [](const auto& o) {
      return std::any_of(o.second.mapped.begin(), o.second.mapped.end(), [&](core::Id id) { return o.second.dirty.count(id) > 0; });
    });
    if (local_pending && (now >= next_local || acknowledging != outgoing_.end())) {
      auto it = acknowledging != outgoing_.end()
                    ? acknowledging
                    : std::find_if(outgoing_.begin(), outgoing_.end(), [](const auto& o) { return !o.second.dirty.empty() || !o.second.dirty_points.empty(); });
      Outgoing& o = it->second;
      busy_ = true;
      // The batch's keyframes and points leave the dirty sets under the lock; capture is outside.
      Outgoing batch;
      batch.map = o.map;
      batch.topic = o.topic;
      const int n = std::min(settings_.local_first_batch * (o.batch + 1), settings_.local_max_batch);
      // The acknowledged keyframes first, so that this batch carries the acknowledgements.
      for (core::Id id : o.mapped)
        if (o.dirty.erase(id)) batch.dirty.insert(id);
      while (!o.dirty.empty() && static_cast<int>(batch.dirty.size()) < n) {
        batch.dirty.insert(*o.dirty.begin());
        o.dirty.erase(o.dirty.begin());
      }
      for (core::Id id : batch.dirty)
        if (o.mapped.erase(id)) batch.mapped.insert(id);
      const bool last = o.dirty.empty();
      ++o.batch;
      // Points go with the first batch whose keyframes see them; the rest with the last batch.
      batch.dirty_points = o.dirty_points;  // filtered during capture
      lock.unlock();
      try {
        sendLocalBatch(batch);
      } catch (const std::exception& e) {
        spdlog::error("map handler: {}", e.what());
      }
      lock.lock();
      // batch.dirty_points now holds what was not sent.
      auto& live = outgoing_[batch.map->id];
      if (last) {
        live.dirty_points.clear();
      } else {
        for (auto p = live.dirty_points.begin(); p != live.dirty_points.end();)
          p = batch.dirty_points.count(*p) ? std::next(p) : live.dirty_points.erase(p);
      }
      next_local = Clock::now() + std::chrono::milliseconds(settings_.local_batch_gap_ms);
      continue;
    }
    if (stopping_ && inbox_.empty() && globals_.empty() && !local_pending) break;
    if (local_pending || !globals_.empty())
      wake_.wait_until(lock, std::min(local_pending ? next_local : Clock::time_point::max(),
                                      globals_.empty() ? Clock::time_point::max() : next_global));
    else
      wake_.wait(lock);
  }
}

KeyFrameRecord MapHandler::updateRecord(const core::KeyFrame& kf, core::Id map, Topic topic) {
  KeyFrameRecord r = captureKeyframe(kf, map, false);
  const size_t h = linksHash(r);
  auto& sent = links_sent_[static_cast<size_t>(topic)];
  auto it = sent.find(kf.id);
  if (it != sent.end() && it->second == h) {
    r.links = false;
    r.matches.clear();
    r.loop_edges.clear();
  } else {
    sent[kf.id] = h;
  }
  return r;
}

void MapHandler::sendLocalBatch(Outgoing& o) {
  core::Map& map = *o.map;
  MapRecord m;
  m.kind = MapRecord::Kind::Local;
  m.map = map.id;
  {
    std::lock_guard lock(map.mutex);
    m.epoch = integrator_.label(map);
    if (map.merged_into.load()) {
      o.dirty_points.clear();
      return;
    }
    m.origin = map.origin ? map.origin->id : kNoId;
    m.mapped.assign(o.mapped.begin(), o.mapped.end());
    std::set<core::Id> unsent = o.dirty_points;
    for (core::Id id : o.dirty) {
      auto it = map.keyframes.find(id);
      if (it == map.keyframes.end() || it->second->bad) continue;
      const core::KeyFrame& kf = *it->second;
      m.keyframes.push_back(updateRecord(kf, map.id, o.topic));
      for (const auto& p : kf.points)
        if (p && !p->bad && unsent.erase(p->id)) m.points.push_back(capturePoint(*p, true));
    }
    o.dirty_points = std::move(unsent);
    takeJournal(map, m);
  }
  if (m.keyframes.empty() && m.points.empty() && m.erased_keyframes.empty() && m.erased_points.empty() &&
      m.replaced_points.empty() && m.mapped.empty())
    return;
  trimForSending(m, o.topic, false);
  observer_.record(m);
  transport_.publish(o.topic, pack(m, node_, 0, m.map, m.epoch));
  ++local_sent_;
}

void MapHandler::trimForSending(MapRecord& m, Topic topic, bool full) {
  std::vector<PointRecord> kept;
  kept.reserve(m.points.size());
  const AppearanceTolerance tolerance{settings_.point_normal_deg, settings_.point_range_ratio,
                                      settings_.point_descriptor_bits};
  for (auto& p : m.points) {
    const bool due = ledger_.needsFull(topic, p, tolerance);
    const bool moved = ledger_.moved(topic, p.id, p.position, settings_.min_point_move);
    if (!due && !full) {
      // A position update only when it moved: local BA leaves most of a window's points where
      // they were to well under a tenth of a millimetre.
      if (!moved && m.kind == MapRecord::Kind::Local) continue;
      p.full = false;
    }
    kept.push_back(std::move(p));
  }
  std::sort(kept.begin(), kept.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  m.points = std::move(kept);
  auto& sent = links_sent_[static_cast<size_t>(topic)];
  for (const auto& k : m.keyframes)
    if (k.links) sent[k.id] = linksHash(k);
}

void MapHandler::carryOver(GlobalJob& from, GlobalJob& into) {
  appendNew(from.merged, into.merged);
  into.full = into.full || from.full;  // a snapshot for a newcomer stays one
  if (!into.newcomer.node) {
    into.newcomer = from.newcomer;
    into.reader_deadline = from.reader_deadline;
  }
  // Erasures ride with the first batch; a job replaced after its capture took them from the
  // map's journal already.
  const MapRecord& once = from.batches.empty() ? from.carried : from.batches.front();
  appendNew(once.erased_keyframes, into.carried.erased_keyframes);
  appendNew(once.erased_points, into.carried.erased_points);
  appendNew(once.replaced_points, into.carried.replaced_points);
}

void MapHandler::captureGlobal(GlobalJob& g) {
  core::Map& map = *g.map;
  std::vector<KeyFrameRecord> kfs;
  std::vector<PointRecord> points;
  MapRecord base;
  base.kind = MapRecord::Kind::Global;
  base.map = map.id;
  base.epoch = g.epoch;
  base.merged_maps = g.merged;
  base.update = ++updates_captured_;
  {
    std::lock_guard lock(map.mutex);
    base.origin = map.origin ? map.origin->id : kNoId;
    std::vector<const core::KeyFrame*> sorted;
    for (const auto& [id, k] : map.keyframes) sorted.push_back(k.get());
    std::sort(sorted.begin(), sorted.end(), [](auto* a, auto* b) { return a->id < b->id; });
    // Links always go with a global map: a receiver may have skipped local maps meanwhile. A
    // snapshot for a newcomer also carries every keyframe's features: it has none of them.
    for (const core::KeyFrame* k : sorted) kfs.push_back(captureKeyframe(*k, map.id, g.newcomer.node != 0));
    for (const auto& [id, p] : map.points)
      if (!p->bad) points.push_back(capturePoint(*p, true));
    base.erased_keyframes = std::move(g.carried.erased_keyframes);
    base.erased_points = std::move(g.carried.erased_points);
    base.replaced_points = std::move(g.carried.replaced_points);
    takeJournal(map, base);
  }
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  const size_t per = static_cast<size_t>(std::max(settings_.global_batch, 1));
  const size_t n = std::max<size_t>(1, (kfs.size() + per - 1) / per);
  const size_t points_per = (points.size() + n - 1) / n;
  for (size_t b = 0; b < n; ++b) {
    MapRecord m;
    m.kind = base.kind;
    m.map = base.map;
    m.epoch = base.epoch;
    m.update = base.update;
    m.origin = base.origin;
    m.merged_maps = base.merged_maps;
    if (b == 0) {  // erasures once
      m.erased_keyframes = std::move(base.erased_keyframes);
      m.erased_points = std::move(base.erased_points);
      m.replaced_points = std::move(base.replaced_points);
    }
    m.batch = static_cast<uint32_t>(b);
    m.batches = static_cast<uint32_t>(n);
    for (size_t i = b * per; i < std::min(kfs.size(), (b + 1) * per); ++i) m.keyframes.push_back(std::move(kfs[i]));
    for (size_t i = b * points_per; i < std::min(points.size(), (b + 1) * points_per); ++i)
      m.points.push_back(std::move(points[i]));
    g.batches.push_back(std::move(m));
  }
}

void MapHandler::handleIncoming(communication::Message& msg, Topic topic) {
  if (msg.kind == static_cast<uint8_t>(PacketKind::Control)) {
    if (hooks_.control) hooks_.control(msg, topic);
    return;
  }
  try {
    MapRecord m = decodeMap(unpack(msg, PacketKind::Map));
    ++received_;
    if (m.kind == MapRecord::Kind::Local) {
      if (hooks_.hold && hooks_.hold(m)) {
        if (hooks_.local_applied) hooks_.local_applied(m);
        return;
      }
      integrator_.applyLocal(m);
      if (hooks_.local_applied) hooks_.local_applied(m);
    } else if (auto all = observer_.collectGlobal(std::move(m), msg.source)) {
      if (hooks_.global) hooks_.global(std::move(*all), topic, msg.source);
    }
  } catch (const std::exception& e) {
    ++dropped_;
    spdlog::warn("dropped a map message from node {}: {}", msg.source, e.what());
  }
}

}  // namespace hiveslam::distribution
