#include "core/mapping/local_mapper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <set>

#include "common/look_alikes.hpp"
#include "core/features/hamming.hpp"
#include "core/features/rotation_histogram.hpp"
#include "core/geometry/skew.hpp"
#include "core/geometry/triangulation.hpp"
#include "core/mapping/keyframe_gap.hpp"
#include "core/mapping/keyframe_insertion.hpp"
#include "core/matching/bow_matcher.hpp"
#include "core/matching/fusion.hpp"
#include "core/matching/projection_matcher.hpp"
#include "core/optim/bundle_adjustment.hpp"

namespace hiveslam::core {

LocalMapper::LocalMapper(const SlamSettings& settings, IdGenerator& ids, std::vector<double> scales)
    : settings_(settings), ids_(ids), scales_(std::move(scales)) {}

struct LocalMapper::LocalBa {
  BaProblem problem;
  std::vector<KeyFrame*> keyframes;  // the optimized ones, in problem.poses order
  std::vector<MapPoint*> points;
  std::vector<std::pair<KeyFrame*, MapPoint*>> observations;
  BaSummary summary;
  uint64_t epoch = 0;  // the map's epoch when the copies were taken
};

namespace {

// Times one keyframe's stages; on leaving (every return of process) adds them to the sums.
class StageClock {
 public:
  explicit StageClock(MappingStageMs& sums) : sums_(sums) {}
  ~StageClock() {
    sums_.insert += here_.insert;
    sums_.cull_points += here_.cull_points;
    sums_.triangulate += here_.triangulate;
    sums_.fuse += here_.fuse;
    sums_.local_ba_setup += here_.local_ba_setup;
    sums_.local_ba += here_.local_ba;
    sums_.cull_keyframes += here_.cull_keyframes;
    const double total = here_.insert + here_.cull_points + here_.triangulate + here_.fuse + here_.local_ba_setup +
                         here_.local_ba + here_.cull_keyframes;
    sums_.total += total;
    sums_.max_total = std::max(sums_.max_total, total);
  }
  StageClock(const StageClock&) = delete;
  StageClock& operator=(const StageClock&) = delete;
  // The time since the last lap goes to `stage` (a member of this keyframe's times).
  void lap(double MappingStageMs::*stage) {
    const auto now = std::chrono::steady_clock::now();
    here_.*stage += std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
  }
  // The time since the last lap is no stage's.
  void skip() { last_ = std::chrono::steady_clock::now(); }

