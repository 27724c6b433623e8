#include "distribution/distributed_node.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <unordered_set>

#include "core/mapping/keyframe_insertion.hpp"
#include "distribution/packet.hpp"

namespace hiveslam::distribution {

using communication::Message;
using communication::PeerInfo;
using communication::Task;
using communication::Topic;
using communication::taskBit;

namespace {

constexpr uint8_t kTargetLm = 1, kTargetLc = 2;

bool isKeyframeTopic(Topic t) { return t == Topic::TrKeyframes || t == Topic::LmKeyframes; }

// Where this incarnation's id counter starts (core/map/ids.hpp): its start time in 10 us ticks
// since 2024-01-01 UTC.
uint64_t firstIdCounter(std::chrono::system_clock::time_point start) {
  using namespace std::chrono;
  constexpr auto k2024 = sys_days{year{2024} / January / 1};
  const auto ticks = duration_cast<microseconds>(start - k2024).count() / 10;
  return ticks > 0 ? static_cast<uint64_t>(ticks) : 0;
}

}  // namespace

DistributedNode::DistributedNode(core::SlamSystem& slam, communication::Transport& transport, NodeOptions options)
    : slam_(slam), transport_(transport), options_(std::move(options)), integrator_(slam, observer_),
      gate_(transport, std::chrono::milliseconds(options_.settings.handover_wait_ms)),
      watch_(std::chrono::milliseconds(options_.settings.release_slow_gateway_ms), options_.settings.release_slow_acks,
             std::chrono::milliseconds(options_.settings.dead_peer_ms)) {
  publisher_ = std::make_unique<KeyframePublisher>(
      transport_, observer_, ledger_, options_.id, [this](Topic topic, core::Id point) {
        // TR's receiver (LM) has every point TR received from it; LM's (LC) those sent to it.
        if (topic == Topic::TrKeyframes) return observer_.hasPoint(point);
        return ledger_.sent(Topic::LmKeyframes, point) || ledger_.sent(Topic::LmMap, point);
      },
      [this](const core::Map& map) { return integrator_.label(map); }, [this](Topic t) { gate_.await(t); });
  subscriber_ = std::make_unique<KeyframeSubscriber>(
      integrator_,
      [this](const StateIntegrator::Added& a, uint8_t target) {
        if (target == kTargetLc) {
          {
            std::lock_guard lock(a.map->mutex);
            core::insertKeyframe(*a.map, *a.keyframe, slam_.scales(), &slam_.database());
          }
          slam_.submit(a.map, a.keyframe, core::SlamSystem::Module::LoopClosing);
        } else {
          slam_.submit(a.map, a.keyframe, core::SlamSystem::Module::Mapping);
        }
      },
      [this](const Message& m) { onControl(m, Topic::TrKeyframes); }, [this](core::Id id, uint8_t target) { awaitMap(id, target); });
  MapHandler::Hooks hooks;
  hooks.hold = [this](const MapRecord& m) {
    {
      std::lock_guard lock(mutex_);
      if (m.epoch <= knownEpoch(m.map)) return false;
      // Bounded: a global update that never comes (its sender died) costs old poses, not memory.
      constexpr size_t kMaxHeld = 256;
      if (held_.size() >= kMaxHeld) held_.erase(held_.begin());
      held_.push_back(m);
      ++local_maps_held_;
    }
    integrator_.applyAhead(m);  // its new points, until the whole record can go in
    return true;
  };
  hooks.global = [this](std::vector<MapRecord>&& b, Topic t) { onGlobal(std::move(b), t); };
  hooks.local_applied = [this](const MapRecord& m) {
    {
      std::lock_guard lock(mutex_);
      const auto now = std::chrono::steady_clock::now();
      for (core::Id k : m.mapped) {
        // Local maps list their mapped keyframes again; only a first acknowledgement counts.
        // Those no longer waited for (unanswered_) count too: on a slow link they are most.
        auto it = outstanding_.find(k);
        auto late = unanswered_.find(k);
        if (it == outstanding_.end() && late == unanswered_.end()) continue;
        const auto sent = it != outstanding_.end() ? it->second : late->second;
        ack_ms_.push_back(std::chrono::duration<double, std::milli>(now - sent).count());
        // Keyframes sent before a new gateway's first answer waited on its hand-over: their
        // answers prove it alive, their round trips say nothing of the link.
        if (handover_pending_) {
          handover_pending_ = false;
          judge_from_ = now;
        }
        watch_.answered(sent >= judge_from_ ? now - sent : GatewayWatch::Clock::duration::zero());
        lost_waiting_ = false;
        if (it != outstanding_.end()) outstanding_.erase(it);
        if (late != unanswered_.end()) unanswered_.erase(late);
      }
    }
    changed_.notify_all();
  };
  hooks.control = [this](const Message& m, Topic t) { onControl(m, t); };
  // A node that gave mapping up still maps the keyframes it had taken: a newcomer's snapshot
  // waits for them. Taken before, the culling and the points that came after it reached no
  // one, and this node ended the run a keyframe short of the others.
  hooks.settled = [this] { return plan().mapping || slam_.mappingIdle(); };
  handler_ = std::make_unique<MapHandler>(transport_, integrator_, observer_, ledger_, options_.settings, options_.id,
                                          std::move(hooks));
  integrator_.setDeparted([this](uint16_t node) {
    std::lock_guard lock(departed_mutex_);
    return departed_.count(node) > 0;
  });
  slam_.setEvents(this);
  slam_.setRemoteMapping([this] { return remoteIdle(); }, [this] { remoteWait(); });
}

DistributedNode::~DistributedNode() {
  stop();
  slam_.setEvents(nullptr);
}

PeerInfo DistributedNode::self() const {
  std::lock_guard lock(mutex_);
  PeerInfo p;
  for (const auto& [id, peer] : peers_) p.seen.push_back(id);
  p.node = options_.id;
  p.name = options_.name;
  p.task = options_.task;
  p.hosted = plan_.hosted;
  p.incarnation = incarnation_;
  p.cores = static_cast<uint16_t>(std::max(1u, std::thread::hardware_concurrency()));
  return p;
}

void DistributedNode::start() {
  const auto now = std::chrono::system_clock::now();
  incarnation_ = static_cast<uint64_t>(now.time_since_epoch().count());
  slam_.startIdsAt(firstIdCounter(now));
  {
    std::lock_guard lock(mutex_);
    plan_ = decide(options_.task, 0);
  }
  slam_.setHosting({plan_.mapping, plan_.loop_closing});
  transport_.start(self(), [this](const PeerInfo& p, bool present) { onPeer(p, present); });
  applyPlan();
}

uint8_t DistributedNode::presentTasks() const {
  std::lock_guard lock(mutex_);
  uint8_t present = 0;
  for (const auto& [id, peer] : peers_) present |= taskBit(peer.task);
  return present;
}

uint8_t DistributedNode::mutualTasks() const {
  std::vector<PeerInfo> mutual;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [id, peer] : peers_)
      if (std::find(peer.seen.begin(), peer.seen.end(), options_.id) != peer.seen.end()) mutual.push_back(peer);
  }
  uint8_t tasks = 0;
  for (const auto& peer : mutual) {
    // A mapping node must read tracking's keyframes from the first: the first map goes out once.
    if (options_.task == Task::Tracking && peer.task == Task::Mapping &&
        !transport_.peerReads(Topic::TrKeyframes, peer.node))
      continue;
    tasks |= taskBit(peer.task);
  }
  return tasks;
}

