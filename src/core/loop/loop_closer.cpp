#include "core/loop/loop_closer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/geometry/sim3_solver.hpp"
#include "core/loop/map_correction.hpp"
#include "core/matching/bow_matcher.hpp"
#include "core/matching/fusion.hpp"
#include "core/matching/projection_matcher.hpp"
#include "core/optim/bundle_adjustment.hpp"
#include "core/optim/map_ba_problem.hpp"
#include "core/optim/pose_graph.hpp"
#include "core/optim/scale_gauge.hpp"
#include "core/optim/sim3_refine.hpp"

namespace hiveslam::core {

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<Id> groupOf(const KeyFrame& kf) {
  std::vector<Id> g{kf.id};
  for (const auto& [n, w] : kf.covisibility) g.push_back(n->id);
  std::sort(g.begin(), g.end());
  return g;
}

bool intersects(const std::vector<Id>& a, const std::vector<Id>& b) {
  auto i = a.begin();
  auto j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (*i == *j) return true;
    if (*i < *j) ++i;
    else ++j;
  }
  return false;
}

// The place keyframe and its best neighbours, and every map point they see.
void placeGroup(KeyFrame& place, std::vector<KeyFrame*>& group, std::vector<std::shared_ptr<MapPoint>>& points) {
  group = {&place};
  for (KeyFrame* n : place.bestCovisible(10)) group.push_back(n);
  std::set<MapPoint*> seen;
  for (KeyFrame* k : group)
    for (const auto& p : k->points)
      if (p && !p->bad && seen.insert(p.get()).second) points.push_back(p);
}

}  // namespace

struct LoopCloser::Verified {
  KeyFrame* place = nullptr;
  Sim3 S12;        // place camera -> keyframe camera
  Sim3 S_cw;       // world (of the place's map) -> keyframe camera: the keyframe's corrected pose
  int matches = 0;
  double scale_agreement = 0;  // share of the inliers whose depth ratio agrees with S12.s
  std::vector<KeyFrame*> place_group;
  std::vector<std::shared_ptr<MapPoint>> place_points;
};

struct LoopCloser::LoopCorrection {
  std::unordered_map<KeyFrame*, Sim3> corrected, uncorrected;  // the keyframes around the loop
  std::map<KeyFrame*, std::set<KeyFrame*, ById>, ById> new_links;  // covisibility the loop created
  KeyFrame* kf = nullptr;
  KeyFrame* place = nullptr;
};

LoopCloser::LoopCloser(const SlamSettings& settings, KeyframeDatabase& database, std::vector<double> scales)
    : settings_(settings), database_(database), scales_(std::move(scales)) {}

std::vector<KeyFrame*> LoopCloser::consistentPlaces(const std::vector<Place>& places, Groups& groups) const {
  Groups next;
  std::vector<KeyFrame*> out;
  for (const Place& p : places) {
    int count = 0;
    for (const auto& [g, n] : groups)
      if (intersects(p.group, g)) count = std::max(count, n + 1);
    next.emplace_back(p.group, count);
    if (count + 1 >= settings_.loop_consistency) out.push_back(p.keyframe);
  }
  groups = std::move(next);
  return out;
}

int LoopCloser::projectedMatches(const KeyFrame& kf, const Sim3& S_cw, double scale,
                                 const std::vector<std::shared_ptr<MapPoint>>& points, std::vector<bool>* taken) const {
  std::vector<bool> local(kf.points.size(), false);
  std::vector<bool>& used = taken ? *taken : local;
  int n = 0;
  for (const auto& p : points) {
    const Eigen::Vector3d pc = S_cw * p->position;
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = kf.frame.K.project(pc);
    if (!kf.frame.inImage(uv)) continue;
    // The predicted level uses the distance in the place map's scale.
    const int level = p->predictLevel(pc.norm() / scale, scales_);
    const int i = bestNear(kf.frame, uv, 3.0 * scales_[static_cast<size_t>(level)], level - 1, level + 1,
                           p->descriptor.ptr<uchar>(), kMatchLow);
    if (i < 0 || used[static_cast<size_t>(i)]) continue;
    used[static_cast<size_t>(i)] = true;
    ++n;
  }
  return n;
}