 private:
  MappingStageMs& sums_;
  MappingStageMs here_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

void LocalMapper::process(const std::shared_ptr<Map>& map, const std::shared_ptr<KeyFrame>& kf,
                          const std::atomic<bool>* abort_ba, const std::function<void()>& before_ba) {
  StageClock clock(stats_.ms);
  std::unique_lock lock(map->mutex);
  // Merged into another map since the job was queued: the keyframe is in the old frame and
  // the map is empty (SlamSystem drops such jobs; this closes the gap until the lock).
  if (map->merged_into.load()) return;
  map->collectGarbage();
  insert(*map, *kf);
  if (kf->bad) {  // culled while it waited, or a copy of a keyframe in the map
    lock.unlock();
    if (before_ba) before_ba();
    return;
  }
  clock.lap(&MappingStageMs::insert);
  cullRecentPoints(*map, *kf);
  clock.lap(&MappingStageMs::cull_points);
  triangulateNewPoints(*map, *kf);
  clock.lap(&MappingStageMs::triangulate);
  fuse(*map, *kf);
  clock.lap(&MappingStageMs::fuse);
  // Maps of two keyframes (just initialized) have nothing for a local BA to hold fixed.
  std::optional<LocalBa> ba;
  if (map->keyframes.size() > 2) ba = prepareLocalBa(*map, *kf);
  clock.lap(&MappingStageMs::local_ba_setup);
  if (ba || before_ba) {
    lock.unlock();
    if (before_ba) before_ba();
    clock.skip();  // the listener's time is not local mapping's
    if (ba) {
      BaOptions o;
      o.iterations = settings_.local_ba_iterations;
      o.abort = abort_ba;
      ba->summary = bundleAdjust(ba->problem, o);
      if (ba->summary.aborted) ++stats_.local_bas_cut_short;
    }
    clock.lap(&MappingStageMs::local_ba);
    lock.lock();
    if (ba) applyLocalBa(*map, *ba);
    clock.lap(&MappingStageMs::local_ba_setup);
    if (map->merged_into.load()) return;  // merged meanwhile: its keyframes live elsewhere
  }
  cullKeyframes(*map, *kf);
  clock.lap(&MappingStageMs::cull_keyframes);
  ++stats_.keyframes_processed;
}

void LocalMapper::insert(Map& map, KeyFrame& kf) {
  // A keyframe whose tracking node inserted it already comes back with its links in place.
  insertKeyframe(map, kf, scales_, database_);
}

void LocalMapper::cullRecentPoints(Map& map, const KeyFrame&) {
  for (auto it = recent_.begin(); it != recent_.end();) {
    MapPoint& p = *it->point;
    ++it->keyframes_since;
    if (p.bad) {
      it = recent_.erase(it);
    } else if (p.foundRatio() < 0.25 || (it->keyframes_since >= 2 && p.observations.size() <= 2)) {
      map.erase(p);
      ++stats_.points_culled;
      it = recent_.erase(it);
    } else if (it->keyframes_since >= 3) {
      it = recent_.erase(it);
    } else {
      ++it;
    }
  }
}

void LocalMapper::triangulateNewPoints(Map& map, KeyFrame& kf) {
  const Eigen::Isometry3d T1w = kf.T_cw;
  const Eigen::Vector3d C1 = kf.center();
  const Intrinsics& K = kf.frame.K;
  const double f = 0.5 * (K.fx + K.fy);
  for (KeyFrame* nb : kf.bestCovisible(static_cast<size_t>(settings_.triangulation_neighbours))) {
    // Enough baseline relative to the scene depth, or the points would be poorly conditioned.
    std::vector<double> depths;
    for (const auto& p : nb->points)
      if (p && !p->bad) depths.push_back((nb->T_cw * p->position).z());
    if (depths.empty()) continue;
    std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
    if ((nb->center() - C1).norm() / depths[depths.size() / 2] < 0.01) continue;

    const Eigen::Isometry3d T21 = nb->T_cw * T1w.inverse();  // kf frame -> neighbour frame
    // Look-alikes of the corners found only at the detector's lower threshold: on handheld4 of
    // the realistic suite 2995 of 3068 wrong new points from such corners had one at least as
    // close as their partner, where strong corners' wrong pairs mostly did not (92 of 122).
    const double look_alike_ratio = settings_.triangulation_look_alike_ratio;
    if (look_alike_ratio > 0) {
      for (KeyFrame* k : {&kf, nb})
        if (k->look_alikes.empty()) k->look_alikes = lookAlikeDistances(k->frame.keypoints, k->frame.descriptors, features::isWeakCorner);
    }
    for (const auto& [ii, best_j] : epipolarPairs(kf, *nb, T21)) {
      const size_t i = static_cast<size_t>(ii);
      const size_t j = static_cast<size_t>(best_j);
      if (look_alike_ratio > 0) {
        const int twin = std::min(kf.look_alikes[i], nb->look_alikes[j]);
        const int d = features::hamming(kf.frame.descriptors.ptr<uchar>(ii), nb->frame.descriptors.ptr<uchar>(best_j));
        if (twin < 255 && d >= look_alike_ratio * twin) continue;
      }
      const double s1 = scales_[static_cast<size_t>(kf.frame.keypoints[i].octave)];
      const double s2 = scales_[static_cast<size_t>(nb->frame.keypoints[j].octave)];
      TriangulationCheck check{std::sqrt(5.991) * std::max(s1, s2), settings_.triangulation_max_cos_parallax};
      const auto X1 = triangulate(K.ray(kf.frame.points[i]), K.ray(nb->frame.points[j]), T21, f, check);
      if (!X1) continue;
      const Eigen::Vector3d Xw = T1w.inverse() * *X1;
      // Scale consistency: distance ratio against pyramid scale ratio.
      const double ratio_dist = (Xw - C1).norm() / std::max((Xw - nb->center()).norm(), 1e-9);
      const double ratio_scale = s1 / s2;
      if (ratio_dist * 1.8 < ratio_scale || ratio_dist > ratio_scale * 1.8) continue;
      auto p = std::make_shared<MapPoint>(ids_.next(), Xw, kf.id);
      Map::observe(kf, static_cast<int>(i), p);
      Map::observe(*nb, best_j, p);
      p->update(scales_);
      map.add(p);
      recent_.push_back({p, 0});
      ++stats_.points_created;
    }
  }
}

std::vector<std::pair<int, int>> LocalMapper::epipolarPairs(const KeyFrame& kf, const KeyFrame& nb,
                                                            const Eigen::Isometry3d& T21) const {
  // Epipolar constraint x2^T F21 x1 = 0 on the ideal pinhole images.
  const Intrinsics& K = kf.frame.K;
  Eigen::Matrix3d Km;
  Km << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1;
  const Eigen::Matrix3d F21 = Km.inverse().transpose() * skew(T21.translation()) * T21.linear() * Km.inverse();
  // Each free keypoint's epipolar line in nb, scaled to give distances in pixels: computed once,
  // tested against every candidate.
  std::vector<Eigen::Vector3d> lines(kf.points.size(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < kf.points.size(); ++i)
    if (!kf.points[i]) {
      const Eigen::Vector3d l2 = F21 * kf.frame.points[i].homogeneous();
      lines[i] = l2 / std::max(l2.head<2>().norm(), 1e-12);
    }
  auto on_band = [&](int i, int j) {
    const double e = nb.frame.points[static_cast<size_t>(j)].homogeneous().dot(lines[static_cast<size_t>(i)]);
    const double s2 = scales_[static_cast<size_t>(nb.frame.keypoints[static_cast<size_t>(j)].octave)];
    return e * e <= 3.84 * s2 * s2;
  };
  // Features under the same vocabulary node only (far fewer comparisons, fewer points; see
  // SlamSettings::triangulation_by_vocabulary), or every free pair on the band.
  if (settings_.triangulation_by_vocabulary && !kf.bow_features.empty() && !nb.bow_features.empty())
    return matchUnmappedByBow(kf, nb, on_band, 0.7);
  // Keypoints of nb still free for a new point (no map point, not taken by an earlier pair).
  std::vector<uint8_t> free(nb.points.size(), 0);
  for (size_t j = 0; j < nb.points.size(); ++j) free[j] = !nb.points[j];
  std::vector<std::pair<int, int>> pairs;
  features::RotationHistogram hist;
  // The widest band any level allows: the grid gives the keypoints of the cells it crosses, a
  // few percent of the image, instead of all of them (a scan of every keypoint was half of local
  // mapping's time on KITTI 07: 49 of 101 ms per keyframe). The order candidates come in does not
  // matter: a tie for the nearest fails the ratio test whichever comes first.
  const double band = std::sqrt(3.84) * scales_.back();
  // Only the stretch of each line where a new point can lie. triangulateNewPoints keeps a point
  // seen at a parallax of at least acos(max_cos), so at most baseline / sin(that) from kf, and
  // whose distances to the two views are in the ratio of their levels within 1.8, so at least
  // k / (1 + k) baselines from kf (k = 1 / (1.8 * the largest level's scale)); halved and doubled
  // for the noise of the rays. The ratio test then weighs a candidate only against others that
  // could be the point too, not against look-alikes beyond the epipole or past infinity: on KITTI
  // 07 a few more pairs pass, and the trajectory moves within its run-to-run spread.
  const double baseline = T21.translation().norm();
  const double max_cos = settings_.triangulation_max_cos_parallax;
  const double k = 1.0 / (1.8 * scales_.back());
  const double dist_lo = 0.5 * k / (1 + k) * baseline;
  const double dist_hi = 2.0 * baseline / std::sqrt(std::max(1 - max_cos * max_cos, 1e-12));
  const double z_min = 1e-3 * baseline;  // nearer to nb's image plane projects far outside it
  for (size_t i = 0; i < kf.points.size(); ++i) {
    if (kf.points[i]) continue;
    const Eigen::Vector3d ray = K.ray(kf.frame.points[i]);
    const Eigen::Vector3d dir = T21.linear() * ray;  // depth d along the ray: dir d + t in nb
    double d_lo = dist_lo / ray.norm(), d_hi = dist_hi;  // depth <= distance: the ray has z 1
    const double tz = T21.translation().z();
    if (dir.z() > 0) d_lo = std::max(d_lo, (z_min - tz) / dir.z());
    else if (dir.z() < 0) d_hi = std::min(d_hi, (z_min - tz) / dir.z());
    else if (tz < z_min) continue;
    if (d_lo >= d_hi) continue;
    const Eigen::Vector2d p0 = nb.frame.K.project(dir * d_lo + T21.translation());
    const Eigen::Vector2d p1 = nb.frame.K.project(dir * d_hi + T21.translation());
    const uchar* d1 = kf.frame.descriptors.ptr<uchar>(static_cast<int>(i));
    features::NearestTwo near;
    nb.frame.grid.forEachNearSegment(p0, p1, band, [&](int j) {
      if (free[static_cast<size_t>(j)] && on_band(static_cast<int>(i), j))
        near.offer(features::hamming(d1, nb.frame.descriptors.ptr<uchar>(j)), j);
    });
    if (!near.accepted(kMatchLow, 0.7)) continue;
    free[static_cast<size_t>(near.index)] = 0;
    hist.add(kf.frame.keypoints[i].angle, nb.frame.keypoints[static_cast<size_t>(near.index)].angle,
             static_cast<int>(pairs.size()));
    pairs.emplace_back(static_cast<int>(i), near.index);
  }
  return hist.kept(pairs);
}

void LocalMapper::fuse(Map& map, KeyFrame& kf) {
  std::vector<KeyFrame*> targets;
  std::set<KeyFrame*> in;
  for (KeyFrame* n : kf.bestCovisible(static_cast<size_t>(settings_.fusion_neighbours))) {
    if (in.insert(n).second) targets.push_back(n);
    for (KeyFrame* n2 : n->bestCovisible(5))
      if (n2 != &kf && in.insert(n2).second) targets.push_back(n2);
  }
  for (KeyFrame* t : targets) fusePoints(map, *t, kf.points, scales_);
  std::vector<std::shared_ptr<MapPoint>> theirs;
  std::set<MapPoint*> seen;
  for (KeyFrame* t : targets)
    for (const auto& p : t->points)
      if (p && !p->bad && seen.insert(p.get()).second) theirs.push_back(p);
  fusePoints(map, kf, theirs, scales_);
  for (const auto& p : kf.points)
    if (p && !p->bad) p->update(scales_);
  kf.updateConnections();
}

LocalMapper::LocalBa LocalMapper::prepareLocalBa(Map& map, KeyFrame& kf) {
  LocalBa out;
  out.epoch = map.epoch;
  std::vector<KeyFrame*> local{&kf};
  for (const auto& [n, w] : kf.covisibility)
    if (!n->bad) local.push_back(n);
  std::set<KeyFrame*> local_set(local.begin(), local.end());
  std::vector<MapPoint*> pts;
  std::set<MapPoint*> pts_set;
  for (KeyFrame* k : local)
    for (const auto& p : k->points)
      if (p && !p->bad && pts_set.insert(p.get()).second) pts.push_back(p.get());
  // Keyframes outside the local window that see local points hold the border fixed.
  std::vector<KeyFrame*> fixed;
  std::set<KeyFrame*> fixed_set;
  for (MapPoint* p : pts)
    for (const auto& [k, idx] : p->observations)
      if (!local_set.count(k) && !k->bad && fixed_set.insert(k).second) fixed.push_back(k);

  BaProblem ba;
  ba.K = kf.frame.K;
  std::map<KeyFrame*, int> pose_index;
  for (KeyFrame* k : local) {
    pose_index[k] = static_cast<int>(ba.poses.size());
    ba.poses.push_back({Eigen::Quaterniond(k->T_cw.linear()), k->T_cw.translation(), k == map.origin});
  }
  for (KeyFrame* k : fixed) {
    pose_index[k] = static_cast<int>(ba.poses.size());
    ba.poses.push_back({Eigen::Quaterniond(k->T_cw.linear()), k->T_cw.translation(), true});
  }
  // Monocular gauge: one fixed pose leaves the scale free (scaling everything about that camera
  // changes no reprojection error), and a free scale wanders; two fixed poses hold it. When the
  // border does not provide two, the oldest keyframes of the window are held as well.
  int fixed_count = 0;
  for (const auto& pose : ba.poses) fixed_count += pose.fixed;
  std::vector<KeyFrame*> by_age = local;
  std::sort(by_age.begin(), by_age.end(), [](KeyFrame* a, KeyFrame* b) { return a->id < b->id; });
  for (KeyFrame* k : by_age) {
    if (fixed_count >= 2 || k == &kf) break;
    auto& pose = ba.poses[static_cast<size_t>(pose_index[k])];
    if (!pose.fixed) {
      pose.fixed = true;
      ++fixed_count;
    }
  }
  std::vector<std::pair<KeyFrame*, MapPoint*>> obs_refs;
  for (size_t i = 0; i < pts.size(); ++i) {
    ba.points.push_back({pts[i]->position, false});
    for (const auto& [k, idx] : pts[i]->observations) {
      auto it = pose_index.find(k);
      if (it == pose_index.end()) continue;
      ba.observations.push_back({it->second, static_cast<int>(i), k->frame.points[static_cast<size_t>(idx)],
                                 1.0 / scales_[static_cast<size_t>(k->frame.keypoints[static_cast<size_t>(idx)].octave)]});
      obs_refs.emplace_back(k, pts[i]);
    }
  }
  out.problem = std::move(ba);
  out.keyframes = local;
  out.points = std::move(pts);
  out.observations = std::move(obs_refs);
  return out;
}

void LocalMapper::applyLocalBa(Map& map, LocalBa& ba) {
  // A loop correction, merge or global BA moved the map while this BA ran on copies: its
  // result is in the old frame and is dropped.
  if (map.epoch != ba.epoch || map.merged_into.load()) {
    ++stats_.local_bas_discarded;
    return;
  }
  ++stats_.local_bas;
  for (size_t k = 0; k < ba.keyframes.size(); ++k) ba.keyframes[k]->T_cw = ba.problem.poses[k].T_cw();
  for (size_t i = 0; i < ba.points.size(); ++i)
    if (!ba.points[i]->bad) ba.points[i]->position = ba.problem.points[i].p_w;
  for (size_t i = 0; i < ba.observations.size(); ++i) {
    if (!ba.summary.outlier[i]) continue;
    auto [k, p] = ba.observations[i];
    auto it = p->observations.find(k);
    if (it == p->observations.end()) continue;
    k->points[static_cast<size_t>(it->second)].reset();
    p->observations.erase(it);
    if (p->observations.size() < 2 && !p->bad) map.erase(*p);
  }
  for (MapPoint* p : ba.points)
    if (!p->bad) p->update(scales_);
}

void LocalMapper::cullKeyframes(Map& map, KeyFrame& kf) {
  for (KeyFrame* k : kf.bestCovisible(1000)) {
    // Loop and merge links hold the essential graph together: their keyframes stay.
    if (k == map.origin || k == &kf || k->bad || !k->loop_edges.empty()) continue;
    int total = 0, redundant = 0;
    for (size_t i = 0; i < k->points.size(); ++i) {
      const auto& p = k->points[i];
      if (!p || p->bad) continue;
      ++total;
      if (p->observations.size() <= 3) continue;
      const int level = k->frame.keypoints[i].octave;
      int others = 0;
      for (const auto& [o, idx] : p->observations)
        if (o != k && o->frame.keypoints[static_cast<size_t>(idx)].octave <= level + 1 && ++others >= 3) break;
      if (others >= 3) ++redundant;
    }
    if (total > 0 && redundant > settings_.redundant_keyframe_ratio * total &&
        !cullingLeavesGap(*k, settings_.keyframe_culling_max_angle_deg)) {
      map.erase(*k);
      if (database_) database_->erase(k);
      ++stats_.keyframes_culled;
    }
  }
}

}  // namespace hiveslam::core
