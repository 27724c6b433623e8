#include "core/tracking/tracker.hpp"

#include <algorithm>
#include <limits>
#include <set>
#include <unordered_set>

#include "core/features/hamming.hpp"
#include "core/geometry/pnp_ransac.hpp"
#include "core/geometry/two_view.hpp"
#include "core/map/follow_merges.hpp"
#include "core/mapping/keyframe_gap.hpp"
#include "core/matching/bow_matcher.hpp"
#include "core/matching/initial_matcher.hpp"
#include "core/optim/bundle_adjustment.hpp"
#include "core/optim/pose_optimizer.hpp"

namespace hiveslam::core {

Tracker::Tracker(const SlamSettings& settings, IdGenerator& ids, std::vector<double> scales)
    : settings_(settings), ids_(ids), scales_(std::move(scales)) {}

TrackingOutput Tracker::track(Frame frame, bool mapping_idle) {
  TrackingOutput out;
  Tracked current;
  current.points.assign(frame.size(), nullptr);
  current.outlier.assign(frame.size(), false);
  current.frame = std::move(frame);

  std::unique_lock<std::mutex> lock;
  bool ok = false;
  if (state_ == TrackingState::NotInitialized) {
    // Before a new map: the frame may show a place a map already holds (the one just lost
    // included), and tracking goes on there.
    // (No map yet, as at the start of a run: no bag of words to compute.)
    ok = !localization_only_ && map_finder_ && database_ && database_->size() > 0 &&
         relocalizeInKnownMap(current, queryPlaces(current.frame), nullptr, lock);
    if (!ok) {
      if (initialize(current, out)) {
        state_ = TrackingState::Ok;
        out.tracked = true;
        last_relocalization_frame_.reset();  // a new map: nothing relocalized in it
      }
      out.state = state_;
      return out;
    }
    out.map_switched = true;
  } else {
    lock = followMerges();
    // Loop closing, a merge or a global BA moved the map: the last frame's pose is re-derived
    // from its reference keyframe, as the motion model predicts from it.
    if (map_->epoch != epoch_seen_) {
      if (last_ && last_reference_) last_->T_cw = last_reference_->poseOf(last_T_c_ref_);
      epoch_seen_ = map_->epoch;
    }
  }
  if (out.map_switched) {
    last_relocalization_frame_ = current.frame.index;
  } else if (state_ == TrackingState::Ok) {
    ok = (have_velocity_ && trackWithMotionModel(current)) || trackReferenceKeyframe(current);
    if (ok) ok = trackLocalMap(current, relocalizedWithin(current.frame, 20) ? settings_.min_inliers_after_relocalization
                                                                              : settings_.min_inliers_tracking);
    if (!ok) {
      ++failures_;
      lost_frames_ = 0;
    }
  } else {
    const PlaceQuery q = queryPlaces(current.frame);
    ok = relocalize(current, relocalizationCandidates(q, *map_, 10), q.features);
    if (!ok && !localization_only_ && map_finder_) {
      const Map* lost_in = map_.get();
      lock.unlock();
      ok = relocalizeInKnownMap(current, q, lost_in, lock);
      out.map_switched = ok;
      if (!ok) lock = std::unique_lock(map_->mutex);
    }
    if (ok) {
      last_relocalization_frame_ = current.frame.index;
    }
  }

  if (!ok) {
    state_ = TrackingState::Lost;
    have_velocity_ = false;
    ++lost_frames_;
    // A young map that loses track is abandoned at once; an established one gets a few frames
    // to relocalize before a new map is started. So is a relocalization that held only a few
    // frames: starting a new map goes on relocalizing in every map, and on phone_room_droidcam
    // the 20-frame wait after a one-frame relocalization in blur cost 19 frames.
    const bool brief_relocalization = map_finder_ && relocalizedWithin(current.frame, 10);
    if (!localization_only_ &&
        (keyframes_made_ <= 5 || brief_relocalization || lost_frames_ > settings_.lost_frames_before_new_map)) {
      lock.unlock();
      state_ = TrackingState::NotInitialized;
      init_reference_.reset();
      last_.reset();
    }
    out.state = state_;
    return out;
  }

  state_ = TrackingState::Ok;
  lost_frames_ = 0;
  if (last_) {
    velocity_ = current.T_cw * last_->T_cw.inverse();
    have_velocity_ = true;
  }
  out.tracked = true;
  out.T_cw = current.T_cw;
  out.inliers = inliers_;
  if (!mapping_idle && wait_for_mapping_ && keyframeWanted(current, trackedShare())) {
    lock.unlock();
    wait_for_mapping_();
    lock.lock();
    mapping_idle = true;
    // Local BA may have moved the points this frame was tracked against: the keyframe must be
    // posed in the map as it is now, or its new points are triangulated in a stale frame.
    optimize(current);
    out.T_cw = current.T_cw;
  }
  const KeyframeDecision decision = localization_only_ ? KeyframeDecision::None : keyframeDecision(current, mapping_idle);
  if (decision == KeyframeDecision::Make) {
    out.new_keyframe = makeKeyframe(current);
    ++keyframes_made_;
    if (!mapping_idle) ++keyframes_made_busy_;
    reference_ = out.new_keyframe;
    last_keyframe_frame_ = current.frame.index;
    last_keyframe_R_cw_ = current.T_cw.linear();
  } else if (decision == KeyframeDecision::Deferred) {
    ++keyframes_deferred_;
  }
  out.reference = out.new_keyframe ? out.new_keyframe : nearestKeyframe(current);
  out.T_c_ref = out.reference->relative(current.T_cw);
  last_reference_ = out.reference;
  last_T_c_ref_ = out.T_c_ref;
  epoch_seen_ = map_->epoch;
  out.state = state_;
  // Outliers do not go forward to the next frame's matching.
  for (size_t i = 0; i < current.points.size(); ++i)
    if (current.outlier[i]) current.points[i].reset();
  if (settings_.refine_frames) {
    out.observations.reserve(static_cast<size_t>(inliers_));
    for (size_t i = 0; i < current.points.size(); ++i)
      if (current.points[i] && !current.points[i]->bad)
        out.observations.push_back({current.points[i]->id, current.frame.points[i].cast<float>(),
                                    static_cast<uint8_t>(current.frame.keypoints[i].octave)});
  }
  last_ = std::move(current);
  return out;
}

std::unique_lock<std::mutex> Tracker::followMerges() {
  // Merged into another map since the last frame: a merge another node made, applied here,
  // need not keep the map tracking is in (LC's merge of TR's old map into its newer one came
  // just after TR had relocalized in the old one). Its keyframes and points live in the
  // other map now, and so does tracking; the merge moved them, so the last frame is re-posed.
  auto locked = lockFollowingMerges(map_, map_finder_);
  if (locked.moved) epoch_seen_ = std::numeric_limits<uint64_t>::max();
  return std::move(locked.lock);
}

void Tracker::startInMap(const std::shared_ptr<Map>& map) {
  map_ = map;
  state_ = TrackingState::Lost;
  keyframes_made_ = static_cast<int>(map->keyframes.size());
  lost_frames_ = 0;
  last_.reset();
  reference_.reset();
  last_reference_.reset();
  epoch_seen_ = map->epoch;
  have_velocity_ = false;
}

bool Tracker::initialize(Tracked& current, TrackingOutput& out) {
  if (!init_reference_ || current.frame.size() <= static_cast<size_t>(settings_.init_min_matches)) {
    if (current.frame.size() > static_cast<size_t>(settings_.init_min_matches)) {
      init_reference_ = current;
      init_prev_matched_ = current.frame.points;
      out.initialization_reference = true;
    }
    return false;
  }
  const Frame& f1 = init_reference_->frame;
  const Frame& f2 = current.frame;
  const std::vector<int> m = matchForInitialization(f1, f2, {}, &init_prev_matched_);
  std::vector<Eigen::Vector2d> p1, p2;
  std::vector<size_t> idx1;
  for (size_t i = 0; i < m.size(); ++i)
    if (m[i] >= 0) {
      p1.push_back(f1.points[i]);
      p2.push_back(f2.points[static_cast<size_t>(m[i])]);
      idx1.push_back(i);
      init_prev_matched_[i] = f2.points[static_cast<size_t>(m[i])];
    }
  if (static_cast<int>(p1.size()) < settings_.init_min_matches) {
    init_reference_ = current;  // too little overlap: start again from this frame
    init_prev_matched_ = current.frame.points;
    out.initialization_reference = true;
    return false;
  }
  TwoViewOptions o;
  o.min_points = settings_.init_min_points;
  o.min_parallax_deg = settings_.init_min_parallax_deg;
  o.seed = settings_.seed + current.frame.index;
  const TwoViewResult r = initializeTwoView(p1, p2, f1.K, o);
  if (!r.ok) return false;

  // The new map: two keyframes, the triangulated points, a full BA, median depth 1. (Points
  // erased here stay alive in map->erased_points until local mapping collects them.)
  auto map = std::make_shared<Map>(ids_.next());
  auto kf1 = std::make_shared<KeyFrame>(ids_.next(), f1, Eigen::Isometry3d::Identity());
  auto kf2 = std::make_shared<KeyFrame>(ids_.next(), f2, r.T_21);
  describePlace(*kf1);
  describePlace(*kf2);
  map->add(kf1);
  map->add(kf2);
  map->origin = kf1.get();
  for (size_t k = 0; k < p1.size(); ++k) {
    if (!r.good[k]) continue;
    auto p = std::make_shared<MapPoint>(ids_.next(), r.points[k], kf1->id);
    Map::observe(*kf1, static_cast<int>(idx1[k]), p);
    Map::observe(*kf2, m[idx1[k]], p);
    p->update(scales_);
    map->add(p);
  }
  kf1->updateConnections();
  kf2->updateConnections();
  {
    BaProblem ba;
    ba.K = f1.K;
    std::vector<KeyFrame*> kfs{kf1.get(), kf2.get()};
    for (auto* kf : kfs) ba.poses.push_back({Eigen::Quaterniond(kf->T_cw.linear()), kf->T_cw.translation(), kf == kf1.get()});
    std::vector<MapPoint*> pts;
    for (auto& [id, p] : map->points) {
      const int pi = static_cast<int>(pts.size());
      pts.push_back(p.get());
      ba.points.push_back({p->position, false});
      for (int k = 0; k < 2; ++k) {
        const int kp = p->observations.at(kfs[static_cast<size_t>(k)]);
        ba.observations.push_back({k, pi, kfs[static_cast<size_t>(k)]->frame.points[static_cast<size_t>(kp)],
                                   1.0 / scales_[static_cast<size_t>(kfs[static_cast<size_t>(k)]->frame.keypoints[static_cast<size_t>(kp)].octave)]});
      }
    }
    BaOptions bo;
    bo.iterations = 20;
    const BaSummary s = bundleAdjust(ba, bo);
    kf2->T_cw = ba.poses[1].T_cw();
    for (size_t i = 0; i < pts.size(); ++i) pts[i]->position = ba.points[i].p_w;
    for (size_t i = 0; i < ba.observations.size(); ++i)
      if (s.outlier[i]) {
        MapPoint* p = pts[static_cast<size_t>(ba.observations[i].point)];
        if (!p->bad) map->erase(*p);
      }
  }
  // Median depth of the first keyframe's points becomes 1.
  std::vector<double> depths;
  for (const auto& p : kf1->points)
    if (p && !p->bad) depths.push_back(p->position.z());
  if (depths.size() < static_cast<size_t>(settings_.init_min_points)) return false;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  const double median = depths[depths.size() / 2];
  if (median <= 0) return false;
  const double s = 1.0 / median;
  kf2->T_cw.translation() *= s;
  for (auto& [id, p] : map->points) {
    p->position *= s;
    p->update(scales_);
  }
  map_ = map;
  epoch_seen_ = map->epoch;
  last_reference_ = kf2;
  last_T_c_ref_ = kf2->relative(kf2->T_cw);
  keyframes_made_ = 2;
  reference_ = kf2;
  current.T_cw = kf2->T_cw;
  current.points = kf2->points;
  current.outlier.assign(current.points.size(), false);
  last_ = current;
  have_velocity_ = false;
  last_keyframe_frame_ = current.frame.index;
  last_keyframe_R_cw_ = current.T_cw.linear();
  init_reference_.reset();
  out.new_map = map;
  out.new_keyframe = kf2;
  out.reference = kf2;
  out.T_cw = kf2->T_cw;
  out.T_c_ref = last_T_c_ref_;
  out.inliers = static_cast<int>(map->points.size());
  return true;
}

std::shared_ptr<KeyFrame> Tracker::nearestKeyframe(const Tracked& c) const {
  // Not the reference keyframe (the one sharing the most points): the nearest keyframe that
  // sees the frame's points. Corrections (local and global BA, loop closing) move and rescale the
  // map around keyframes, and a relative pose follows its keyframe rigidly apart from the
  // scale: its error grows with its length. Right after initialization the first keyframe
  // shares the most points with every frame for a second or more; after a loop closure those
  // frames came out 4 to 32 mm off, growing with their distance from it (loop, 500 frames),
  // while the keyframes were within 4 mm.
  const Eigen::Vector3d center = c.T_cw.inverse().translation();
  std::shared_ptr<KeyFrame> best = reference_;
  double best_d2 = (reference_->pose().inverse().translation() - center).squaredNorm();
  std::unordered_set<KeyFrame*> seen{reference_.get()};
  for (size_t i = 0; i < c.points.size(); ++i) {
    if (!c.points[i] || c.outlier[i] || c.points[i]->bad) continue;
    for (const auto& [kf, idx] : c.points[i]->observations) {
      if (kf->bad || !seen.insert(kf).second) continue;
      const double d2 = (kf->center() - center).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best = kf->shared_from_this();
      }
    }
  }
  return best;
}

