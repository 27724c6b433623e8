#pragma once
// The standard suite's sweep, for tests that measure features against the true geometry of its
// turn: the model (no lens distortion, so pixels are pinhole pixels), and a corner's surface point
// read off a view's rendered depth.
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "synth/renderer.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::testing {

inline synth::SequenceModel renderedSweep() {
  synth::SequenceOptions o;
  o.trajectory = "sweep";
  o.seed = 4;
  o.frames = 800;
  return synth::buildSequence(o);
}

// The rendered depth of a view (metres along the optical axis) under a sub-pixel position.
inline double depthAt(const cv::Mat& depth, cv::Point2f p) {
  cv::Mat d;
  cv::getRectSubPix(depth, {1, 1}, p, d);
  return d.at<float>(0, 0);
}

// The world point a view (pose T_wc, depth map `depth`) sees at pixel `p`, or nothing where the
// depth within `radius` pixels varies by more than 5%: an occluding edge has no one surface under
// it, and a patch or corner there mixes two.
inline std::optional<Eigen::Vector3d> surfacePoint(const cv::Mat& depth, const synth::Lens& lens, const Eigen::Isometry3d& T_wc,
                                                   cv::Point2f p, int radius) {
  const int x = static_cast<int>(p.x), y = static_cast<int>(p.y);
  if (x < radius || y < radius || x >= depth.cols - radius - 1 || y >= depth.rows - radius - 1) return std::nullopt;
  double lo = 0, hi = 0;
  cv::minMaxLoc(depth(cv::Rect(x - radius, y - radius, 2 * radius + 1, 2 * radius + 1)), &lo, &hi);
  if (hi - lo > 0.05 * lo) return std::nullopt;
  const double z = depthAt(depth, p);
  return T_wc * Eigen::Vector3d((p.x - lens.cx) / lens.fx * z, (p.y - lens.cy) / lens.fy * z, z);
}

}  // namespace hiveslam::testing