bool LoopCloser::verify(KeyFrame& kf, KeyFrame& place, Verified& out) const {
  const auto pairs = matchKeyframesByBow(kf, place);
  if (static_cast<int>(pairs.size()) < settings_.loop_min_bow_matches) return false;
  auto matchOf = [&](int i, int j) {
    Sim3Match m;
    m.p1 = kf.T_cw * kf.points[static_cast<size_t>(i)]->position;
    m.p2 = place.T_cw * place.points[static_cast<size_t>(j)]->position;
    m.uv1 = kf.frame.points[static_cast<size_t>(i)];
    m.uv2 = place.frame.points[static_cast<size_t>(j)];
    const double s1 = scales_[static_cast<size_t>(kf.frame.keypoints[static_cast<size_t>(i)].octave)];
    const double s2 = scales_[static_cast<size_t>(place.frame.keypoints[static_cast<size_t>(j)].octave)];
    m.sigma2_1 = s1 * s1;
    m.sigma2_2 = s2 * s2;
    return m;
  };
  std::vector<Sim3Match> matches;
  std::vector<int> kf_index;
  for (const auto& [i, j] : pairs) {
    matches.push_back(matchOf(i, j));
    kf_index.push_back(i);
  }
  Sim3RansacOptions ro;
  ro.min_inliers = settings_.loop_min_sim3_inliers;
  ro.seed = settings_.seed + kf.id;
  Sim3Result r = solveSim3Ransac(kf.frame.K, place.frame.K, matches, ro);
  if (!r.found) return false;
  // Guided matching: the place's other points projected into the keyframe with the Sim3.
  std::vector<bool> used_kf(kf.points.size(), false), used_place(place.points.size(), false);
  for (const auto& [i, j] : pairs) {
    used_kf[static_cast<size_t>(i)] = true;
    used_place[static_cast<size_t>(j)] = true;
  }
  std::vector<bool> inlier = r.inlier;
  for (size_t j = 0; j < place.points.size(); ++j) {
    const auto& p = place.points[j];
    if (!p || p->bad || used_place[j]) continue;
    const Eigen::Vector3d p1 = r.S12 * (place.T_cw * p->position);
    if (p1.z() <= 0) continue;
    const Eigen::Vector2d uv = kf.frame.K.project(p1);
    if (!kf.frame.inImage(uv)) continue;
    const int level = place.frame.keypoints[j].octave;
    const int i = bestNear(kf.frame, uv, 7.5 * scales_[static_cast<size_t>(level)], level - 1, level + 1,
                           p->descriptor.ptr<uchar>(), kMatchHigh);
    if (i < 0 || used_kf[static_cast<size_t>(i)] || !kf.points[static_cast<size_t>(i)] ||
        kf.points[static_cast<size_t>(i)]->bad)
      continue;
    used_kf[static_cast<size_t>(i)] = true;
    matches.push_back(matchOf(i, static_cast<int>(j)));
    kf_index.push_back(i);
    inlier.push_back(true);
  }
  // Rotation and translation from the images; the scale from the points. Where the keyframe
  // stands close to where the place was seen from (a revisit welded late, as at LC while a
  // correction is still on its way to tracking), the reprojections leave the scale free and the
  // refinement wandered to 0.94-1.13 while the points said 0.998-1.011.
  Sim3 S = r.S12;
  refineSim3(kf.frame.K, place.frame.K, matches, S, inlier);
  S.s = pointScale(matches, S, inlier);
  const int inliers = refineSim3(kf.frame.K, place.frame.K, matches, S, inlier, true);
  // A true place explains most of the guided matches too; a look-alike (a repeated texture seen
  // from elsewhere) gives a Sim3 that only a minority of them agree with.
  if (inliers < settings_.loop_min_sim3_inliers ||
      inliers < settings_.loop_min_inlier_ratio * static_cast<double>(matches.size()))
    return false;
  // The whole place (the keyframe and its neighbours) must show up where the Sim3 puts it.
  out = Verified{};
  out.place = &place;
  out.S12 = S;
  out.S_cw = S * Sim3(place.T_cw);
  out.scale_agreement = pointScaleAgreement(matches, S, inlier, 0.2);
  placeGroup(place, out.place_group, out.place_points);
  std::vector<bool> seen(kf.points.size(), false);
  int total = 0;
  for (size_t k = 0; k < matches.size(); ++k)
    if (inlier[k]) {
      seen[static_cast<size_t>(kf_index[k])] = true;
      ++total;
    }
  total += projectedMatches(kf, out.S_cw, S.s, out.place_points, &seen);
  out.matches = total;
  if (total < settings_.loop_min_total_matches) return false;
  // The keyframe's best neighbours must see the place where the same Sim3 puts it.
  int agreeing = 0, asked = 0;
  const Eigen::Isometry3d T_wc = kf.T_cw.inverse();
  for (KeyFrame* n : kf.bestCovisible(3)) {
    ++asked;
    const Sim3 S_nw = Sim3(n->T_cw * T_wc) * out.S_cw;
    const int m = projectedMatches(*n, S_nw, S.s, out.place_points, nullptr);
    if (m >= settings_.loop_min_total_matches / 2) ++agreeing;
  }
  return agreeing >= std::min(asked, 2);
}