int Tracker::optimize(Tracked& c) {
  std::vector<PoseObservation> obs;
  std::vector<size_t> which;
  for (size_t i = 0; i < c.points.size(); ++i)
    if (c.points[i] && !c.points[i]->bad) {
      obs.push_back({c.points[i]->position, c.frame.points[i], 1.0 / scales_[static_cast<size_t>(c.frame.keypoints[i].octave)]});
      which.push_back(i);
    }
  std::vector<bool> outlier;
  const int inliers = optimizePose(c.frame.K, obs, c.T_cw, outlier);
  c.outlier.assign(c.points.size(), false);
  for (size_t k = 0; k < which.size(); ++k) c.outlier[which[k]] = outlier[k];
  return inliers;
}

bool Tracker::trackWithMotionModel(Tracked& c) {
  c.T_cw = velocity_ * last_->T_cw;
  std::fill(c.points.begin(), c.points.end(), nullptr);
  int n = matchFromLastFrame(c.frame, c.T_cw, c.points, last_->frame, last_->points, last_->outlier,
                             settings_.search_radius_last_frame, scales_, true);
  if (n < settings_.min_matches_last_frame) {
    std::fill(c.points.begin(), c.points.end(), nullptr);
    n = matchFromLastFrame(c.frame, c.T_cw, c.points, last_->frame, last_->points, last_->outlier,
                           2 * settings_.search_radius_last_frame, scales_, true);
  }
  if (n < settings_.min_matches_last_frame) return false;
  return optimize(c) >= 10;
}

