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
  double min_x = 0, min_y = 0, max_x = camera.width(), max_y = camera.height();
  for (const auto& kp : f.keypoints) {
    const Eigen::Vector3d b = camera.unproject({kp.pt.x, kp.pt.y});
    // A fisheye bearing at or past 90 degrees has no pinhole image: keep it far outside.
    const Eigen::Vector2d p = b.z() > 1e-3 ? f.K.project(b) : Eigen::Vector2d(-1e6, -1e6);
    f.points.push_back(p);
    if (b.z() > 1e-3) {
      min_x = std::min(min_x, p.x());
      min_y = std::min(min_y, p.y());
      max_x = std::max(max_x, p.x());
      max_y = std::max(max_y, p.y());
    }
  }
  f.grid = FeatureGrid(f.points, min_x, min_y, max_x, max_y);
  return f;
}

}  // namespace hiveslam::core
