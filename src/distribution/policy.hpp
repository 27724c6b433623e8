#pragma once
// The distribution policy D(N, G) of the paper, for every task: given this node's task and the
// tasks present among its peers (G), what it runs itself, where its keyframes go and which
// topics it listens to. Re-evaluated whenever a peer appears or disappears.
#include <vector>

#include "communication/message.hpp"

namespace hiveslam::distribution {

using communication::Task;
using communication::Topic;

struct Plan {
  bool mapping = false;        // runs local mapping
  bool loop_closing = false;   // runs loop closing
  bool keyframes_to_lm = false;  // publishes its new keyframes for a remote LM (TR)
  bool keyframes_to_lc = false;  // publishes mapped keyframes for a remote LC (LM, or TR acting as LM)
  bool local_maps = false;       // publishes local maps (it is the LM of the network)
  std::vector<Topic> subscriptions;
  uint8_t hosted = 0;  // taskBit()s, for announcements
};

// present: taskBit()s of the peers' tasks (not this node's).
Plan decide(Task own, uint8_t present);

}  // namespace hiveslam::distribution