bool Tracker::trackReferenceKeyframe(Tracked& c) {
  if (!last_ || !reference_) return false;
  // Without a velocity: the reference keyframe's points projected from the last pose with a
  // wide window (the bag-of-words search replaces this in the next layer of the core).
  c.T_cw = last_->T_cw;
  std::fill(c.points.begin(), c.points.end(), nullptr);
  std::vector<bool> no_outliers(reference_->points.size(), false);
  const int n = matchFromLastFrame(c.frame, c.T_cw, c.points, reference_->frame, reference_->points, no_outliers,
                                   3 * settings_.search_radius_last_frame, scales_, true);
  if (n < 15) return false;
  return optimize(c) >= 10;
}

bool Tracker::trackLocalMap(Tracked& c, int min_inliers) {
  // Local keyframes: those seeing the current matches, plus their best covisible neighbours.
  std::map<KeyFrame*, int, ById> votes;
  for (size_t i = 0; i < c.points.size(); ++i)
    if (c.points[i] && !c.outlier[i] && !c.points[i]->bad)
      for (const auto& [kf, idx] : c.points[i]->observations) ++votes[kf];
  std::vector<KeyFrame*> local;
  std::set<KeyFrame*> in_local;
  KeyFrame* best = nullptr;
  int best_votes = 0;
  for (const auto& [kf, v] : votes) {
    if (kf->bad) continue;
    local.push_back(kf);
    in_local.insert(kf);
    if (v > best_votes) {
      best_votes = v;
      best = kf;
    }
  }
  const size_t direct = local.size();
  for (size_t k = 0; k < direct && local.size() < 80; ++k)
    for (KeyFrame* n : local[k]->bestCovisible(static_cast<size_t>(settings_.local_keyframes)))
      if (in_local.insert(n).second) local.push_back(n);
  if (best) reference_ = best->shared_from_this();
  // Local points not matched yet.
  std::unordered_set<MapPoint*> matched;
  for (size_t i = 0; i < c.points.size(); ++i)
    if (c.points[i]) {
      if (c.outlier[i]) c.points[i].reset();
      else matched.insert(c.points[i].get());
    }
  std::vector<std::shared_ptr<MapPoint>> candidates;
  std::unordered_set<MapPoint*> seen;  // thousands of points per frame: hashed, not a tree
  seen.reserve(8192);
  for (KeyFrame* kf : local)
    for (const auto& p : kf->points)
      if (p && !p->bad && !matched.count(p.get()) && seen.insert(p.get()).second) candidates.push_back(p);
  matchLocalMap(c.frame, c.T_cw, c.points, candidates, relocalizedWithin(c.frame, 2) ? 5.0 : 1.0, scales_);
  optimize(c);
  inliers_ = 0;
  for (size_t i = 0; i < c.points.size(); ++i)
    if (c.points[i] && !c.outlier[i]) {
      ++c.points[i]->found;
      if (!c.points[i]->observations.empty()) ++inliers_;
    }
  return inliers_ >= min_inliers;
}