Plan DistributedNode::plan() const {
  std::lock_guard lock(mutex_);
  return plan_;
}

void DistributedNode::onPeer(const PeerInfo& peer, bool present) {
  if (!present) {
    onLeaving(peer);
    return;
  }
  bool newcomer = false, restarted = false, leaving = false;
  const Plan before = plan();
  {
    std::lock_guard lock(mutex_);
    // A node released here is gone for this node already: its announcements until the Release
    // reaches it change nothing. Restarted (a new incarnation), it is a newcomer like any other.
    if (released_.count({peer.node, peer.incarnation})) return;
    leaving = stopping_;
    auto it = peers_.find(peer.node);
    newcomer = it == peers_.end() || it->second.incarnation != peer.incarnation;
    restarted = it != peers_.end() && newcomer;
    peers_[peer.node] = peer;
    had_mapping_peer_ = had_mapping_peer_ || peer.task == Task::Mapping;
  }
  {
    std::lock_guard lock(departed_mutex_);
    departed_.erase(peer.node);
  }
  if (newcomer) gate_.joined(peer.node, peer.task);
  spdlog::info("node {}: peer {} ({}) {}", options_.id, peer.name, communication::taskName(peer.task),
               newcomer ? "joined" : "changed");
  // A restarted node's old packets are all in; its new ones must not be dropped.
  if (restarted) dropPendingGlobals(peer);
  if (leaving) return;  // no task is taken over or handed on while the transport goes down
  applyPlan();
  // The peers it sees changed: they learn it from the next announcement (see mutualTasks()).
  if (newcomer) transport_.announce(self());
  // A node that joins late gets the maps so far from the gateway; a mapping node that joins
  // (or returns) gets them from the node that mapped until now, which gives mapping up to it.
  const Plan after = plan();
  if (newcomer && before.mapping && !after.mapping) {
    // A gateway taking the map over answers nothing until it holds it (handover_wait_ms at
    // most): it is not judged slow before its first answer (a restarted LM was released).
    std::lock_guard lock(mutex_);
    handover_pending_ = true;
  }
  if (newcomer && (after.local_maps || (before.mapping && !after.mapping))) sendMapsTo(peer);
}

void DistributedNode::dropPendingGlobals(const PeerInfo& peer) {
  // A global map it was sending when it died would otherwise wait here, half collected, until
  // its next batch: it is never completed.
  if (const size_t dropped = observer_.dropPendingGlobals(peer.node))
    spdlog::info("node {}: {} batches of an unfinished global map from {} dropped", options_.id, dropped, peer.name);
}