void LoopCloser::process(const std::shared_ptr<Map>& map_handle, const std::shared_ptr<KeyFrame>& kf_handle) {
  if (!settings_.loop_closing) return;
  const auto t0 = std::chrono::steady_clock::now();
  Map& map = *map_handle->resolve();
  KeyFrame& kf = *kf_handle;
  std::vector<Place> loop_places;
  std::map<Map*, std::vector<KeyFrame*>> other_places;
  {
    std::lock_guard lock(map.mutex);
    if (kf.bad || !map.keyframes.count(kf.id)) return;
    ++stats_.keyframes_checked;
    ++keyframes_since_loop_;
    // A place must look at least as similar as the keyframe's own neighbours do.
    std::unordered_set<Id> exclude{kf.id};
    double min_score = 1.0;
    for (const auto& [n, w] : kf.covisibility) {
      exclude.insert(n->id);
      min_score = std::min(min_score, place::scoreL1(kf.bow, n->bow));
    }
    if (kf.covisibility.empty()) min_score = 0;
    const auto candidates = database_.query(kf.bow, exclude);
    std::map<KeyFrame*, double> same_map;
    for (const auto& c : candidates) {
      // Local mapping runs ahead of this module: keyframes newer than this one are never the
      // place it returns to.
      if (c.score < min_score || c.keyframe->id > kf.id) continue;
      if (c.map == &map) {
        if (!c.keyframe->bad) same_map[c.keyframe] = c.score;
      } else {
        other_places[c.map].push_back(c.keyframe);
      }
    }
    // Places of this map, pooled by covisibility: a group's score is the sum of its members'.
    if (static_cast<int>(map.keyframes.size()) >= settings_.loop_min_keyframes && keyframes_since_loop_ > 5) {
      double best_acc = 0;
      std::vector<std::pair<KeyFrame*, double>> reps;
      for (const auto& [c, score] : same_map) {
        double acc = score, best = score;
        KeyFrame* rep = c;
        for (KeyFrame* n : c->bestCovisible(10))
          if (auto it = same_map.find(n); it != same_map.end()) {
            acc += it->second;
            if (it->second > best) {
              best = it->second;
              rep = n;
            }
          }
        reps.emplace_back(rep, acc);
        best_acc = std::max(best_acc, acc);
      }
      std::set<KeyFrame*, ById> chosen;
      for (const auto& [rep, acc] : reps)
        if (acc >= 0.75 * best_acc && chosen.insert(rep).second) loop_places.push_back({rep, groupOf(*rep)});
    }
  }
  stats_.query_ms_total += msSince(t0);
  const std::vector<KeyFrame*> loops = consistentPlaces(loop_places, loop_groups_);

  // Places of other maps first: welding a map back in matters more than one more loop.
  std::vector<Place> merge_places;
  for (auto& [other, kfs] : other_places) {
    if (other->merged_into.load()) continue;
    std::lock_guard lock(other->mutex);
    for (KeyFrame* c : kfs)
      if (!c->bad) merge_places.push_back({c, groupOf(*c)});
  }
  std::vector<KeyFrame*> merges = consistentPlaces(merge_places, merge_groups_);
  if (active_ && active_->load() != &map) merges.clear();
  for (KeyFrame* place : merges) {
    Map* other = nullptr;
    for (auto& [m, kfs] : other_places)
      if (std::find(kfs.begin(), kfs.end(), place) != kfs.end()) other = m;
    if (!other || other == &map || other->merged_into.load()) continue;
    bool merged = false;
    {
      std::scoped_lock lock(map.mutex, other->mutex);
      Verified v;
      if (!kf.bad && !place->bad && verify(kf, *place, v)) {
        mergeMaps(map, kf, *other, v);
        merged = true;
      } else {
        ++stats_.rejected_geometry;
      }
    }
    if (merged) {
      merge_groups_.clear();
      loop_groups_.clear();
      keyframes_since_loop_ = 0;
      stats_.events.back().correct_ms = msSince(t0);
      report(GlobalUpdate::Kind::Merge, map.id, other->id);
      globalBundleAdjustment(map, 0, true);
      return;
    }
  }

  for (KeyFrame* place : loops) {
    LoopCorrection c;
    Verified v;
    {
      std::lock_guard lock(map.mutex);
      const double max_scale = settings_.loop_max_scale_change;
      if (kf.bad || place->bad || !verify(kf, *place, v) || v.S12.s > max_scale || v.S12.s < 1.0 / max_scale) {
        ++stats_.rejected_geometry;
        continue;
      }
      c = correctLoop(map, kf, v);
    }
    LoopEvent event;
    event.kind = LoopEvent::Kind::Loop;
    event.timestamp = kf.frame.timestamp;
    event.place_timestamp = place->frame.timestamp;
    event.keyframe = kf.id;
    event.matched = place->id;
    event.map = map.id;
    event.matches = v.matches;
    event.scale = v.S12.s;
    event.scale_agreement = v.scale_agreement;
    event.correct_ms = msSince(t0);
    optimizeEssentialGraph(map, c, event);
    stats_.events.push_back(event);
    ++stats_.loops;
    report(GlobalUpdate::Kind::Loop, map.id);
    loop_groups_.clear();
    keyframes_since_loop_ = 0;
    globalBundleAdjustment(map, 0, true);
    return;
  }
  // No loop: the map still gets a global BA each time it has grown by global_ba_every_keyframes.
  // Local BA holds its border fixed where earlier windows left it, so their errors (the young
  // map's scale above all) are never revisited; a full BA lets every observation weigh in.
  if (settings_.global_ba_every_keyframes > 0) {
    size_t size = 0;
    {
      std::lock_guard lock(map.mutex);
      size = map.keyframes.size();
    }
    if (size >= keyframes_at_global_ba_[map.id] + static_cast<size_t>(settings_.global_ba_every_keyframes))
      globalBundleAdjustment(map);
  }
}

