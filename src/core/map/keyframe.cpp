#include "core/map/keyframe.hpp"

#include <algorithm>
#include <cstdint>

#include "core/map/map_point.hpp"

namespace hiveslam::core {

std::pair<Eigen::Isometry3d, double> KeyFrame::placement() const {
  // Down the anchors to a live keyframe, then back up: culled keyframes can chain (an anchor
  // culled in turn), and a loop keeps this linear in the chain's length. A live keyframe is
  // its own end of the chain.
  std::vector<const KeyFrame*> chain;
  const KeyFrame* k = this;
  while (k->bad && k->anchor) {
    chain.push_back(k);
    k = k->anchor;
  }
  Eigen::Isometry3d T = k->T_cw;
  double s = k->scale_change;
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    const RelativePose& r = (*it)->from_anchor;
    const double change = s / r.scale;
    Eigen::Isometry3d T_c_k = r.T_c_k;
    T_c_k.translation() *= change;
    T = T_c_k * T;
    s = (*it)->scale_change * change;
  }
  return {T, s};
}

RelativePose KeyFrame::relative(const Eigen::Isometry3d& T) const {
  const auto [T_kw, s] = placement();
  return {T * T_kw.inverse(), s};
}

Eigen::Isometry3d KeyFrame::poseOf(const RelativePose& r) const {
  const auto [T_kw, s] = placement();
  Eigen::Isometry3d T = r.T_c_k;
  T.translation() *= s / r.scale;
  return T * T_kw;
}

std::vector<KeyFrame*> KeyFrame::bestCovisible(size_t n) const {
  std::vector<std::pair<int, KeyFrame*>> v;
  for (const auto& [kf, w] : covisibility)
    if (!kf->bad) v.emplace_back(w, kf);
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second->id < b.second->id); });
  std::vector<KeyFrame*> out;
  for (size_t i = 0; i < v.size() && i < n; ++i) out.push_back(v[i].second);
  return out;
}

namespace {

// Shared-point counts per observing keyframe: an open-addressing table reused from call to
// call on each thread, cleared slot by slot. updateConnections adds one count per observation
// of every point of a keyframe (some ten thousand) into a few dozen keyframes; as a node-based
// hash map that was half of the call.
class ObserverCounts {
 public:
  void add(KeyFrame* kf) {
    if (2 * (used_.size() + 1) > slots_.size()) grow();
    size_t i = slotOf(kf);
    if (!slots_[i].first) {
      slots_[i].first = kf;
      used_.push_back(i);
    }
    ++slots_[i].second;
  }
  template <typename F>
  void forEach(F&& f) const {
    for (size_t i : used_) f(slots_[i].first, slots_[i].second);
  }
  void clear() {
    for (size_t i : used_) slots_[i] = {nullptr, 0};
    used_.clear();
  }

 private:
  size_t slotOf(const KeyFrame* kf) const {
    const size_t mask = slots_.size() - 1;
    // Fibonacci hashing: the product's high bits mix all of the address.
    size_t i = static_cast<size_t>((reinterpret_cast<uintptr_t>(kf) * 0x9E3779B97F4A7C15ull) >> 40) & mask;
    while (slots_[i].first && slots_[i].first != kf) i = (i + 1) & mask;
    return i;
  }
  void grow() {
    std::vector<std::pair<KeyFrame*, int>> old(std::max<size_t>(256, 2 * slots_.size()), {nullptr, 0});
    old.swap(slots_);
    std::vector<size_t> was;
    was.swap(used_);
    for (size_t i : was) {
      const size_t j = slotOf(old[i].first);
      slots_[j] = old[i];
      used_.push_back(j);
    }
  }

  std::vector<std::pair<KeyFrame*, int>> slots_;
  std::vector<size_t> used_;
};

}  // namespace

void KeyFrame::updateConnections() {
  // Nothing below depends on the order the counts come in: the strongest neighbour breaks
  // ties by id, and covisibility keeps itself sorted by id.
  thread_local ObserverCounts counts;
  counts.clear();
  for (const auto& p : points) {
    if (!p || p->bad) continue;
    for (const auto& [kf, idx] : p->observations)
      if (kf != this && !kf->bad) counts.add(kf);
  }
  // Drop this keyframe from its old neighbours, then connect with weights of at least 15
  // (or the strongest one when none reaches it).
  for (auto& [kf, w] : covisibility) kf->covisibility.erase(this);
  covisibility.clear();
  KeyFrame* strongest = nullptr;
  int strongest_w = 0;
  counts.forEach([&](KeyFrame* kf, int w) {
    if (w > strongest_w || (w == strongest_w && strongest && kf->id < strongest->id)) {
      strongest = kf;
      strongest_w = w;
    }
    if (w >= 15) {
      covisibility[kf] = w;
      kf->covisibility[this] = w;
    }
  });
  if (covisibility.empty() && strongest) {
    covisibility[strongest] = strongest_w;
    strongest->covisibility[this] = strongest_w;
  }
  if (!parent && strongest && strongest->id < id) {
    parent = strongest;
    strongest->children.insert(this);
  }
}

int KeyFrame::trackedPoints(int min_observations) const {
  int n = 0;
  for (const auto& p : points)
    if (p && !p->bad && static_cast<int>(p->observations.size()) >= min_observations) ++n;
  return n;
}

}  // namespace hiveslam::core
