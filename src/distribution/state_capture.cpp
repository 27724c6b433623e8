#include "distribution/state_capture.hpp"

#include <cstring>

namespace hiveslam::distribution {

KeyFrameRecord captureKeyframe(const core::KeyFrame& kf, Id map, bool full) {
  KeyFrameRecord r;
  r.id = kf.id;
  r.map = map;
  r.T_cw = kf.T_cw;
  r.parent = kf.parent ? kf.parent->id : kNoId;
  for (size_t i = 0; i < kf.points.size(); ++i)
    if (kf.points[i] && !kf.points[i]->bad) r.matches.emplace_back(static_cast<uint32_t>(i), kf.points[i]->id);
  for (const core::KeyFrame* l : kf.loop_edges) r.loop_edges.push_back(l->id);
  r.full = full;
  if (full) {
    r.frame = kf.frame;
    r.made_in_epoch = kf.made_in_epoch;
    r.made_from = kf.made_from ? kf.made_from->id : kNoId;
    // In the map's current frame (the label's): the scale it was taken at is this node's own.
    r.T_made_from = kf.made_pose.T_c_k;
    if (kf.made_from) r.T_made_from.translation() *= kf.made_from->scale() / kf.made_pose.scale;
  }
  return r;
}

PointRecord capturePoint(const core::MapPoint& p, bool full) {
  PointRecord r;
  r.id = p.id;
  r.position = p.position;
  r.full = full;
  if (full) {
    r.first_keyframe = p.first_keyframe;
    if (!p.descriptor.empty()) std::memcpy(r.descriptor.data(), p.descriptor.ptr<uint8_t>(), 32);
    r.normal = p.normal;
    r.min_distance = p.min_distance;
    r.max_distance = p.max_distance;
  }
  return r;
}

}  // namespace hiveslam::distribution
