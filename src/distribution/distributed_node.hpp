#pragma once
// One node of the distributed system: this process's SLAM system (core), the distribution
// layer around it (Observer, KeyFrame Publisher and Subscriber, Map Handler, policy) and a
// transport. Without a transport, or with no peer, it is the standalone system.
//
// End of a run (hiveslam cluster): TR sends EndOfSequence after its last keyframe; LM maps what
// it has, forwards it to LC; LC finishes its queue and answers Done; LM then sends a last full
// snapshot of its maps and Done on its map topic. A node is finished when it has that Done:
// from then on every node's S_full holds the same keyframes and points (eventual consistency).
// A gateway that dies before its Done: TR stops waiting for it and, with mapping back and an
// LC left, runs the gateway's part itself (LC answers each gateway that asks); an LC that has
// answered and is left alone ends without the Done.
//
// Hand-over: a node that joins the network gets the maps so far as a full snapshot, from the
// gateway (a late LC) or from the node that mapped until it came (an LM that joins or returns
// after TR took mapping back). Its keyframes of those maps wait for the snapshot. A peer back
// from a partition (the incarnation whose lease ran out) is a newcomer too, but a tracking node
// back from one is sent nothing: it kept its maps and mapped on alone, so the newer maps go from
// it, not to it (docs/RELIABILITY.md). It hands them over only while it maps: an LC that hears
// it back after LM took mapping asks the gateway for them (watchHandOvers).
//
// Slow link: a tracking node whose gateway acknowledges its keyframes too late (GatewayWatch)
// releases its peers (Control::Release) and runs alone from then on, as the standalone system.
// It ignores them until they leave; a released node leaves the network when the Release
// reaches it, and ends its run "released".
//
// Lost map: a node that gets keyframes of a map it does not hold, with no snapshot coming (the
// packet that started the map was lost), asks the node that sends it keyframes for the map
// (Control::SendMap) and gets the same snapshot a newcomer would.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <set>
#include <memory>
#include <mutex>
#include <optional>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "communication/transport.hpp"
#include "core/system/slam_system.hpp"
#include "distribution/gateway_watch.hpp"
#include "distribution/keyframe_publisher.hpp"
#include "distribution/keyframe_subscriber.hpp"
#include "distribution/map_handler.hpp"
#include "distribution/policy.hpp"
#include "distribution/reader_gate.hpp"

namespace hiveslam::distribution {

struct NodeOptions {
  communication::Task task = communication::Task::Tracking;
  uint16_t id = 1;
  std::string name;
  DistributionSettings settings;
};

class DistributedNode final : public core::SystemEvents {
 public:
  DistributedNode(core::SlamSystem& slam, communication::Transport& transport, NodeOptions options);
  ~DistributedNode() override;

  // Joins the network and applies the policy to the peers found so far.
  void start();
  // TR: after the last frame, runs the end-of-run exchange (bounded by `timeout`). Returns
  // whether it completed: the Done came back or, when the gateway left before sending it and
  // an LC remains, this node finished the exchange with the LC as its gateway.
  bool finishRun(std::chrono::milliseconds timeout);
  // LM and LC: blocks until the end-of-run exchange is over (or `timeout`). Over also for an
  // LC that has answered its Done and is left alone: its gateway left before sending the last
  // snapshot, and nobody is left to send one (see completed()).
  bool waitUntilDone(std::chrono::milliseconds timeout);
  // Whether the gateway's Done came (this node's own, on the gateway).
  bool completed() const;
  // LM and LC: whether a tracking node released this node (its link was too slow to offload
  // to). waitUntilDone() is over then too.
  bool released() const;
  // TR: gives up offloading (see Slow link above): `why` goes to the log.
  void releasePeers(const std::string& why);
  // Leaves the network (after the exchange).
  void stop();

  Plan plan() const;
  // taskBit()s of the peers present now.
  uint8_t presentTasks() const;
  // taskBit()s of the present peers that have heard this node too (PeerInfo::seen) and, for
  // a mapping peer of a tracking node, read its keyframes: what a tracking node waits for
  // before its first frame, since what it sends a peer that has not heard it yet is lost.
  uint8_t mutualTasks() const;
  const Observer& observer() const { return observer_; }
  // What the node adds to `hiveslam run`'s report: tasks, traffic, message rates.
  nlohmann::json report(double seconds) const;
  // Keyframes of S_full that no live SLAM map holds: known here by their record only, without
  // the features to track against, match or correct them. Empty after a healthy run.
  std::vector<core::Id> sFullKeyframesNotInMap() const;
  // Count, median, 95th percentile and max of keyframe round trips (report's keyframe_ack_ms).
  static nlohmann::json ackSummary(std::vector<double> ms);

