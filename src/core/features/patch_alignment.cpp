#include "core/features/patch_alignment.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

namespace hiveslam::features {

std::optional<Patch> sampleWarpedPatch(const ImagePyramid& reference, const ImagePyramid& searched, int level,
                                       cv::Point2d centre, const PixelWarp& warp, int half) {
  const auto toReference = [&](double dx, double dy) -> std::optional<Eigen::Vector2d> {
    const cv::Point2d p = searched.toLevel0(level, centre + cv::Point2d(dx, dy));
    return warp(Eigen::Vector2d(p.x, p.y));
  };
  // The reference level: one searched pixel spans about one of its pixels.
  const auto at = toReference(0, 0), right = toReference(1, 0), down = toReference(0, 1);
  if (!at || !right || !down) return std::nullopt;
  const double spacing = std::sqrt((*right - *at).norm() * (*down - *at).norm());
  const double scale = reference.scaleFactor();
  int ref_level = 0;
  if (spacing > 0 && scale > 1.0)
    ref_level = std::clamp(static_cast<int>(std::lround(std::log(spacing) / std::log(scale))), 0, reference.levels() - 1);
  // The warp is smooth across one patch: taken through the camera model on a 3x3 grid over the
  // patch and interpolated quadratically between (nine warps instead of one per pixel; the
  // distortion's inversion made the per-pixel warp most of the re-measurement's time).
  const double h = std::max(half, 1);
  std::array<Eigen::Vector2d, 9> grid;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const auto p = i == 1 && j == 1 ? at : toReference((i - 1) * h, (j - 1) * h);
      if (!p) return std::nullopt;
      grid[static_cast<size_t>(j * 3 + i)] = *p;
    }
  // Lagrange weights of the nodes -h, 0, h at t.
  const auto weights = [h](double t) -> std::array<double, 3> {
    const double u = t / h;
    return {0.5 * u * (u - 1), 1 - u * u, 0.5 * u * (u + 1)};
  };
  Patch patch;
  patch.half = half;
  patch.values.resize(static_cast<size_t>(patch.side() * patch.side()));
  for (int r = 0; r < patch.side(); ++r)
    for (int c = 0; c < patch.side(); ++c) {
      const auto wx = weights(patch.offset(c)), wy = weights(patch.offset(r));
      Eigen::Vector2d p = Eigen::Vector2d::Zero();
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) p += wx[static_cast<size_t>(i)] * wy[static_cast<size_t>(j)] * grid[static_cast<size_t>(j * 3 + i)];
      const cv::Point2d q = reference.toLevel(ref_level, {p.x(), p.y()});
      const float v = sampleBilinear(reference.level(ref_level), q.x, q.y);
      if (std::isnan(v)) return std::nullopt;
      patch.values[static_cast<size_t>(r * patch.side() + c)] = v;
    }
  return patch;
}

namespace {

// Bilinear samples of `gray` at x0 + c, y0 + r (c < cols, r < rows) into `out`, row by row: one
// sub-pixel offset for all, so the bounds are checked once and each sample is four reads (as
// sampleBilinear, which this replaces in the alignment's inner loop). False where the block
// leaves the image.
bool sampleGrid(const cv::Mat& gray, double x0, double y0, int cols, int rows, float* out) {
  const double fx0 = std::floor(x0), fy0 = std::floor(y0);
  const int ix = static_cast<int>(fx0), iy = static_cast<int>(fy0);
  if (ix < 0 || iy < 0 || ix + cols > gray.cols - 1 || iy + rows > gray.rows - 1) return false;
  const double fx = x0 - fx0, fy = y0 - fy0;
  for (int r = 0; r < rows; ++r) {
    const uchar* r0 = gray.ptr<uchar>(iy + r) + ix;
    const uchar* r1 = gray.ptr<uchar>(iy + r + 1) + ix;
    for (int c = 0; c < cols; ++c) {
      const double top = r0[c] + fx * (r0[c + 1] - r0[c]);
      const double bottom = r1[c] + fx * (r1[c + 1] - r1[c]);
      *out++ = static_cast<float>(top + fy * (bottom - top));
    }
  }
  return true;
}

}  // namespace

std::optional<PatchAlignment> alignPatch(const cv::Mat& image, const Patch& patch, cv::Point2d start,
                                         const PatchAlignmentOptions& options) {
  CV_Assert(image.type() == CV_8UC1);
  const int n = patch.side();
  CV_Assert(static_cast<int>(patch.values.size()) == n * n);
  PatchAlignment a;
  a.position = start;
  // The patch's samples, and those half a pixel left and right (above and below) of each.
  std::vector<float> I(static_cast<size_t>(n * n)), Ih(static_cast<size_t>(n * (n + 1))), Iv(Ih.size());
  for (a.iterations = 1; a.iterations <= options.max_iterations; ++a.iterations) {
    // Unknowns: shift x, shift y, gain, bias. Residual: image - (gain patch + bias).
    Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
    Eigen::Vector4d g = Eigen::Vector4d::Zero();
    const double x0 = a.position.x + patch.offset(0), y0 = a.position.y + patch.offset(0);
    if (!sampleGrid(image, x0, y0, n, n, I.data()) || !sampleGrid(image, x0 - 0.5, y0, n + 1, n, Ih.data()) ||
        !sampleGrid(image, x0, y0 - 0.5, n, n + 1, Iv.data()))
      return std::nullopt;
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        // Gradients by central differences half a pixel either side: on the bilinear surface
        // they are the slopes of the cells the sample sits between.
        const size_t h = static_cast<size_t>(r * (n + 1) + c), v = static_cast<size_t>(r * n + c);
        const float Ix = Ih[h + 1] - Ih[h];
        const float Iy = Iv[v + static_cast<size_t>(n)] - Iv[v];
        const double t = patch.values[v];
        const double e = I[v] - a.gain * t - a.bias;
        const Eigen::Vector4d J(Ix, Iy, -t, -1.0);
        H.noalias() += J * J.transpose();
        g.noalias() += J * e;
      }
    if (a.iterations == 1) {
      const Eigen::Matrix2d shift_block = H.topLeftCorner<2, 2>() / static_cast<double>(n * n);
      const double weaker = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(shift_block, Eigen::EigenvaluesOnly).eigenvalues()(0);
      if (weaker < options.min_gradient * options.min_gradient) return std::nullopt;
    }
    const Eigen::Vector4d step = -H.ldlt().solve(g);
    if (!step.allFinite()) return std::nullopt;
    a.position += cv::Point2d(step[0], step[1]);
    a.gain += step[2];
    a.bias += step[3];
    const double moved = std::hypot(a.position.x - start.x, a.position.y - start.y);
    if (moved > 3 * options.max_shift_px) return std::nullopt;  // diverging; the first steps may overshoot
    if (std::hypot(step[0], step[1]) < options.converged_px) {
      if (moved > options.max_shift_px || a.gain < options.min_gain || a.gain > options.max_gain) return std::nullopt;
      return a;
    }
  }
  return std::nullopt;
}

}  // namespace hiveslam::features