Tracker::PlaceQuery Tracker::queryPlaces(const Frame& frame) const {
  PlaceQuery q;
  if (!vocabulary_ || !database_) return q;
  place::BowVector bow;
  vocabulary_->transform(frame.descriptors, bow, q.features);
  q.places = database_->query(bow, {});
  return q;
}

std::vector<std::shared_ptr<KeyFrame>> Tracker::relocalizationCandidates(const PlaceQuery& q, const Map& map,
                                                                        size_t max) const {
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  if (vocabulary_ && database_) {
    // Keyframes of this map that look like the frame, best first.
    for (const auto& c : q.places) {
      if (c.map != &map || c.keyframe->bad) continue;
      auto it = map.keyframes.find(c.keyframe->id);
      if (it != map.keyframes.end()) kfs.push_back(it->second);
      if (kfs.size() >= max) break;
    }
    return kfs;
  }
  // Without a vocabulary: a spread of the keyframes, most recent first.
  std::vector<std::shared_ptr<KeyFrame>> all;
  for (const auto& [id, kf] : map.keyframes) all.push_back(kf);
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a->id > b->id; });
  const size_t stride = std::max<size_t>(1, all.size() / 20);
  for (size_t k = 0; k < all.size(); k += stride) kfs.push_back(all[k]);
  return kfs;
}