  // core::SystemEvents
  void mapCreated(const std::shared_ptr<core::Map>& map) override;
  void trackingLost() override;
  void keyframeCreated(const std::shared_ptr<core::Map>& map, const std::shared_ptr<core::KeyFrame>& kf) override;
  void keyframeTriangulated(const std::shared_ptr<core::Map>& map, const std::shared_ptr<core::KeyFrame>& kf) override;
  void keyframeMapped(const std::shared_ptr<core::Map>& map, const std::shared_ptr<core::KeyFrame>& kf) override;
  void globalUpdate(const core::GlobalUpdate& update) override;

 private:
  // A keyframe message's target module (KeyframePublisher::Item::target).
  static constexpr uint8_t kTargetLm = 1, kTargetLc = 2;

  void onPeer(const communication::PeerInfo& peer, bool present);
  // A peer's leaving notice (transport thread): what must not wait; departed() follows on the
  // map handler's thread, once the packets the peer sent before it are handled.
  void onLeaving(const communication::PeerInfo& peer);
  // The peer leaves peers_ and the tasks are re-planned, unless the run is over here.
  void departed(const communication::PeerInfo& peer);
  void dropPendingGlobals(const communication::PeerInfo& peer);
  void applyPlan();
  void onGlobal(std::vector<MapRecord>&& batches, communication::Topic topic, uint16_t source);
  // LC: runs watchHandOvers() on handover_watch_ unless it runs already; mutex_ held.
  void startHandOverWatch();
  // LC: a fifth of the hand-over wait after each tracking node's return from a partition, the
  // maps it should have handed over here and has not are asked for from the gateway. Returns
  // when no return is left to check, or the node stops.
  void watchHandOvers();
  // The gateway: LC's update applied, then this node's state of the map relayed (LmMap).
  void applyLoopClosingUpdate(const std::vector<MapRecord>& batches);
  // The gateway: LC's update of a map that a tracking node back from a partition has yet to
  // hand over, held until it has (true), then applied if it was made from that map.
  bool holdForAdoption(std::vector<MapRecord>& batches);
  // Held updates applied: those of `map` (all maps if kNoId); with `adopted`, only one that
  // covers it (StateIntegrator::covers), the others dropped as older than the adopted map.
  // With `expired`, only those held longer than the hand-over wait (a map never handed over).
  void releaseHeldUpdates(core::Id map, const std::vector<MapRecord>* adopted, bool expired = false);
  void onControl(const communication::Message& m, communication::Topic topic);
  // The gateway's part of the end of a run. Returns whether the LC (if any) answered.
  bool finishAsGateway();
  // End of a run: observations measured again (by TR, which alone holds the keyframes' images)
  // go to the next node towards loop closing, ahead of the end-of-sequence packet on `topic`,
  // for the final global BA (SlamSettings::remeasure).
  void pushRemeasurements(const core::Remeasurements& r, communication::Topic topic);
  // A newcomer gets this node's maps so far (see Hand-over above).
  void sendMapsTo(const communication::PeerInfo& peer);
  // LC, once its mapping node has left: the global maps that node had not relayed yet never
  // reach TR, which maps again as the new gateway. Its maps would stay in an older epoch, and
  // LC ignores everything TR labels with that epoch, the last snapshot included (LC ended 79
  // points short of TR). So LC sends its latest global state of each map to TR.
  void resendGlobalsToTracking();
  // LC: whether `asker` is TR asking as the gateway after an LM (a TR that was the gateway all
  // along has every global map already).
  bool trackingTookOver(uint16_t asker) const;
  std::vector<communication::PeerInfo> peersWith(communication::Task task) const;
  // A full snapshot of `map` with its keyframes' features, for `newcomer` (a hand-over, or a
  // node that asked for a map it missed).
  void sendSnapshot(const std::shared_ptr<core::Map>& map, Newcomer newcomer);
  // Subscriber thread: until map `id` is held here, a new node's start-up is over, or the
  // node stops (handover_wait_ms at most).
  // `target`: the module the waiting keyframe is for. Asks for the map when no snapshot comes.
  void awaitMap(core::Id id, uint8_t target);
  // Control::SendMap: a snapshot of the map for the node that asked, if this node feeds it.
  void answerMapRequest(const communication::Message& m, communication::Topic topic);
  // Tracking thread, each frame while mapping is remote: whether the gateway has acknowledged
  // every keyframe (those it never will no longer count), and watchGateway().
  bool remoteIdle();
  void remoteWait() const;
  // With mutex_ held: starts releasePeers() on its own thread once the gateway is too slow
  // (GatewayWatch).
  void watchGateway(std::chrono::steady_clock::time_point now);
  communication::PeerInfo self() const;

  core::SlamSystem& slam_;
  communication::Transport& transport_;
  NodeOptions options_;
  Observer observer_;
  SentLedger ledger_;
  StateIntegrator integrator_;
  ReaderGate gate_;  // keyframes wait for the readers of peers that just joined
  std::unique_ptr<KeyframePublisher> publisher_;
  std::unique_ptr<KeyframeSubscriber> subscriber_;
  std::unique_ptr<MapHandler> handler_;

