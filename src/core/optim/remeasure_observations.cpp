#include "core/optim/remeasure_observations.hpp"

#include <algorithm>
#include <unordered_map>

#include "core/geometry/plane_warp.hpp"
#include "core/map/keyframe.hpp"

namespace hiveslam::core {

RemeasureStats remeasureObservations(MapBaProblem& mp, const camera::CameraModel& camera, const KeyframeImages& images,
                                     const RemeasureOptions& options, Remeasurements* measured) {
  std::vector<Eigen::Vector3d> positions;
  for (const BaPoint& p : mp.problem.points) positions.push_back(p.p_w);
  return remeasureObservations(mp, camera, images, planeNormals(positions, options.normals), options, measured);
}

RemeasureStats remeasureObservations(MapBaProblem& mp, const camera::CameraModel& camera, const KeyframeImages& images,
                                     const std::vector<std::optional<Eigen::Vector3d>>& normals,
                                     const RemeasureOptions& options, Remeasurements* measured) {
  RemeasureStats stats;
  BaProblem& ba = mp.problem;
  const std::vector<int> anchor = pointAnchors(mp);
  // Anchor by anchor (in keyframe order), and each anchor's views in keyframe order.
  std::vector<size_t> order(ba.observations.size());
  for (size_t o = 0; o < order.size(); ++o) order[o] = o;
  const auto keyframe_of = [&](size_t o) { return mp.sources[o].first->id; };
  const auto anchor_of = [&](size_t o) { return static_cast<size_t>(anchor[static_cast<size_t>(ba.observations[o].point)]); };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return std::pair(keyframe_of(anchor_of(a)), keyframe_of(a)) < std::pair(keyframe_of(anchor_of(b)), keyframe_of(b));
  });
  for (const size_t o : order) {
    BaObservation& ob = ba.observations[o];
    const size_t point = static_cast<size_t>(ob.point);
    const size_t a = static_cast<size_t>(anchor[point]);
    if (a == o) {
      ++stats.anchors;
      continue;
    }
    const KeyFrame& kf = *mp.sources[o].first;
    const KeyFrame& anchor_kf = *mp.sources[a].first;
    const auto here = images(kf);
    const auto there = images(anchor_kf);
    const cv::KeyPoint& kp = kf.frame.keypoints[static_cast<size_t>(mp.sources[o].second)];
    if (!here || !there || kp.octave >= here->levels()) {
      ++stats.kept;
      continue;
    }
    const Eigen::Isometry3d T_here = ba.poses[static_cast<size_t>(ob.pose)].T_cw();
    const Eigen::Isometry3d T_there = ba.poses[static_cast<size_t>(ba.observations[a].pose)].T_cw();
    const Eigen::Vector3d X = ba.points[point].p_w, anchor_centre = T_there.inverse().translation();
    Eigen::Vector3d n = (anchor_centre - X).normalized();  // facing the anchor, unless the neighbours say otherwise
    if (normals[point]) n = normals[point]->dot(n) < 0 ? Eigen::Vector3d(-*normals[point]) : *normals[point];
    // The anchor's corner on that plane, and where it falls in this view: the patch's centre.
    const cv::KeyPoint& anchor_kp = anchor_kf.frame.keypoints[static_cast<size_t>(mp.sources[a].second)];
    const auto into_here = geometry::PlaneWarp::through(camera, T_there, T_here, X, n);
    const auto centre0 = into_here(Eigen::Vector2d(anchor_kp.pt.x, anchor_kp.pt.y));
    if (!centre0) {
      ++stats.kept;
      continue;
    }
    const auto into_anchor = geometry::PlaneWarp::through(camera, T_here, T_there, X, n);
    const cv::Point2d centre = here->toLevel(kp.octave, {centre0->x(), centre0->y()});
    const auto patch = features::sampleWarpedPatch(*there, *here, kp.octave, centre, into_anchor, options.patch_half);
    const auto found = patch ? features::alignPatch(here->level(kp.octave), *patch, here->toLevel(kp.octave, kp.pt), options.alignment)
                             : std::nullopt;
    if (!found) {
      ++stats.kept;
      continue;
    }
    const cv::Point2d at = here->toLevel0(kp.octave, found->position);
    const Eigen::Vector3d ray = camera.unproject({at.x, at.y});
    ob.uv = ba.K.project(ray);
    ++stats.aligned;
    if (measured) {
      const auto idx = static_cast<size_t>(mp.sources[o].second);
      (*measured)[kf.id].push_back({static_cast<uint32_t>(idx), (ob.uv - kf.frame.points[idx]).cast<float>(), mp.points[point]->id,
                                    anchor_kf.id, static_cast<uint32_t>(mp.sources[a].second)});
    }
  }
  for (const auto& n : normals) stats.plane_normals += n.has_value();
  if (measured)
    for (auto& [id, entries] : *measured)
      std::sort(entries.begin(), entries.end(), [](const Remeasurement& a, const Remeasurement& b) { return a.keypoint < b.keypoint; });
  return stats;
}

}  // namespace hiveslam::core