LoopCloser::LoopCorrection LoopCloser::correctLoop(Map& map, KeyFrame& kf, const Verified& v) {
  LoopCorrection c;
  c.kf = &kf;
  c.place = v.place;
  std::vector<KeyFrame*> connected{&kf};
  for (const auto& [n, w] : kf.covisibility)
    if (!n->bad) connected.push_back(n);
  const Eigen::Isometry3d T_wc = kf.T_cw.inverse();
  for (KeyFrame* k : connected) {
    c.uncorrected[k] = Sim3(k->T_cw);
    c.corrected[k] = Sim3(k->T_cw * T_wc) * v.S_cw;
  }
  // Points move with the first connected keyframe that sees them.
  std::set<MapPoint*, ById> moved;
  for (KeyFrame* k : connected)
    for (const auto& p : k->points)
      if (p && !p->bad && moved.insert(p.get()).second)
        p->position = c.corrected[k].inverse() * (c.uncorrected[k] * p->position);
  for (KeyFrame* k : connected) {
    k->T_cw = c.corrected[k].toPose();
    // Its points were scaled by the loop's Sim3 around it: what is held relative to it (culled
    // keyframes, keyframes and tracked frames posed from it) must be too. The essential graph
    // starts from these corrected poses and adds only its own change.
    k->scale_change /= c.corrected[k].s;
  }
  for (MapPoint* p : moved) p->update(scales_);
  // Fuse the place's points into the corrected side, then see which new links that made.
  std::map<KeyFrame*, std::set<KeyFrame*, ById>, ById> before;
  for (KeyFrame* k : connected)
    for (const auto& [n, w] : k->covisibility) before[k].insert(n);
  for (KeyFrame* k : connected) fusePoints(map, *k, v.place_points, scales_);
  for (KeyFrame* k : connected)
    for (const auto& p : k->points)
      if (p && !p->bad) p->update(scales_);
  for (KeyFrame* k : connected) k->updateConnections();
  const std::set<KeyFrame*> connected_set(connected.begin(), connected.end());
  for (KeyFrame* k : connected)
    for (const auto& [n, w] : k->covisibility)
      if (!before[k].count(n) && !connected_set.count(n)) c.new_links[k].insert(n);
  kf.loop_edges.insert(v.place);
  v.place->loop_edges.insert(&kf);
  ++map.epoch;
  return c;
}

