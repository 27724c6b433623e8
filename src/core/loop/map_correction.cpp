#include "core/loop/map_correction.hpp"

namespace hiveslam::core {

void applyCorrection(Map& map, const PoseCorrection& c, const std::vector<double>& scales) {
  // Correction of every keyframe, live or retired: old world -> new world.
  std::unordered_map<KeyFrame*, Sim3> moves;
  for (const auto& [kf, after] : c.after) moves[kf] = after.inverse() * c.before.at(kf);
  auto correctionOf = [&](KeyFrame* kf) {
    std::vector<KeyFrame*> chain;
    KeyFrame* k = kf;
    while (k && !moves.count(k)) {
      chain.push_back(k);
      k = k->parent;
      if (chain.size() > 100000) break;  // a broken tree must not hang us
    }
    const Sim3 C = k ? moves.at(k) : Sim3();
    for (KeyFrame* x : chain) moves[x] = C;
    return C;
  };
  // Retired keyframes follow their parents by themselves (KeyFrame::pose).
  std::vector<KeyFrame*> all;
  for (const auto& [id, kf] : map.keyframes) all.push_back(kf.get());
  std::unordered_map<KeyFrame*, Sim3> inherited;
  for (KeyFrame* kf : all)
    if (!c.after.count(kf)) inherited[kf] = correctionOf(kf);
  // Points first (they need the keyframes' old poses only through `moves`).
  for (const auto& [id, p] : map.points) {
    if (p->bad) continue;
    if (auto it = c.points.find(p.get()); it != c.points.end()) {
      p->position = it->second;
    } else if (!p->observations.empty()) {
      // The observation map is ordered by id: the anchor is the oldest observer.
      KeyFrame* anchor = p->observations.begin()->first;
      auto m = moves.find(anchor);
      p->position = (m != moves.end() ? m->second : correctionOf(anchor)) * p->position;
    }
  }
  for (const auto& [kf, after] : c.after)
    if (!kf->bad) kf->T_cw = after.toPose();
  for (const auto& [kf, C] : inherited) kf->T_cw = (Sim3(kf->T_cw) * C.inverse()).toPose();
  for (const auto& [id, p] : map.points)
    if (!p->bad) p->update(scales);
  ++map.epoch;
}

}  // namespace hiveslam::core