void DistributedNode::onLeaving(const PeerInfo& peer) {
  {
    std::lock_guard lock(mutex_);
    // Its leaving was counted at the release.
    if (std::erase_if(released_, [&](const auto& r) { return r.first == peer.node; }) > 0 && !peers_.count(peer.node))
      return;
    ++departures_;
  }
  {
    std::lock_guard lock(departed_mutex_);
    departed_.insert(peer.node);
  }
  gate_.left(peer.node);  // keyframes no longer wait for its readers
  spdlog::info("node {}: peer {} ({}) left", options_.id, peer.name, communication::taskName(peer.task));
  // The rest waits until the packets it sent before leaving are handled. Dropped at the
  // notice, the batches still queued here of its last snapshot started a collection never
  // completed (LC ended 71 points short, session 39). And a gateway that leaves at the end of
  // a run has sent its Done before its leaving notice, which can overtake it (the notice comes
  // on its own topic and is handled at once): taken as a death, TR took mapping back and LC
  // and TR sent each other their whole maps, the newcomer's reader wait holding TR 10 s past
  // the end (2 of 5 bench runs). The peer stays a peer until then: any re-plan meanwhile (a
  // peer's changed announcement) keeps the plan it had.
  handler_->afterIncoming([this, peer] {
    dropPendingGlobals(peer);
    departed(peer);
    {
      std::lock_guard lock(mutex_);
      ++departures_handled_;
    }
    changed_.notify_all();
  });
}

void DistributedNode::departed(const PeerInfo& peer) {
  const Plan before = plan();
  {
    std::lock_guard lock(mutex_);
    auto it = peers_.find(peer.node);
    // Back meanwhile as a new incarnation: that one is a peer.
    if (it == peers_.end() || it->second.incarnation != peer.incarnation) return;
    peers_.erase(it);
    // Stopping, or the run is over here (the gateway's Done is in): nothing is taken over.
    if (stopping_ || done_) return;
  }
  applyPlan();
  transport_.announce(self());
  // LC whose mapping node left: TR maps again, and is its gateway now.
  if (options_.task == Task::LoopClosing && peer.task == Task::Mapping) resendGlobalsToTracking();
  // TR, the gateway now that its LM left, and an LC: the keyframes LM had mapped but not yet
  // sent on to LC never reach it (LC's S_full got their records from TR's last snapshot, its
  // SLAM map never their features: a keyframe short of TR, session 40). The newcomer's snapshot
  // brings the features of those it lacks.
  const Plan after = plan();
  if (before.keyframes_to_lm && after.keyframes_to_lc)
    for (const auto& lc : peersWith(Task::LoopClosing)) sendMapsTo(lc);
}

std::vector<PeerInfo> DistributedNode::peersWith(Task task) const {
  std::lock_guard lock(mutex_);
  std::vector<PeerInfo> out;
  for (const auto& [id, p] : peers_)
    if (p.task == task) out.push_back(p);
  return out;
}

bool DistributedNode::trackingTookOver(uint16_t asker) const {
  std::lock_guard lock(mutex_);
  auto it = peers_.find(asker);
  return had_mapping_peer_ && it != peers_.end() && it->second.task == Task::Tracking;
}

void DistributedNode::resendGlobalsToTracking() {
  const auto maps = slam_.liveMaps();
  std::lock_guard lock(mutex_);
  if (stopping_) return;
  auto tr = std::find_if(peers_.begin(), peers_.end(), [](const auto& p) { return p.second.task == Task::Tracking; });
  if (tr == peers_.end()) return;
  for (const auto& map : maps) {
    auto it = published_.find(map->id);
    if (it == published_.end()) continue;
    spdlog::info("node {}: map {} of epoch {} sent again, to node {}, the new gateway", options_.id, map->id, it->second,
                 tr->first);
    // A snapshot in full, once TR reads this topic (it began to when LM left).
    handler_->sendGlobal(map, it->second, Topic::LcMap, {}, true, {tr->first, {Topic::LcMap}});
  }
}

void DistributedNode::sendMapsTo(const PeerInfo& peer) {
  // Every task reads the map topic; keyframes go from here to an LM or an LC only.
  Newcomer newcomer{peer.node, {Topic::LmMap}};
  const Plan p = plan();
  if (p.keyframes_to_lm && peer.task == Task::Mapping) newcomer.reads.push_back(Topic::TrKeyframes);
  if (p.keyframes_to_lc && peer.task == Task::LoopClosing) newcomer.reads.push_back(Topic::LmKeyframes);
  for (const auto& map : slam_.liveMaps()) {
    publisher_->push({map, nullptr, Topic::TrKeyframes, 0, true});
    sendSnapshot(map, newcomer);
  }
}

void DistributedNode::sendSnapshot(const std::shared_ptr<core::Map>& map, Newcomer newcomer) {
  std::lock_guard lock(mutex_);
  handler_->sendGlobal(map, synced_[map->id], Topic::LmMap, {}, true, std::move(newcomer));
}