void LoopCloser::optimizeEssentialGraph(Map& map, const LoopCorrection& c, LoopEvent& event) {
  const auto t0 = std::chrono::steady_clock::now();
  PoseGraph graph;
  std::vector<KeyFrame*> kfs;
  std::unordered_map<KeyFrame*, int> index;
  {
    std::lock_guard lock(map.mutex);
    for (const auto& [id, k] : map.keyframes)
      if (!k->bad) kfs.push_back(k.get());
    std::sort(kfs.begin(), kfs.end(), [](KeyFrame* a, KeyFrame* b) { return a->id < b->id; });
    for (KeyFrame* k : kfs) {
      index[k] = static_cast<int>(graph.poses.size());
      auto it = c.corrected.find(k);
      graph.poses.push_back(it != c.corrected.end() ? it->second : Sim3(k->T_cw));
      graph.fixed.push_back(k == map.origin);
    }
    // Relative poses as they were before the correction, except across the loop itself.
    auto measured = [&](KeyFrame* k) {
      auto it = c.uncorrected.find(k);
      return it != c.uncorrected.end() ? it->second : Sim3(k->T_cw);
    };
    auto addEdge = [&](KeyFrame* a, KeyFrame* b, bool across_loop) {
      auto ia = index.find(a), ib = index.find(b);
      if (ia == index.end() || ib == index.end()) return;
      const Sim3 Sa = across_loop ? graph.poses[static_cast<size_t>(ia->second)] : measured(a);
      const Sim3 Sb = across_loop ? graph.poses[static_cast<size_t>(ib->second)] : measured(b);
      graph.edges.push_back({ia->second, ib->second, Sa * Sb.inverse(), 1.0});
    };
    for (const auto& [k, links] : c.new_links)
      for (KeyFrame* n : links) addEdge(k, n, true);
    for (KeyFrame* k : kfs) {
      if (k->parent) addEdge(k, k->parent, false);
      for (KeyFrame* l : k->loop_edges)
        if (l->id < k->id) addEdge(k, l, (k == c.kf && l == c.place) || (k == c.place && l == c.kf));
      for (const auto& [n, w] : k->covisibility) {
        if (n->id >= k->id || w < settings_.essential_graph_min_weight || n == k->parent || k == n->parent) continue;
        auto nl = c.new_links.find(k);
        if (nl != c.new_links.end() && nl->second.count(n)) continue;
        addEdge(k, n, false);
      }
    }
  }
  PoseCorrection correction;
  for (size_t i = 0; i < kfs.size(); ++i) correction.before[kfs[i]] = graph.poses[i];
  optimizePoseGraph(graph, settings_.essential_graph_iterations);
  for (size_t i = 0; i < kfs.size(); ++i) correction.after[kfs[i]] = graph.poses[i];
  {
    std::lock_guard lock(map.mutex);
    applyCorrection(map, correction, scales_);
  }
  event.essential_graph_ms = msSince(t0);
}

