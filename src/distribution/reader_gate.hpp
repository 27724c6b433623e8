#pragma once
// The Reader Gate: holds what this node publishes on a keyframe topic until the peers that
// joined lately read that topic from it. DDS hands a packet only to the readers matched when
// it is written (volatile durability), and a peer is announced a little before its readers
// match this node's writers. What goes out in between never reaches it. Most packets are
// repaired by later ones; a new map's first keyframe is not: it carries the map (its first
// keyframe as a companion), and the later ones only name it. One lost that way left a
// loop-closing node holding keyframes of a map it never got (CI: a mapping node
// that had just returned forwarded TR's new map to LC before LC's reader had matched).
//
// Which tasks read which topic from this node: keyframes from TR go to mapping nodes, mapped
// keyframes to loop-closing nodes (the policy subscribes every such node, so each of them
// matches in the end; `patience` bounds the wait all the same).
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>

#include "communication/transport.hpp"

namespace hiveslam::distribution {

class ReaderGate {
 public:
  using Clock = std::chrono::steady_clock;
  ReaderGate(communication::Transport& transport, std::chrono::milliseconds patience)
      : transport_(transport), patience_(patience) {}
  // A peer joined or returned: await() waits for its readers, up to `patience` from now.
  void joined(uint16_t node, communication::Task task);
  void left(uint16_t node);
  // Returns once every peer that joined less than `patience` ago and reads `topic` from this
  // node by its task reads it (its reader has matched), or after stop().
  void await(communication::Topic topic);
  // From now on await() returns at once (the node is leaving).
  void stop();

 private:
  struct Newcomer {
    communication::Task task;
    Clock::time_point until;
  };
  communication::Transport& transport_;
  const std::chrono::milliseconds patience_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<uint16_t, Newcomer> newcomers_;  // until their readers have matched
  bool stopped_ = false;
};

}  // namespace hiveslam::distribution