void DistributedNode::awaitMap(core::Id id, uint8_t target) {
  if (slam_.findMap(id)) return;
  const auto start = std::chrono::steady_clock::now();
  const auto wait = std::chrono::milliseconds(options_.settings.handover_wait_ms);
  // A hand-over snapshot comes within a second or so. Later than that, nobody is sending one:
  // the packet that started the map never arrived, and the sender is asked for the map.
  const auto ask_at = start + wait / 5;
  bool asked = false;
  {
    std::lock_guard lock(mutex_);
    ++maps_awaited_;
  }
  spdlog::info("node {}: keyframes of map {} wait for its snapshot", options_.id, id);
  while (!slam_.findMap(id)) {
    const auto now = std::chrono::steady_clock::now();
    const bool ask = !asked && now >= ask_at;
    if (ask) {
      asked = true;
      // Keyframes for loop closing come from the gateway, which reads LC's map topic; those for
      // mapping come from TR, which reads the mapping node's.
      const Topic ask_on = target == kTargetLc ? Topic::LcMap : Topic::LmMap;
      spdlog::info("node {}: asks for map {} (the packet that started it never came)", options_.id, id);
      transport_.publish(ask_on, controlPacket(options_.id, Control::SendMap, id));
    }
    std::unique_lock lock(mutex_);
    maps_asked_for_ += ask;
    if (stopping_ || now >= start + wait) {
      spdlog::warn("node {}: no snapshot of map {} came; its keyframes are mapped without it", options_.id, id);
      return;
    }
    changed_.wait_for(lock, std::chrono::milliseconds(20));
  }
}

void DistributedNode::applyPlan() {
  // Called from the transport's peer thread, the map handler's (a departure) and the releaser:
  // one at a time, or two could change the hosting and the subscriptions in opposite orders.
  // Not held while announcing: the in-process transport calls the peers' handlers from there,
  // and theirs may come back here.
  std::unique_lock apply(apply_mutex_);
  std::vector<Topic> add, remove;
  Plan p;
  std::map<core::Id, std::chrono::steady_clock::time_point> orphans;  // by id: mapped in order
  {
    std::lock_guard lock(mutex_);
    const Plan before = plan_;
    uint8_t present = 0;
    for (const auto& [id, peer] : peers_) present |= taskBit(peer.task);
    p = decide(options_.task, present);
    const bool changed = p.hosted != plan_.hosted || p.subscriptions != plan_.subscriptions;
    plan_ = p;
    for (Topic t : p.subscriptions)
      if (std::find(subscribed_.begin(), subscribed_.end(), t) == subscribed_.end()) add.push_back(t);
    for (Topic t : subscribed_)
      if (std::find(p.subscriptions.begin(), p.subscriptions.end(), t) == p.subscriptions.end()) remove.push_back(t);
    subscribed_ = p.subscriptions;
    if (!changed && add.empty() && remove.empty()) return;
    lost_waiting_ = false;  // a loss under the old plan says nothing of a new gateway
    if (p.mapping && !before.mapping) {
      orphans.swap(outstanding_);
      orphans.insert(unanswered_.begin(), unanswered_.end());
      unanswered_.clear();
      // Sent in the LM's last seconds (its lease, then the wait): older ones went unanswered
      // for another reason (dropped at the gateway, their map merged meanwhile).
      const auto recent = std::chrono::steady_clock::now() - 5 * std::chrono::milliseconds(options_.settings.remote_mapping_wait_ms);
      std::erase_if(orphans, [&](const auto& o) { return o.second < recent; });
    }
  }
  slam_.setHosting({p.mapping, p.loop_closing});
  // Mapping taken back from a node that left: the keyframes it was sent and never acknowledged
  // are mapped here (tracked against, never triangulated, they left TR short of new points
  // just where it tracks now).
  if (!orphans.empty())
    for (const auto& map : slam_.liveMaps()) {
      std::vector<std::shared_ptr<core::KeyFrame>> lost;
      {
        std::lock_guard lock(map->mutex);
        for (const auto& [id, when] : orphans)
          if (auto it = map->keyframes.find(id); it != map->keyframes.end()) lost.push_back(it->second);
      }
      for (const auto& kf : lost) slam_.submit(map, kf, core::SlamSystem::Module::Mapping);
      std::lock_guard lock(mutex_);
      keyframes_taken_back_ += static_cast<int>(lost.size());
    }
  for (Topic t : remove) transport_.unsubscribe(t);
  for (Topic t : add) {
    if (isKeyframeTopic(t))
      transport_.subscribe(t, [this](Message&& m) { subscriber_->push(std::move(m)); });
    else
      transport_.subscribe(t, [this, t](Message&& m) { handler_->incoming(std::move(m), t); });
  }
  apply.unlock();
  transport_.announce(self());
  changed_.notify_all();
}

void DistributedNode::mapCreated(const std::shared_ptr<core::Map>& map) {
  std::lock_guard lock(map->mutex);
  map->journal_on = true;
}

void DistributedNode::trackingLost() {
  // Lost with keyframes waiting for their points: the round trip may have starved tracking.
  std::lock_guard lock(mutex_);
  if (plan_.keyframes_to_lm) lost_waiting_ = true;
}

