#include "distribution/policy.hpp"

namespace hiveslam::distribution {

using communication::taskBit;

Plan decide(Task own, uint8_t present) {
  const bool lm = present & taskBit(Task::Mapping);
  const bool lc = present & taskBit(Task::LoopClosing);
  Plan p;
  switch (own) {
    case Task::Tracking:
      // N_lm in G: offload LM (and LC, which LM hosts or offloads further). Otherwise this node
      // is the LM of the network, and offloads only LC when N_lc is in G.
      p.mapping = !lm;
      p.loop_closing = !lm && !lc;
      p.keyframes_to_lm = lm;
      if (lm) p.subscriptions = {Topic::LmMap};
      if (!lm && lc) {
        p.keyframes_to_lc = true;
        p.local_maps = true;
        p.subscriptions = {Topic::LcMap};
      }
      break;
    case Task::Mapping:
      // The gateway: keyframes from TR in, local maps out, LC offloaded when there is one. It
      // also reads the map topic it publishes: TR, when it mapped before this node came, hands
      // the maps so far over on it (the node's own packets are not delivered to it).
      p.mapping = true;
      p.loop_closing = !lc;
      p.keyframes_to_lc = lc;
      p.local_maps = true;
      p.subscriptions = {Topic::TrKeyframes, Topic::LmMap};
      if (lc) p.subscriptions.push_back(Topic::LcMap);
      break;
    case Task::LoopClosing:
      // Keyframes and local maps come from whoever maps (LM, or TR without an LM).
      p.loop_closing = true;
      p.subscriptions = {Topic::LmKeyframes, Topic::LmMap};
      break;
  }
  p.hosted = taskBit(own);
  if (p.mapping) p.hosted |= taskBit(Task::Mapping);
  if (p.loop_closing) p.hosted |= taskBit(Task::LoopClosing);
  return p;
}

}  // namespace hiveslam::distribution