bool Tracker::relocalize(Tracked& c, const std::vector<std::shared_ptr<KeyFrame>>& kfs,
                         const place::FeatureVector& features) {
  for (size_t k = 0; k < kfs.size(); ++k) {
    const KeyFrame& kf = *kfs[k];
    std::vector<PnpMatch> matches;
    PointSlots slots(c.frame.size());
    auto add = [&](int i, const std::shared_ptr<MapPoint>& p) {
      slots[static_cast<size_t>(i)] = p;
      matches.push_back({p->position, c.frame.points[static_cast<size_t>(i)]});
    };
    if (!features.empty() && !kf.bow_features.empty()) {
      const std::vector<int> m = matchFrameByBow(c.frame, features, kf);
      for (size_t i = 0; i < m.size(); ++i)
        if (m[i] >= 0) add(static_cast<int>(i), kf.points[static_cast<size_t>(m[i])]);
    } else {
      for (size_t j = 0; j < kf.points.size(); ++j) {
        const auto& p = kf.points[j];
        if (!p || p->bad) continue;
        features::NearestTwo near;
        for (int i = 0; i < static_cast<int>(c.frame.size()); ++i)
          near.offer(features::hamming(p->descriptor.ptr<uchar>(), c.frame.descriptors.ptr<uchar>(i)), i);
        if (!near.accepted(kMatchLow, 0.75) || slots[static_cast<size_t>(near.index)]) continue;
        add(near.index, p);
      }
    }
    if (matches.size() < 15) continue;
    const auto pose = solvePnpRansac(c.frame.K, matches, 4.0, 10, static_cast<int>((settings_.seed + c.frame.index) & 0x7fffffff));
    if (!pose) continue;
    c.T_cw = pose->T_cw;
    c.points = slots;
    if (optimize(c) < 10) continue;
    reference_ = kfs[k];
    if (trackLocalMap(c, settings_.min_inliers_after_relocalization)) return true;
  }
  return false;
}

