#include "distribution/reader_gate.hpp"

#include <vector>

namespace hiveslam::distribution {

using communication::Task;
using communication::Topic;

namespace {

bool readsFromUs(Task task, Topic topic) {
  switch (topic) {
    case Topic::TrKeyframes: return task == Task::Mapping;
    case Topic::LmKeyframes: return task == Task::LoopClosing;
    default: return false;  // map topics: a later snapshot or batch repairs a lost one
  }
}

}  // namespace

void ReaderGate::joined(uint16_t node, Task task) {
  std::lock_guard lock(mutex_);
  newcomers_[node] = {task, Clock::now() + patience_};
}

void ReaderGate::left(uint16_t node) {
  {
    std::lock_guard lock(mutex_);
    newcomers_.erase(node);
  }
  changed_.notify_all();
}

void ReaderGate::stop() {
  {
    std::lock_guard lock(mutex_);
    stopped_ = true;
  }
  changed_.notify_all();
}

void ReaderGate::await(Topic topic) {
  std::unique_lock lock(mutex_);
  while (!stopped_) {
    const auto now = Clock::now();
    std::vector<uint16_t> waiting;
    for (auto it = newcomers_.begin(); it != newcomers_.end();) {
      if (now >= it->second.until) {
        it = newcomers_.erase(it);  // given up on: what it misses, it misses
        continue;
      }
      if (readsFromUs(it->second.task, topic)) waiting.push_back(it->first);
      ++it;
    }
    if (waiting.empty()) return;
    // The transport is asked without the lock: peer events (joined, left) must not wait on it.
    lock.unlock();
    std::vector<uint16_t> matched;
    for (uint16_t node : waiting)
      if (transport_.peerReads(topic, node)) matched.push_back(node);
    lock.lock();
    // Each task reads one keyframe topic from this node: matched on it, a peer is no newcomer.
    for (uint16_t node : matched) newcomers_.erase(node);
    if (matched.size() == waiting.size()) return;
    changed_.wait_for(lock, std::chrono::milliseconds(5));
  }
}

}  // namespace hiveslam::distribution
