#pragma once
// The Map Handler: one thread for incoming and outgoing maps.
//
// Outgoing local maps: keyframes that local mapping changed are marked dirty; the handler sends
// them newest first, with the points they see, in batches that grow while no new keyframe is
// mapped, each batch a short gap after the last. Keyframe links and point descriptors go only
// when they changed. Erasures (the map's journal) ride with the next batch.
// Outgoing global maps: after a loop closure, merge or global BA, the whole map in batches; a
// newer global update of the same map restarts the sending.
// Incoming maps: local ones are applied as they come; global ones once all their batches are in.
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <set>
#include <thread>
#include <unordered_map>

#include "communication/transport.hpp"
#include "distribution/distribution_settings.hpp"
#include "distribution/sent_ledger.hpp"
#include "distribution/state_integrator.hpp"

namespace hiveslam::distribution {

// A node a snapshot is for (MapHandler::sendGlobal), and the topics it reads from this node.
struct Newcomer {
  uint16_t node = 0;
  std::vector<communication::Topic> reads;
};

class MapHandler {
 public:
  struct Hooks {
    // Incoming local map from a newer epoch than this node has applied (its sender took a
    // global update that is still on its way here): the hook keeps it and returns true. Its
    // poses are in the new frame; applied now, the global update would correct them twice.
    std::function<bool(const MapRecord&)> hold;
    // Incoming global map, complete (all batches), from `topic`, sent by node `source`.
    std::function<void(std::vector<MapRecord>&&, communication::Topic, uint16_t source)> global;
    std::function<void(const MapRecord&)> local_applied;
    // A control packet, in order with the maps of its topic.
    std::function<void(const communication::Message&, communication::Topic)> control;
    // Whether this node's maps are settled enough for a newcomer's snapshot: what changes
    // them after the capture must also reach the newcomer by a later message.
    std::function<bool()> settled;
  };
  MapHandler(communication::Transport& transport, StateIntegrator& integrator, Observer& observer,
             SentLedger& ledger, const DistributionSettings& settings, uint16_t node, Hooks hooks);
  ~MapHandler();

  void incoming(communication::Message&& m, communication::Topic topic);
  // Runs `f` on the handler thread once everything that came in before has been handled. A
  // peer's leaving notice comes on its own path and can overtake what the peer sent just before
  // leaving (its last snapshot, its Done): what the node does about the leaving waits for those.
  void afterIncoming(std::function<void()> f);
  // Local mapping changed `kf` and up to `window` of its covisible keyframes (the setting's
  // local_window when negative), sent on `topic` with the points they see. `acknowledge`: the
  // batch that carries `kf` also tells its maker that `kf` is mapped (MapRecord::mapped).
  void markDirty(const std::shared_ptr<core::Map>& map, const core::KeyFrame& kf, communication::Topic topic,
                 int window = -1, bool acknowledge = false);
  // The whole map, as a global map of `epoch`, on `topic`.
  // `full`: every point with its full record and every keyframe with its links (a snapshot for
  // a node that may have missed updates: a newcomer, or the end of a run). With a newcomer
  // the keyframes go with their features (it holds none of them), and the map is taken only
  // once the newcomer reads every topic it gets from this node and Hooks::settled holds (up to
  // `handover_wait_ms`): what goes before never reaches it, and what goes after the capture is
  // not in the snapshot.
  void sendGlobal(const std::shared_ptr<core::Map>& map, uint64_t epoch, communication::Topic topic,
                  std::vector<core::Id> merged_maps, bool full = false, Newcomer newcomer = {});
  // Sends everything pending (dirty keyframes, global maps), then stops the thread.
  void finish();
  // Whether nothing is waiting to be sent or applied.
  bool idle() const;
  int localMapsSent() const { return local_sent_; }
  int globalMapsSent() const { return global_sent_; }
  int mapsReceived() const { return received_; }
  int dropped() const { return dropped_; }

 private:
  struct Outgoing {
    std::shared_ptr<core::Map> map;
    communication::Topic topic{};
    std::set<core::Id, std::greater<>> dirty;  // keyframe ids, newest first
    std::set<core::Id> dirty_points;
    std::set<core::Id> mapped;  // acknowledgements, each sent with the batch holding its keyframe
    int batch = 0;  // grows while no new keyframe is marked
  };
  struct GlobalJob {
    std::shared_ptr<core::Map> map;
    uint64_t epoch = 0;
    communication::Topic topic{};
    std::vector<core::Id> merged;
    bool full = false;
    Newcomer newcomer;
    std::chrono::steady_clock::time_point reader_deadline;
    std::vector<MapRecord> batches;  // captured when its turn comes
    size_t next = 0;
    MapRecord carried;  // erasures of the updates this one replaced
  };
  // `from` is replaced by the newer `into`: what `from` would have announced once moves over.
  static void carryOver(GlobalJob& from, GlobalJob& into);
  void loop();
  void handleIncoming(communication::Message& m, communication::Topic topic);
  void sendLocalBatch(Outgoing& o);
  void captureGlobal(GlobalJob& g);
  KeyFrameRecord updateRecord(const core::KeyFrame& kf, core::Id map, communication::Topic topic);
  // Just before a batch goes out: point records stripped to positions where the receivers have
  // the full one, and the ledgers updated with what this batch carries.
  void trimForSending(MapRecord& m, communication::Topic topic, bool full);

  communication::Transport& transport_;
  StateIntegrator& integrator_;
  Observer& observer_;
  SentLedger& ledger_;
  DistributionSettings settings_;
  uint16_t node_;
  Hooks hooks_;

  mutable std::mutex mutex_;  // guards the queues below
  std::condition_variable wake_;
  struct Inbound {
    communication::Message message;
    communication::Topic topic{};
    std::function<void()> after;  // set: a marker (afterIncoming), no message
  };
  std::deque<Inbound> inbox_;
  std::unordered_map<core::Id, Outgoing> outgoing_;  // by map
  std::deque<GlobalJob> globals_;
  bool stopping_ = false, busy_ = false;
  std::thread thread_;
  // Handler thread only: hash of the links last sent per (topic, keyframe).
  std::unordered_map<core::Id, size_t> links_sent_[communication::kTopicCount];
  uint32_t updates_captured_ = 0;  // handler thread only: numbers this node's global maps
  std::atomic<int> local_sent_{0}, global_sent_{0}, received_{0}, dropped_{0};
};

}  // namespace hiveslam::distribution