void DistributedNode::keyframeCreated(const std::shared_ptr<core::Map>& map, const std::shared_ptr<core::KeyFrame>& kf) {
  if (!plan().keyframes_to_lm) return;
  {
    std::lock_guard lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    outstanding_.emplace(kf->id, now);
    watch_.sent(now);
  }
  publisher_->push({map, kf, Topic::TrKeyframes, kTargetLm});
}

void DistributedNode::keyframeTriangulated(const std::shared_ptr<core::Map>& map,
                                           const std::shared_ptr<core::KeyFrame>& kf) {
  // The keyframe and its new points go out before local BA (one small message): TR tracked
  // 10% fewer points than the standalone system, which sees new points the moment they are
  // made, while these waited for the BA and the batches before them.
  if (!plan().local_maps) return;
  {
    std::lock_guard lock(mutex_);
    if (peers_.empty()) return;
  }
  handler_->markDirty(map, *kf, Topic::LmMap, 0, /*acknowledge=*/true);
}

void DistributedNode::keyframeMapped(const std::shared_ptr<core::Map>& map, const std::shared_ptr<core::KeyFrame>& kf) {
  const Plan p = plan();
  bool anyone = false;
  {
    std::lock_guard lock(mutex_);
    anyone = !peers_.empty();
  }
  if (p.local_maps && anyone) handler_->markDirty(map, *kf, Topic::LmMap);
  if (p.keyframes_to_lc) publisher_->push({map, kf, Topic::LmKeyframes, kTargetLc});
}

void DistributedNode::globalUpdate(const core::GlobalUpdate& u) {
  auto map = slam_.findMap(u.map);
  if (!map) return;
  std::vector<core::Id> merged;
  if (u.merged_map != core::kNoId) merged.push_back(u.merged_map);
  std::lock_guard lock(mutex_);
  // The map is in this epoch's frame from now on, for what this node sends and what it takes.
  const auto note = [&](uint64_t e) {
    std::lock_guard map_lock(map->mutex);
    integrator_.noteEpoch(*map, e);
  };
  if (options_.task == Task::LoopClosing) {
    const uint64_t e = std::max(published_[u.map], synced_[u.map]) + 1;
    published_[u.map] = synced_[u.map] = e;
    note(e);
    handler_->sendGlobal(map, e, Topic::LcMap, merged);
  } else if (plan_.local_maps && !peers_.empty()) {
    const uint64_t e = ++synced_[u.map];
    note(e);
    handler_->sendGlobal(map, e, Topic::LmMap, merged);
  }
}

void DistributedNode::onGlobal(std::vector<MapRecord>&& batches, Topic topic) {
  const core::Id map_id = batches.front().map;
  const uint64_t epoch = batches.front().epoch;
  if (topic == Topic::LcMap) {
    // The gateway applies LC's update, then relays its own full state of the map: LC's update
    // plus what LM made meanwhile, in one coordinate frame.
    integrator_.applyGlobal(batches, false);
    std::vector<core::Id> merged;
    for (const auto& b : batches) merged.insert(merged.end(), b.merged_maps.begin(), b.merged_maps.end());
    auto map = slam_.findMap(map_id);
    {
      std::lock_guard lock(mutex_);
      synced_[map_id] = std::max(synced_[map_id], epoch);
      if (map) handler_->sendGlobal(map, epoch, Topic::LmMap, merged);
    }
    releaseHeld(map_id);
    return;
  }
  bool ignore = false;
  {
    std::lock_guard lock(mutex_);
    auto it = published_.find(map_id);
    // LC takes the relay of its latest update only: an older one would undo a newer correction.
    if (it != published_.end() && it->second != epoch) {
      ++globals_ignored_;
      ignore = true;
      spdlog::info("node {}: global map {} of epoch {} ignored (this node published epoch {})", options_.id, map_id,
                   epoch, it->second);
    }
  }
  if (!ignore && integrator_.applyGlobal(batches, true)) {
    {
      std::lock_guard lock(mutex_);
      synced_[map_id] = std::max(synced_[map_id], epoch);
    }
    releaseHeld(map_id);
    return;
  }
  if (!ignore) {
    std::lock_guard lock(mutex_);
    ++globals_ignored_;  // older than the map here (a correction made here, not yet out)
    spdlog::info("node {}: global map {} of epoch {} ignored (the map here has left that frame)", options_.id, map_id,
                 epoch);
  }
  // Still, what is new here (points LM made) and what LM erased is taken, and the keyframes a
  // snapshot brings that this node never got: the one a mapping node mapped as it died, those
  // the node that took mapping back mapped after it gave mapping up again. Without them LC
  // ended such runs two keyframes short of TR and LM.
  for (const auto& b : batches) integrator_.applyLocal(b);  // labelled older: stale here
  for (const auto& a : integrator_.addMissing(batches)) {
    std::lock_guard lock(a.map->mutex);
    core::insertKeyframe(*a.map, *a.keyframe, slam_.scales(), &slam_.database());
  }
}

