#pragma once
// Valid wire records of every kind, for the wire tests and the fuzzer's seed corpus
// (fuzz/wire_seeds.cpp): a full keyframe with its features, a point and a companion, a global
// map batch with erasures, and re-measured observations.
#include "core/features/orb_extractor.hpp"
#include "distribution/wire/record_codec.hpp"

namespace hiveslam::distribution {

inline KeyFrameMessage sampleKeyframe() {
  KeyFrameMessage m;
  auto& k = m.keyframe;
  k.id = 42;
  k.map = 7;
  k.T_cw.translate(Eigen::Vector3d(1, 2, 3));
  k.T_cw.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  k.parent = 41;
  k.full = true;
  k.frame.width = 640;
  k.frame.height = 480;
  k.frame.K = {500, 500, 320, 240};
  k.frame.timestamp = 12.5;
  k.frame.descriptors = cv::Mat(3, 32, CV_8U);
  for (int i = 0; i < 3; ++i) {
    k.frame.keypoints.emplace_back(cv::Point2f(10.f * i, 20.f), 31.f, 45.f * i, 0.f, i);
    k.frame.points.emplace_back(10.0 * i, 20.0);
    for (int b = 0; b < 32; ++b) k.frame.descriptors.at<uint8_t>(i, b) = static_cast<uint8_t>(i * 32 + b);
  }
  k.frame.keypoints[1].class_id = features::kWeakCorner;
  k.matches = {{0, 100}, {2, 101}};
  PointRecord p;
  p.id = 100;
  p.position = {0.5, -1.25, 3.0};
  p.full = true;
  p.normal = {0, 0, 1};
  p.max_distance = 4;
  m.points.push_back(p);
  return m;
}

inline MapRecord sampleMap() {
  MapRecord m;
  m.kind = MapRecord::Kind::Global;
  m.map = 7;
  m.epoch = 3;
  m.keyframes.push_back(sampleKeyframe().keyframe);
  m.points = sampleKeyframe().points;
  m.erased_points = {9, 10};
  m.replaced_points = {{11, 12}};
  m.mapped = {42};
  return m;
}

inline core::Remeasurements sampleRemeasurements() {
  core::Remeasurements r;
  r[42] = {{1, {0.25f, -0.125f}, 100, 40, 7}, {2, {1.0f, 2.0f}, 5, 41, 17}};
  return r;
}

}  // namespace hiveslam::distribution
