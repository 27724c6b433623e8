#include "distribution/keyframe_publisher.hpp"

#include <spdlog/spdlog.h>

#include <set>

#include "common/thread_name.hpp"
#include "core/map/follow_merges.hpp"
#include "distribution/packet.hpp"
#include "distribution/state_capture.hpp"

namespace hiveslam::distribution {

KeyframePublisher::KeyframePublisher(communication::Transport& transport, Observer& observer, SentLedger& ledger,
                                     uint16_t node, Known known, Label label, AwaitReaders await_readers)
    : transport_(transport),
      observer_(observer),
      ledger_(ledger),
      node_(node),
      known_(std::move(known)),
      label_(std::move(label)),
      await_readers_(std::move(await_readers)) {
  thread_ = std::thread([this] {
    nameThisThread("kf-publisher");
    loop();
  });
}

KeyframePublisher::~KeyframePublisher() { finish(); }

void KeyframePublisher::finish() {
  queue_.close();
  if (thread_.joinable()) thread_.join();
}

void KeyframePublisher::loop() {
  while (auto job = queue_.pop()) {
    try {
      publish(*job);
    } catch (const std::exception& e) {
      spdlog::error("keyframe publisher: {}", e.what());
    }
  }
}

void KeyframePublisher::publish(const Job& job) {
  if (job.handed_over) {
    maps_started_[job.map->id] = true;
    return;
  }
  if (await_readers_) await_readers_(job.topic);
  if (job.packet) {
    communication::Message m = *job.packet;
    transport_.publish(job.topic, std::move(m));
    return;
  }
  if (!job.keyframe) {  // a control packet, in order after the keyframes before it
    transport_.publish(job.topic, controlPacket(node_, static_cast<Control>(job.target)));
    return;
  }
  KeyFrameMessage m;
  uint64_t label = 0;
  // Queued before its map was merged into another here: the keyframe lives in the merged map
  // now, in that map's frame, and goes out as that map's. Sent as the old map's, in a pose the
  // merge had moved, LM could not place it, and TR ended a run holding it alone. (Maps stay in
  // the atlas once merged: the pointers stay valid.)
  core::Map* map = job.map.get();
  auto lock = core::lockFollowingMerges(map);
  if (map != job.map.get()) maps_started_[map->id] = true;  // the receiver holds it already
  {
    const core::KeyFrame& kf = *job.keyframe;
    // Culled before its turn: its erasure goes out with the map's journal. Sent, it was made
    // again at the receiver, which would hold it alone.
    if (kf.bad) return;
    label = label_ ? label_(*map) : 0;
    m.keyframe = captureKeyframe(kf, map->id, true);
    std::vector<const core::KeyFrame*> with_points{&kf};
    // A new map's first keyframe travels with its second (the receiver builds the map from them).
    if (!maps_started_[map->id]) {
      maps_started_[map->id] = true;
      for (const auto& [id, other] : map->keyframes)
        if (other.get() != &kf && other->id < kf.id) {
          m.companions.push_back(captureKeyframe(*other, map->id, true));
          with_points.push_back(other.get());
        }
    }
    for (const core::KeyFrame* k : with_points)
      for (const auto& p : k->points)
        if (p && !p->bad && !known_(job.topic, p->id)) {
          m.points.push_back(capturePoint(*p, true));
          ledger_.mark(job.topic, m.points.back());
        }
    // Tracking's counts for points made since the last few keyframes (local mapping's
    // candidates for culling), found among the keyframe's neighbours.
    auto& recent = recent_[map->id];
    if (job.topic == communication::Topic::TrKeyframes && !recent.empty()) {
      const core::Id since = recent.front();
      std::set<core::MapPoint*, core::ById> seen;
      std::vector<const core::KeyFrame*> around{&kf};
      for (const core::KeyFrame* n : kf.bestCovisible(10)) around.push_back(n);
      for (const core::KeyFrame* k : around)
        for (const auto& p : k->points)
          if (p && !p->bad && p->first_keyframe >= since && seen.insert(p.get()).second)
            m.stats.push_back({p->id, static_cast<uint32_t>(p->visible), static_cast<uint32_t>(p->found)});
    }
    recent.push_back(kf.id);
    if (recent.size() > 4) recent.pop_front();
  }
  lock.unlock();
  observer_.record(m.keyframe);
  for (const auto& p : m.points) observer_.record(p, m.keyframe.map);
  transport_.publish(job.topic, pack(m, node_, job.target, map->id, label));
  ++published_;
}

}  // namespace hiveslam::distribution