uint64_t DistributedNode::knownEpoch(core::Id map) const {
  uint64_t e = 0;
  if (auto it = synced_.find(map); it != synced_.end()) e = it->second;
  if (auto it = published_.find(map); it != published_.end()) e = std::max(e, it->second);
  return e;
}

void DistributedNode::releaseHeld(core::Id map) {
  // Runs on the map handler's thread, like every other apply: arrival order is kept.
  std::vector<MapRecord> ready;
  {
    std::lock_guard lock(mutex_);
    const uint64_t now = knownEpoch(map);
    for (auto it = held_.begin(); it != held_.end();) {
      if (it->map == map && it->epoch <= now) {
        ready.push_back(std::move(*it));
        it = held_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const auto& m : ready) integrator_.applyLocal(m);
}

void DistributedNode::onControl(const Message& m, Topic topic) {
  const auto c = static_cast<Control>(m.target);
  if (c == Control::EndOfSequence) {
    spdlog::info("node {}: end of the sequence, from node {}", options_.id, m.source);
    // Runs off the subscriber thread: finishing waits for queues that thread may feed. Made
    // under the lock: stop() takes the thread from another thread.
    std::lock_guard lock(mutex_);
    run_hosted_ = plan_.hosted;
    if (stopping_) return;
    // An LC answers every gateway that asks: after its gateway died, TR asks again as the new
    // one, and reads this node's map topic only from then on (the first Done never reached it).
    // The finisher that answered has nothing left to do once lc_answered_ is set: joined here.
    if (options_.task == Task::LoopClosing && finisher_.joinable() && lc_answered_) finisher_.join();
    if (finisher_.joinable()) return;
    if (options_.task == Task::LoopClosing) {
      lc_answered_ = false;
      finisher_ = std::thread([this, asker = m.source] {
        slam_.drain();
        // The LM's departure may not have reached this node yet: TR's last snapshot must
        // find TR in LC's latest epoch.
        if (trackingTookOver(asker)) resendGlobalsToTracking();
        while (!handler_->idle()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        // A gateway that took over at the end (TR, after its LM died) began to read this topic
        // only then: a Done written before its reader matched never reaches it (TR waited its
        // 60 s for one, session 40). Bounded: a gateway that never reads is not waited for.
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
        while (!transport_.peerReads(Topic::LcMap, asker) && std::chrono::steady_clock::now() < until) {
          {
            std::lock_guard lock(mutex_);
            if (stopping_) break;
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        transport_.publish(Topic::LcMap, controlPacket(options_.id, Control::Done));
        {
          std::lock_guard lock(mutex_);
          lc_answered_ = true;
        }
        changed_.notify_all();
      });
    } else {
      finisher_ = std::thread([this] { finishAsGateway(); });
    }
    return;
  }
  if (c == Control::SendMap) {
    answerMapRequest(m, topic);
    return;
  }
  if (c == Control::Release) {
    if (options_.task == Task::Tracking) return;
    spdlog::warn("node {}: released by node {} (its link is too slow to offload to); leaving", options_.id, m.source);
    {
      std::lock_guard lock(mutex_);
      released_by_ = true;
    }
    changed_.notify_all();
    return;
  }
  if (c == Control::Done) {
    {
      std::lock_guard lock(mutex_);
      if (topic == Topic::LcMap)
        lc_done_ = true;
      else
        done_ = true;
    }
    changed_.notify_all();
  }
}

void DistributedNode::answerMapRequest(const Message& m, Topic topic) {
  // Only the node that sends the asker its keyframes answers (LC, say, also reads the mapping
  // node's map topic, where a mapping node asks TR).
  const Plan p = plan();
  if (!(topic == Topic::LcMap ? p.keyframes_to_lc : p.keyframes_to_lm)) return;
  auto map = slam_.findMap(m.map);
  if (!map || map->merged_into.load()) {
    spdlog::info("node {}: node {} asked for map {}, which is not held here", options_.id, m.source, m.map);
    return;
  }
  spdlog::info("node {}: node {} asked for map {}", options_.id, m.source, m.map);
  sendSnapshot(map, {m.source, {Topic::LmMap}});
}

bool DistributedNode::finishAsGateway() {
  slam_.drain();
  bool answered = true;
  if (plan().keyframes_to_lc) {
    publisher_->push({nullptr, nullptr, Topic::LmKeyframes, static_cast<uint8_t>(Control::EndOfSequence)});
    std::unique_lock lock(mutex_);
    answered = changed_.wait_for(lock, std::chrono::seconds(60), [&] { return lc_done_ || !plan_.keyframes_to_lc; }) && lc_done_;
    if (!answered) spdlog::warn("node {}: no Done from LC; sending the last snapshot anyway", options_.id);
  }
  while (!handler_->idle()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  // The last snapshot: after it, every node holds this node's state.
  for (const auto& map : slam_.liveMaps()) {
    std::lock_guard lock(mutex_);
    handler_->sendGlobal(map, synced_[map->id], Topic::LmMap, {}, true);
  }
  while (!handler_->idle()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  transport_.publish(Topic::LmMap, controlPacket(options_.id, Control::Done));
  {
    std::lock_guard lock(mutex_);
    done_ = true;
  }
  changed_.notify_all();
  return answered;
}

bool DistributedNode::finishRun(std::chrono::milliseconds timeout) {
  const Plan p = plan();
  {
    std::lock_guard lock(mutex_);
    run_hosted_ = p.hosted;
  }
  if (p.keyframes_to_lm) {
    publisher_->push({nullptr, nullptr, Topic::TrKeyframes, static_cast<uint8_t>(Control::EndOfSequence)});
    // The Done comes from the gateway: one that leaves first sends none, and this node then
    // maps what it had sent it and ends without (it waited out the whole timeout before). The
    // leaving notice may come before the Done is handled here, behind the last snapshot.
    bool done = false;
    {
      std::unique_lock lock(mutex_);
      done = changed_.wait_for(lock, timeout, [&] {
        return done_ || (!plan_.keyframes_to_lm && departures_handled_ == departures_);
      }) && done_;
    }
    if (done) return true;
    const Plan now = plan();
    if (!now.mapping) return false;  // timed out with the gateway still there
    // The gateway left first, and this node maps again. With an LC left, it is the gateway now
    // and finishes the exchange with it: the LC's map would otherwise end without the last
    // snapshot, and its node would wait for a Done nobody sends.
    if (now.local_maps) return finishAsGateway();
    slam_.drain();
    return false;
  } else if (p.local_maps) {
    finishAsGateway();  // this node maps: it is the gateway
  } else {
    slam_.drain();
    return true;  // alone
  }
  return waitUntilDone(timeout);
}

bool DistributedNode::waitUntilDone(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  // Alone once the departures are handled: a Done sent just before leaving is in by then.
  return changed_.wait_for(lock, timeout, [&] {
    return done_ || released_by_ || (lc_answered_ && peers_.empty() && departures_handled_ == departures_);
  });
}

bool DistributedNode::completed() const {
  std::lock_guard lock(mutex_);
  return done_;
}

bool DistributedNode::released() const {
  std::lock_guard lock(mutex_);
  return released_by_;
}

void DistributedNode::watchGateway(std::chrono::steady_clock::time_point now) {
  // Only in real time does tracking starve: offline, it waits for the gateway instead.
  if (slam_.mode() != core::SlamSystem::Mode::Realtime) return;
  if (stopping_ || releaser_.joinable() || !plan_.keyframes_to_lm || handover_pending_) return;
  const int slow_ms = options_.settings.release_slow_gateway_ms, slow_acks = options_.settings.release_slow_acks;
  const auto starved = [&](const auto& waiting) {
    return std::any_of(waiting.begin(), waiting.end(), [&](const auto& k) { return watch_.starved(now, k.second); });
  };
  std::string why;
  if (lost_waiting_ && (starved(outstanding_) || starved(unanswered_)))
    why = fmt::format("tracking lost with a keyframe unacknowledged for over {} ms",
                      std::max(slow_ms, options_.settings.dead_peer_ms));
  else if (!watch_.tooSlow(now))
    return;
  else if (watch_.slowInARow() >= slow_acks)
    why = fmt::format("{} keyframe acknowledgements in a row took over {} ms", watch_.slowInARow(), slow_ms);
  else
    why = fmt::format("no keyframe acknowledged for {} ms", std::max(slow_ms * slow_acks, options_.settings.dead_peer_ms));
  releaser_ = std::thread([this, why] { releasePeers(why); });
}

void DistributedNode::releasePeers(const std::string& why) {
  std::vector<PeerInfo> gone;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || peers_.empty()) return;
    for (const auto& [id, p] : peers_) {
      gone.push_back(p);
      released_.insert({id, p.incarnation});
      released_names_.push_back(p.name);
    }
    peers_.clear();
  }
  {
    std::lock_guard lock(departed_mutex_);
    for (const auto& p : gone) departed_.insert(p.node);
  }
  std::string names;
  for (const auto& p : gone) {
    gate_.left(p.node);
    names += (names.empty() ? "" : ", ") + p.name;
  }
  spdlog::warn("node {}: {}: the link is too slow to offload; releasing {} and running alone", options_.id, why, names);
  // LM reads TR's keyframe topic, LC the gateway's map topic (so does LM).
  transport_.publish(Topic::TrKeyframes, controlPacket(options_.id, Control::Release));
  transport_.publish(Topic::LmMap, controlPacket(options_.id, Control::Release));
  applyPlan();  // alone: mapping and loop closing here, the unacknowledged keyframes mapped here
}

void DistributedNode::stop() {
  std::thread finisher, releaser;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    finisher = std::move(finisher_);
    releaser = std::move(releaser_);
  }
  if (finisher.joinable()) finisher.join();
  if (releaser.joinable()) releaser.join();
  gate_.stop();  // what is left goes out now: a peer that never matched is not waited for
  publisher_->finish();
  transport_.stop();
  subscriber_->finish();
  handler_->finish();
}

bool DistributedNode::remoteIdle() {
  std::lock_guard lock(mutex_);
  // An acknowledgement that never came (the keyframe was dropped at the gateway: its map was
  // merged meanwhile, or the gateway changed) must not hold keyframes back for good.
  const auto now = std::chrono::steady_clock::now();
  const auto lost = now - std::chrono::milliseconds(options_.settings.remote_mapping_wait_ms);
  for (auto it = outstanding_.begin(); it != outstanding_.end();)
    if (it->second < lost) {
      unanswered_.insert(*it);
      it = outstanding_.erase(it);
    } else {
      ++it;
    }
  constexpr size_t kUnansweredKept = 64;  // bounded: an LM that lives on never answers them
  while (unanswered_.size() > kUnansweredKept) unanswered_.erase(unanswered_.begin());
  watchGateway(now);
  return outstanding_.empty();
}

void DistributedNode::remoteWait() const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, std::chrono::milliseconds(options_.settings.remote_mapping_wait_ms),
                    [&] { return outstanding_.empty() || !plan_.keyframes_to_lm; });
}

nlohmann::json DistributedNode::report(double seconds) const {
  nlohmann::json j;
  uint8_t hosted = 0;
  {
    std::lock_guard lock(mutex_);
    hosted = run_hosted_ ? run_hosted_ : plan_.hosted;
  }
  j["task"] = communication::taskName(options_.task);
  j["tasks"] = nlohmann::json::array();
  for (Task t : {Task::Tracking, Task::Mapping, Task::LoopClosing})
    if (hosted & taskBit(t)) j["tasks"].push_back(communication::taskName(t));
  uint64_t bytes_out = 0, bytes_in = 0, msgs_out = 0, msgs_in = 0, kf_msgs = 0, map_msgs = 0;
  nlohmann::json topics = nlohmann::json::object();
  for (const auto& [name, t] : transport_.traffic()) {
    topics[name] = {{"bytes_out", t.bytes_out},       {"bytes_in", t.bytes_in},
                    {"messages_out", t.messages_out}, {"messages_in", t.messages_in},
                    {"writes_failed", t.writes_failed}, {"messages_lost", t.messages_lost}};
    bytes_out += t.bytes_out;
    bytes_in += t.bytes_in;
    msgs_out += t.messages_out;
    msgs_in += t.messages_in;
    if (name.find("keyframes") != std::string::npos)
      kf_msgs += t.messages_out + t.messages_in;
    else
      map_msgs += t.messages_out + t.messages_in;
  }
  const double s = std::max(seconds, 1e-9);
  j["bytes_out"] = bytes_out;
  j["bytes_in"] = bytes_in;
  j["messages_out"] = msgs_out;
  j["messages_in"] = msgs_in;
  j["topics"] = topics;
  j["bandwidth_mbps"] = (bytes_out + bytes_in) * 8.0 / s / 1e6;
  j["keyframe_msgs_hz"] = kf_msgs / s;
  j["map_msgs_hz"] = map_msgs / s;
  j["local_maps_sent"] = handler_->localMapsSent();
  j["global_maps_sent"] = handler_->globalMapsSent();
  j["maps_received"] = handler_->mapsReceived();
  j["keyframes_published"] = publisher_->published();
  j["keyframes_received"] = subscriber_->received();
  j["messages_dropped"] = subscriber_->dropped() + handler_->dropped();
  {
    std::lock_guard lock(mutex_);
    j["globals_ignored"] = globals_ignored_;
    j["local_maps_held"] = local_maps_held_;
    j["maps_awaited"] = maps_awaited_;
    j["maps_asked_for"] = maps_asked_for_;
    j["keyframes_taken_back"] = keyframes_taken_back_;
    if (!ack_ms_.empty()) j["keyframe_ack_ms"] = ackSummary(ack_ms_);
    if (!released_names_.empty()) j["peers_released"] = released_names_;
    j["stale_points_carried"] = integrator_.stalePointsCarried();
    j["peers"] = peers_.size();
  }
  j["s_full_keyframes"] = observer_.keyframeCount();
  j["s_full_keyframes_not_in_map"] = sFullKeyframesNotInMap();
  return j;
}

nlohmann::json DistributedNode::ackSummary(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  auto at = [&](double q) { return ms[std::min(ms.size() - 1, static_cast<size_t>(q * static_cast<double>(ms.size())))]; };
  return {{"count", ms.size()}, {"median", at(0.5)}, {"p95", at(0.95)}, {"max", ms.back()}};
}

std::vector<core::Id> DistributedNode::sFullKeyframesNotInMap() const {
  std::unordered_set<core::Id> held;
  for (const auto& map : slam_.liveMaps()) {
    std::lock_guard lock(map->mutex);
    for (const auto& [id, kf] : map->keyframes) held.insert(id);
  }
  std::vector<core::Id> missing;
  for (const auto& [id, pose] : observer_.digest().keyframes)
    if (!held.count(id)) missing.push_back(id);
  std::sort(missing.begin(), missing.end());
  return missing;
}

}  // namespace hiveslam::distribution