  std::mutex apply_mutex_;  // one applyPlan() at a time; taken before mutex_
  mutable std::mutex mutex_;  // guards everything below
  mutable std::condition_variable changed_;
  std::map<uint16_t, communication::PeerInfo> peers_;
  Plan plan_;
  std::vector<communication::Topic> subscribed_;
  std::map<core::Id, uint64_t> synced_;     // last global epoch applied, per map
  std::map<core::Id, uint64_t> published_;  // LC: last global epoch published, per map
  // TR: keyframes sent, not yet acknowledged as mapped (MapRecord::mapped), with when they went.
  std::map<core::Id, std::chrono::steady_clock::time_point> outstanding_;
  // TR: those no longer waited for (remote_mapping_wait_ms passed). Mapped here if this node
  // takes mapping back: the mapping node died before it mapped them.
  std::map<core::Id, std::chrono::steady_clock::time_point> unanswered_;
  std::vector<MapRecord> held_;             // local maps ahead of synced_, in arrival order
  bool done_ = false, lc_done_ = false;
  bool lc_answered_ = false;  // LC: its Done went to the gateway that asked last
  bool had_mapping_peer_ = false;  // a mapping node was among the peers at some point
  bool stopping_ = false;  // stop() has begun: no finisher may start any more
  uint8_t run_hosted_ = 0;  // what it ran when the sequence ended (before peers leave)
  // Its peers when its input ended: those that leave at the end of a run (LM and LC once the
  // last map is in) may go before the report is written (a 3-node run reported 1 peer of 2).
  std::optional<size_t> peers_at_end_;
  int globals_ignored_ = 0;
  int local_maps_held_ = 0;  // local maps that came ahead of their global update
  uint64_t incarnation_ = 0;
  int maps_awaited_ = 0;  // keyframes that waited for a hand-over
  int maps_asked_for_ = 0;  // maps asked for (Control::SendMap): for waiting keyframes, or a missed hand-over
  int keyframes_taken_back_ = 0;  // unacknowledged keyframes mapped here after the LM left
  // TR: each acknowledged keyframe's round trip, in ms (sent to mapped, as TR saw it): what
  // decides how often TR may make a keyframe, and what a slow link stretches first.
  std::vector<double> ack_ms_;
  GatewayWatch watch_;  // TR: how its gateway answers
  bool lost_waiting_ = false;  // TR: tracking was lost since the gateway's last answer
  bool handover_pending_ = false;  // TR: its new gateway has not answered since taking the map
  GatewayWatch::Clock::time_point judge_from_{};  // TR: round trips of keyframes sent since
  std::set<std::pair<uint16_t, uint64_t>> released_;  // TR: (node, incarnation) it released
  std::vector<std::string> released_names_;           // TR: for the report
  std::thread releaser_;      // TR: runs releasePeers() off the tracking thread
  bool released_by_ = false;  // LM, LC: a tracking node released this node
  int departures_ = 0, departures_handled_ = 0;  // peers that left; of those, handled in order
  uint64_t knownEpoch(core::Id map) const;  // the newer of synced_ and published_; mutex_ held
  void releaseHeld(core::Id map);           // applies the held local maps the epoch has reached
  // A global map taken whole whatever its labels (StateIntegrator::adoptGlobal), `why` logged.
  void adoptWhole(const std::vector<MapRecord>& batches, uint16_t source, const char* why);
  std::thread finisher_;  // the end-of-run exchange (LM, LC)
  // Peers that departed (their lease ran out, or they left), by node: the incarnation that
  // went. The same incarnation back is a partition that healed, not a restart. Guarded by mutex_.
  std::map<uint16_t, uint64_t> gone_incarnations_;
  // LM, LC: tracking nodes back from a partition, by node, and the maps already taken whole
  // from them (the first global map of each: StateIntegrator::adoptGlobal). Guarded by mutex_.
  std::map<uint16_t, std::set<core::Id>> adopt_from_;
  // LM, LC: the maps this node held when each of those tracking nodes came back: those it
  // hands over (a map made since comes as keyframes, not whole). Guarded by mutex_.
  std::map<uint16_t, std::set<core::Id>> known_at_return_;
  // LC: when to check that each of them handed its maps over (watchHandOvers), by node; the
  // thread that checks, and whether it runs. Guarded by mutex_.
  std::map<uint16_t, std::chrono::steady_clock::time_point> handover_due_;
  std::thread handover_watch_;
  bool handover_watching_ = false;
  // The gateway: LC's latest update of each map held by holdForAdoption, and since when.
  // Guarded by mutex_.
  struct HeldUpdate {
    std::vector<MapRecord> batches;
    std::chrono::steady_clock::time_point since;
  };
  std::map<core::Id, HeldUpdate> held_updates_;
  // Peers that left and have not come back (StateIntegrator::setDeparted). Its own lock, taken
  // last: the integrator asks with a map's mutex held.
  mutable std::mutex departed_mutex_;
  std::set<uint16_t> departed_;
};

}  // namespace hiveslam::distribution
