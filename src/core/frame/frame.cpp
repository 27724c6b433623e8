#include "core/frame/frame.hpp"

#include <algorithm>

namespace hiveslam::core {

Frame makeFrame(const cv::Mat& gray, size_t index, double timestamp, const features::OrbExtractor& extractor,
                const camera::CameraModel& camera) {
  Frame f;
  f.index = index;
  f.timestamp = timestamp;
  f.K = {camera.fx(), camera.fy(), camera.cx(), camera.cy()};
  f.width = camera.width();
  f.height = camera.height();
  extractor.extract(gray, f.keypoints, f.descriptors);
  f.points.reserve(f.keypoints.size());
  for (const auto& kp : f.keypoints) {
    const Eigen::Vector3d b = camera.unproject({kp.pt.x, kp.pt.y});
    // A fisheye bearing at or past 90 degrees has no pinhole image: keep it far outside.
    f.points.push_back(b.z() > 1e-3 ? f.K.project(b) : Eigen::Vector2d(Frame::kFarOutside, Frame::kFarOutside));
  }
  f.buildGrid();
  return f;
}

void Frame::buildGrid() {
  double min_x = 0, min_y = 0, max_x = width, max_y = height;
  for (const auto& p : points) {
    if (p.x() <= kFarOutside) continue;
    min_x = std::min(min_x, p.x());
    min_y = std::min(min_y, p.y());
    max_x = std::max(max_x, p.x());
    max_y = std::max(max_y, p.y());
  }
  grid = FeatureGrid(points, min_x, min_y, max_x, max_y);
}

}  // namespace hiveslam::core
