// DistributedNode: control messages and the end-of-run exchange (see "End of a run" in the
// header).
#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "distribution/distributed_node.hpp"
#include "distribution/packet.hpp"

namespace hiveslam::distribution {

using communication::Message;
using communication::Task;
using communication::Topic;

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
        // 60 s for one). Bounded: a gateway that never reads is not waited for.
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

void DistributedNode::pushRemeasurements(const core::Remeasurements& r, Topic topic) {
  // A few packets of at most 20 keyframes (a sweep run: some 29,600 observations, 246 KB).
  constexpr size_t kKeyframesPerPacket = 20;
  core::Remeasurements part;
  size_t bytes = 0, packets = 0;
  const auto send = [&] {
    auto m = std::make_shared<Message>(pack(part, options_.id, 0, 0, 0));
    bytes += m->wireSize();
    ++packets;
    publisher_->push({nullptr, nullptr, topic, 0, false, std::move(m)});
    part.clear();
  };
  for (const auto& [keyframe, entries] : r) {
    part.emplace(keyframe, entries);
    if (part.size() == kKeyframesPerPacket) send();
  }
  if (!part.empty()) send();
  spdlog::info("node {}: {} re-measured observations sent in {} packets, {} KB", options_.id, core::remeasurementCount(r),
               packets, bytes / 1024);
}

bool DistributedNode::finishAsGateway() {
  // No hand-over is waited for past the end; applied on the map handler's thread, in order.
  handler_->afterIncoming([this] { releaseHeldUpdates(core::kNoId, nullptr); });
  while (!handler_->idle()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  slam_.drain();
  bool answered = true;
  if (plan().keyframes_to_lc) {
    // A TR that maps now measures its own keyframes here; an LM passes on what TR sent.
    slam_.remeasureOwnKeyframes();
    pushRemeasurements(slam_.remeasurements(), Topic::LmKeyframes);
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
    peers_at_end_ = peers_.size();
  }
  if (p.keyframes_to_lm) {
    pushRemeasurements(slam_.remeasureOwnKeyframes(), Topic::TrKeyframes);
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

}  // namespace hiveslam::distribution