bool LoopCloser::globalBundleAdjustment(Map& map, int iterations, bool corrected, const Remeasurements* remeasured) {
  const auto t0 = std::chrono::steady_clock::now();
  MapBaProblem whole;
  uint64_t epoch = 0;
  {
    std::lock_guard lock(map.mutex);
    epoch = map.epoch;
    keyframes_at_global_ba_[map.id] = map.keyframes.size();
    whole = buildMapBaProblem(map, scales_);
  }
  const std::vector<KeyFrame*>& kfs = whole.keyframes;
  const std::vector<MapPoint*>& pts = whole.points;
  BaProblem& ba = whole.problem;
  if (kfs.size() < 3) return true;
  PoseCorrection correction;
  for (size_t i = 0; i < kfs.size(); ++i) correction.before[kfs[i]] = Sim3(ba.poses[i].q_cw, ba.poses[i].t_cw, 1.0);
  const std::vector<Eigen::Vector3d> centres = cameraCentres(ba);
  // Observations the map's own noise calls outliers sit this BA out; they stay in the map.
  bool loose_first = false;
  if (remeasured) {
    stats_.remeasured = applyRemeasurements(whole, *remeasured);
    loose_first = stats_.remeasured.applied > 0;
  }
  const Outliers outliers = settings_.global_ba_outliers_from_start && !corrected ? Outliers::FromStart : Outliers::SecondRound;
  const double sigma = solveGlobal(ba, iterations > 0 ? iterations : settings_.global_ba_iterations,
                                   settings_.global_ba_noise_factor, outliers, loose_first);
  if (settings_.global_ba_noise_factor > 0) stats_.global_ba_sigma = sigma;
  const double restored = restoreScale(ba, centres);  // only the origin is fixed: the scale was free (scale_gauge.hpp)
  stats_.global_ba_scale_drift = std::max({stats_.global_ba_scale_drift, restored, 1.0 / restored});
  for (size_t i = 0; i < kfs.size(); ++i) correction.after[kfs[i]] = Sim3(ba.poses[i].q_cw, ba.poses[i].t_cw, 1.0);
  for (size_t i = 0; i < pts.size(); ++i) correction.points[pts[i]] = ba.points[i].p_w;
  {
    std::lock_guard lock(map.mutex);
    if (map.epoch != epoch || map.merged_into.load()) {
      ++stats_.global_bas_discarded;
      return false;
    }
    applyCorrection(map, correction, scales_);
  }
  ++stats_.global_bas;
  report(GlobalUpdate::Kind::GlobalBa, map.id);
  const double ms = msSince(t0);
  stats_.global_ba_ms_total += ms;
  stats_.global_ba_ms.emplace_back(static_cast<int>(kfs.size()), ms);
  return true;
}

void LoopCloser::mergeMaps(Map& map, KeyFrame& kf, Map& other, const Verified& v) {
  // other's world -> this map's world.
  const Sim3 S_ab = Sim3(kf.T_cw).inverse() * v.S_cw;
  const Sim3 S_ba = S_ab.inverse();
  for (const auto& [id, k] : other.keyframes) {
    k->T_cw = (Sim3(k->T_cw) * S_ba).toPose();
    k->scale_change *= S_ab.s;
  }
  for (const auto& [id, p] : other.points) p->position = S_ab * p->position;
  map.absorb(other);
  database_.moveMap(&other, &map);
  for (const auto& p : v.place_points)
    if (!p->bad) p->update(scales_);
  // Weld the seam: each side's points fused into the other side's keyframes.
  std::vector<KeyFrame*> connected{&kf};
  for (const auto& [n, w] : kf.covisibility)
    if (!n->bad) connected.push_back(n);
  std::vector<std::shared_ptr<MapPoint>> ours;
  std::set<MapPoint*> seen;
  for (KeyFrame* k : connected)
    for (const auto& p : k->points)
      if (p && !p->bad && seen.insert(p.get()).second) ours.push_back(p);
  for (KeyFrame* k : connected) fusePoints(map, *k, v.place_points, scales_);
  for (KeyFrame* k : v.place_group)
    if (!k->bad) fusePoints(map, *k, ours, scales_);
  std::vector<KeyFrame*> seam = connected;
  seam.insert(seam.end(), v.place_group.begin(), v.place_group.end());
  for (KeyFrame* k : seam)
    for (const auto& p : k->points)
      if (p && !p->bad) p->update(scales_);
  for (KeyFrame* k : seam)
    if (!k->bad) k->updateConnections();
  kf.loop_edges.insert(v.place);
  v.place->loop_edges.insert(&kf);
  ++map.epoch;
  LoopEvent event;
  event.kind = LoopEvent::Kind::Merge;
  event.timestamp = kf.frame.timestamp;
  event.place_timestamp = v.place->frame.timestamp;
  event.keyframe = kf.id;
  event.matched = v.place->id;
  event.map = map.id;
  event.merged_map = other.id;
  event.matches = v.matches;
  event.scale = S_ab.s;
  event.scale_agreement = v.scale_agreement;
  stats_.events.push_back(event);
  ++stats_.merges;
}

}  // namespace hiveslam::core