bool Tracker::relocalizeInKnownMap(Tracked& c, const PlaceQuery& q, const Map* skip,
                                   std::unique_lock<std::mutex>& lock) {
  if (!map_finder_) return false;
  // The best-scored places outside `skip`, by map in the order of each map's best place: a
  // handful, as every candidate costs a PnP RANSAC on a frame that is not tracked anyway.
  constexpr size_t kPlaces = 5;
  std::vector<std::pair<const Map*, size_t>> maps;  // map, places in it
  size_t places = 0;
  for (const auto& p : q.places) {
    if (p.map == skip || p.keyframe->bad) continue;
    auto it = std::find_if(maps.begin(), maps.end(), [&](const auto& m) { return m.first == p.map; });
    if (it == maps.end()) maps.emplace_back(p.map, 1);
    else ++it->second;
    if (++places >= kPlaces) break;
  }
  const std::shared_ptr<Map> previous = map_;
  const std::shared_ptr<KeyFrame> previous_reference = reference_;
  for (const auto& [m, count] : maps) {
    std::shared_ptr<Map> map = map_finder_(m);
    if (!map) continue;
    std::unique_lock candidate_lock(map->mutex);
    if (map->merged_into.load()) continue;
    map_ = map;
    if (relocalize(c, relocalizationCandidates(q, *map, count), q.features)) {
      lock = std::move(candidate_lock);
      state_ = TrackingState::Ok;
      keyframes_made_ = static_cast<int>(map->keyframes.size());
      epoch_seen_ = map->epoch;
      init_reference_.reset();
      last_.reset();
      have_velocity_ = false;
      ++relocalized_in_known_map_;
      return true;
    }
  }
  map_ = previous;
  reference_ = previous_reference;
  return false;
}

double Tracker::trackedShare() const {
  const int reference_points = reference_ ? reference_->trackedPoints(keyframes_made_ <= 2 ? 2 : 3) : 0;
  // Without reference points no keyframe is due: as if every one were tracked.
  return reference_points > 0 ? static_cast<double>(inliers_) / reference_points : std::numeric_limits<double>::infinity();
}

bool Tracker::turnedFromKeyframe(const Tracked& c) const {
  return settings_.keyframe_turn_deg > 0 && viewAngleDegrees(last_keyframe_R_cw_, c.T_cw.linear()) > settings_.keyframe_turn_deg;
}

bool Tracker::keyframeWanted(const Tracked& c, double share) const {
  if (c.frame.index - last_keyframe_frame_ < static_cast<size_t>(settings_.keyframe_min_frames)) return false;
  return (share < settings_.keyframe_ratio || turnedFromKeyframe(c)) && inliers_ > settings_.keyframe_min_inliers;
}

Tracker::KeyframeDecision Tracker::keyframeDecision(const Tracked& c, bool mapping_idle) const {
  if (relocalizedWithin(c.frame, static_cast<size_t>(settings_.keyframe_max_frames)) &&
      keyframes_made_ > settings_.keyframe_max_frames)
    return KeyframeDecision::None;
  const double share = trackedShare();  // counts the reference's points: once per frame
  if (!keyframeWanted(c, share)) return KeyframeDecision::None;  // also: too soon after the last one
  const size_t since = c.frame.index - last_keyframe_frame_;
  const bool timely = since >= static_cast<size_t>(settings_.keyframe_max_frames) || mapping_idle ||
                      share < settings_.keyframe_weak_ratio || turnedFromKeyframe(c);
  return timely ? KeyframeDecision::Make : KeyframeDecision::Deferred;
}

void Tracker::describePlace(KeyFrame& kf) const {
  if (vocabulary_) vocabulary_->transform(kf.frame.descriptors, kf.bow, kf.bow_features);
}

std::shared_ptr<KeyFrame> Tracker::makeKeyframe(const Tracked& c) {
  auto kf = std::make_shared<KeyFrame>(ids_.next(), c.frame, c.T_cw);
  describePlace(*kf);
  kf->made_in_epoch = map_->epoch;
  if (reference_) {
    kf->made_from = reference_.get();
    kf->made_pose = reference_->relative(c.T_cw);
  }
  for (size_t i = 0; i < c.points.size(); ++i)
    if (c.points[i] && !c.outlier[i] && !c.points[i]->bad) kf->points[i] = c.points[i];
  return kf;
}

}  // namespace hiveslam::core
