// DistributedNode: start-up, peers and the plan they make (policy D(N, G)), the SLAM system's
// events, and stop. Hand-over, global maps, the end of a run, the slow link and the report are
// in the distributed_node_*.cpp files beside this one.
#include "distribution/distributed_node.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

#include "core/mapping/keyframe_insertion.hpp"

namespace hiveslam::distribution {

using communication::Message;
using communication::PeerInfo;
using communication::Task;
using communication::Topic;
using communication::taskBit;

namespace {

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
          std::shared_ptr<core::KeyFrame> kf = a.keyframe;
          {
            std::lock_guard lock(a.map->mutex);
            core::insertKeyframe(*a.map, *kf, slam_.scales(), &slam_.database());
            // A snapshot brought the keyframe first: loop detection takes the map's copy.
            if (kf->bad)
              if (auto it = a.map->keyframes.find(kf->id); it != a.map->keyframes.end()) kf = it->second;
          }
          slam_.submit(a.map, kf, core::SlamSystem::Module::LoopClosing);
        } else {
          slam_.submit(a.map, a.keyframe, core::SlamSystem::Module::Mapping);
        }
      },
      [this](const Message& m) { onControl(m, Topic::TrKeyframes); }, [this](core::Id id, uint8_t target) { awaitMap(id, target); },
      [this](const core::Remeasurements& r) { slam_.addRemeasurements(r); });
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
  hooks.global = [this](std::vector<MapRecord>&& b, Topic t, uint16_t source) { onGlobal(std::move(b), t, source); };
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
  bool newcomer = false, restarted = false, leaving = false, rejoined = false;
  const Plan before = plan();
  const auto maps_here = slam_.liveMaps();  // before mutex_: the atlas takes locks of its own
  {
    std::lock_guard lock(mutex_);
    // A node released here is gone for this node already: its announcements until the Release
    // reaches it change nothing. Restarted (a new incarnation), it is a newcomer like any other.
    if (released_.count({peer.node, peer.incarnation})) return;
    leaving = stopping_;
    auto it = peers_.find(peer.node);
    newcomer = it == peers_.end() || it->second.incarnation != peer.incarnation;
    restarted = it != peers_.end() && newcomer;
    const auto gone = gone_incarnations_.find(peer.node);
    rejoined = newcomer && gone != gone_incarnations_.end() && gone->second == peer.incarnation;
    if (gone != gone_incarnations_.end()) gone_incarnations_.erase(gone);
    if (rejoined && peer.task == Task::Tracking && options_.task != Task::Tracking) {
      adopt_from_[peer.node].clear();
      auto& known = known_at_return_[peer.node];
      known.clear();
      for (const auto& m : maps_here) known.insert(m->id);
      if (options_.task == Task::LoopClosing) {
        handover_due_[peer.node] =
            std::chrono::steady_clock::now() + std::chrono::milliseconds(options_.settings.handover_wait_ms) / 5;
        startHandOverWatch();
      }
    } else if (newcomer) {
      adopt_from_.erase(peer.node);
      known_at_return_.erase(peer.node);
      handover_due_.erase(peer.node);
    }
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
  // A tracking node back from a partition (the same incarnation) kept its maps and mapped on
  // alone meanwhile: its maps are newer than this node's and come here with mapping. This
  // node's older snapshot, sent to it, would overwrite them (a 30 s cut of TR from LM and LC
  // ended 6-100x off the uncut ATE).
  const bool peer_is_newer = rejoined && peer.task == Task::Tracking;
  if (newcomer && !peer_is_newer && (after.local_maps || (before.mapping && !after.mapping))) sendMapsTo(peer);
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
  // completed (LC ended 71 points short). And a gateway that leaves at the end of
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
    gone_incarnations_[peer.node] = peer.incarnation;
    peers_.erase(it);
    // Stopping, or the run is over here (the gateway's Done is in): nothing is taken over.
    if (stopping_ || done_) return;
  }
  applyPlan();
  transport_.announce(self());
  // A tracking node that left before handing its map over hands nothing over.
  if (peer.task == Task::Tracking) releaseHeldUpdates(core::kNoId, nullptr);
  // LC whose mapping node left: TR maps again, and is its gateway now.
  if (options_.task == Task::LoopClosing && peer.task == Task::Mapping) resendGlobalsToTracking();
  // TR, the gateway now that its LM left, and an LC: the keyframes LM had mapped but not yet
  // sent on to LC never reach it (LC's S_full got their records from TR's last snapshot, its
  // SLAM map never their features: a keyframe short of TR). The newcomer's snapshot
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
    if (p.mapping != before.mapping) watch_.restart();
    // A gateway taking the map over answers nothing until it holds it (handover_wait_ms at
    // most): it is not judged slow before its first answer (a restarted LM was released). Set
    // with the plan: set after it, tracking judged the new gateway in between.
    if (before.mapping && !p.mapping) handover_pending_ = true;
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

void DistributedNode::stop() {
  std::thread finisher, releaser, watch;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    finisher = std::move(finisher_);
    releaser = std::move(releaser_);
    watch = std::move(handover_watch_);
  }
  changed_.notify_all();
  if (finisher.joinable()) finisher.join();
  if (releaser.joinable()) releaser.join();
  if (watch.joinable()) watch.join();
  gate_.stop();  // what is left goes out now: a peer that never matched is not waited for
  publisher_->finish();
  transport_.stop();
  subscriber_->finish();
  handler_->finish();
}

}  // namespace hiveslam::distribution
