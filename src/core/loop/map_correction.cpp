#include "core/loop/map_correction.hpp"

#include <algorithm>
#include <optional>
#include <unordered_set>
#include <vector>

#include "core/map/map_point.hpp"

namespace hiveslam::core {

namespace {

double median(std::vector<double> v) {
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Rigid poses and moved points (a global BA; a merge made at another node arrives so) still
// rescale the map around a keyframe: how far its points are from it now, against before.
// Nothing where too few of its points moved to tell.
std::optional<double> scaleChange(const KeyFrame& kf, const Sim3& before, const Sim3& after,
                                  const std::unordered_map<MapPoint*, Eigen::Vector3d>& moved) {
  std::vector<double> ratios;
  for (const auto& p : kf.points) {
    if (!p || p->bad) continue;
    auto it = moved.find(p.get());
    if (it == moved.end()) continue;
    const double was = (before * p->position).norm(), is = (after * it->second).norm();
    if (was > 1e-9 && is > 1e-9) ratios.push_back(is / was);
  }
  if (ratios.size() < 8) return std::nullopt;
  return median(std::move(ratios));
}

}  // namespace

void applyCorrection(Map& map, const PoseCorrection& c, const std::vector<double>& scales) {
  // Correction of every keyframe, live or retired: old world -> new world.
  std::unordered_map<KeyFrame*, Sim3> moves;
  std::unordered_map<KeyFrame*, Sim3> before_of;
  std::unordered_map<KeyFrame*, double> scale_of;
  for (const auto& [kf, after] : c.after) {
    // The optimization started from `before`, but it ran without the lock: local mapping may
    // have moved the keyframe since, and posed new keyframes and points on it where it is now.
    // What it carries moves from where it is now (with the optimization's scale), or each
    // local BA that landed during a global BA would be baked into its children as an error.
    const Sim3& started = c.before.at(kf);
    before_of[kf] = kf->bad ? started
                            : Sim3(Eigen::Quaterniond(kf->T_cw.linear()), started.s * kf->T_cw.translation(), started.s);
    if (c.points.empty()) continue;
    if (const auto s = scaleChange(*kf, before_of[kf], after, c.points)) scale_of[kf] = *s;
  }
  // A keyframe with too few moved points to measure (culled down to a handful, or mostly fused
  // away at a merge seam) takes the map's median change, not none: left at 1 while its pose
  // moved to a map rescaled eighty-fold, it kept the frames posed on it at the old scale.
  double typical = 1.0;
  if (!scale_of.empty()) {
    std::vector<double> all;
    for (const auto& [kf, s] : scale_of) all.push_back(s);
    typical = median(std::move(all));
  }
  for (const auto& [kf, after] : c.after) {
    const auto it = scale_of.find(kf);
    const double s = it != scale_of.end() ? it->second : typical;  // 1 for poses alone (scale in them)
    moves[kf] = after.inverse() * Sim3(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(), s) * before_of.at(kf);
  }
  auto next = [](KeyFrame* k) -> KeyFrame* {
    if (k->bad && k->anchor) return k->anchor;
    if (k->parent) return k->parent;
    // A keyframe tracking has just made has no parent until local mapping gives it one
    // (at TR, until a local map says which): it moves with the keyframe it was posed from.
    if (k->made_from) return k->made_from;
    // The root of a map merged into this one (its origin) has no parent, and once it is no
    // longer an origin it can be culled where the correction was made: then the correction
    // leaves it out, and it moves with the neighbour sharing the most points with it. (Left
    // where it was, a merge at another node left TR's frames posed from it in the old map's
    // frame, metres off.)
    const auto best = k->bestCovisible(1);
    return best.empty() ? nullptr : best.front();
  };
  auto correctionOf = [&](KeyFrame* kf) {
    std::vector<KeyFrame*> chain;
    std::unordered_set<KeyFrame*> seen;  // covisibility can lead back into the chain
    KeyFrame* k = kf;
    while (k && !moves.count(k)) {
      if (!seen.insert(k).second) {
        k = nullptr;
        break;
      }
      chain.push_back(k);
      k = next(k);
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
  std::vector<MapPoint*> unseen;
  for (const auto& [id, p] : map.points) {
    if (p->bad) continue;
    if (auto it = c.points.find(p.get()); it != c.points.end()) {
      p->position = it->second;
    } else if (!p->observations.empty()) {
      // The observation map is ordered by id: the anchor is the oldest observer.
      KeyFrame* anchor = p->observations.begin()->first;
      auto m = moves.find(anchor);
      p->position = (m != moves.end() ? m->second : correctionOf(anchor)) * p->position;
    } else {
      unseen.push_back(p.get());
    }
  }
  // A point no keyframe sees any more (its last observer culled, or relinked away by an update)
  // has nothing to move it by. Left where it was it stays in the old frame: blackout's 3-node
  // runs ended with some 40-70 such points, many up to 2 map units behind the frames that had
  // tracked them, and one 0.03 map units (some 9 cm) in front of a frame pulled that frame's
  // end-of-run refinement 13 mm off. It leaves the map (journalled: the other nodes drop it too).
  for (MapPoint* p : unseen) map.erase(*p);
  for (const auto& [kf, after] : c.after)
    if (!kf->bad) {
      kf->T_cw = after.toPose();
      kf->scale_change *= moves.at(kf).s;
    }
  for (const auto& [kf, C] : inherited) {
    kf->T_cw = (Sim3(kf->T_cw) * C.inverse()).toPose();
    kf->scale_change *= C.s;
  }
  for (const auto& [id, p] : map.points)
    if (!p->bad) p->update(scales);
  ++map.epoch;
}

}  // namespace hiveslam::core
