#pragma once
// The renderer's own camera: pinhole with optional radial-tangential distortion. Written
// separately from core/camera on purpose: the renderer is the oracle the core is tested
// against, so it must not share the core's projection code.
#include <Eigen/Core>
#include <array>
#include <vector>

namespace hiveslam::synth {

struct Lens {
  int width = 752, height = 480;
  double fx = 460.0, fy = 460.0, cx = 375.5, cy = 239.5;
  std::array<double, 4> k{0, 0, 0, 0};  // k1 k2 p1 p2

  // A camera of the given size with EuRoC's field of view (about 78 x 55 degrees).
  static Lens standard(int width, int height, bool distorted);

  Eigen::Vector2d distort(const Eigen::Vector2d& n) const;
  // Normalized undistorted coordinates (x/z, y/z) seen by pixel (u, v).
  Eigen::Vector2d pixelToNormalized(double u, double v) const;
};

// Per-pixel rays (camera frame, z = 1) and the pixel's angular size at unit depth, made once
// per sequence: the per-frame work is then one rotation per pixel.
struct RayTable {
  int width = 0, height = 0;
  std::vector<Eigen::Vector3d> rays;
  std::vector<float> pixel_size;  // metres per pixel at depth 1
  explicit RayTable(const Lens& lens);
};

}  // namespace hiveslam::synth
