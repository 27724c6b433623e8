#include "synth/lens.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace hiveslam::synth {

Lens Lens::standard(int width, int height, bool distorted) {
  Lens l;
  l.width = width;
  l.height = height;
  l.fx = l.fy = 460.0 * width / 752.0;
  // Pixel centres are integers (OpenCV's convention): the image centre is (w-1)/2.
  l.cx = (width - 1) / 2.0;
  l.cy = (height - 1) / 2.0;
  if (distorted) l.k = {-0.28, 0.074, 2e-4, 1.8e-5};  // close to EuRoC's cam0
  return l;
}

Eigen::Vector2d Lens::distort(const Eigen::Vector2d& n) const {
  const double x = n.x(), y = n.y(), r2 = x * x + y * y;
  const double radial = 1 + k[0] * r2 + k[1] * r2 * r2;
  return {x * radial + 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x),
          y * radial + k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y};
}

Eigen::Vector2d Lens::pixelToNormalized(double u, double v) const {
  const Eigen::Vector2d target((u - cx) / fx, (v - cy) / fy);
  Eigen::Vector2d n = target;
  // Fixed-point iteration n <- n - (distort(n) - target); converges for EuRoC-like lenses.
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector2d e = distort(n) - target;
    n -= e;
    if (e.squaredNorm() < 1e-28) break;
  }
  return n;
}

RayTable::RayTable(const Lens& lens) : width(lens.width), height(lens.height) {
  rays.resize(static_cast<size_t>(width) * height);
  pixel_size.resize(rays.size());
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector2d n = lens.pixelToNormalized(u, v);
      const Eigen::Vector2d nx = lens.pixelToNormalized(u + 1, v);
      const Eigen::Vector2d ny = lens.pixelToNormalized(u, v + 1);
      const size_t i = static_cast<size_t>(v) * width + u;
      rays[i] = Eigen::Vector3d(n.x(), n.y(), 1.0);
      pixel_size[i] = static_cast<float>(std::sqrt((nx - n).norm() * (ny - n).norm()));
    }
}

}  // namespace hiveslam::synth
