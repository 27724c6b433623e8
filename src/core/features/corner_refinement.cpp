#include "core/features/corner_refinement.hpp"

#include <array>
#include <cmath>

namespace hiveslam::features {

namespace {

constexpr int kWindow = 3;                 // Gaussian window radius
constexpr int kMaxGrid = kCornerClimb + 1;  // response grid radius: the climb and the fit
constexpr int kMaxSide = 2 * kMaxGrid + 1;
static_assert(kMaxGrid + kWindow + 1 <= kCornerReach, "the Sobel of the window's rim must be inside the reach");

// Weights of the Gaussian window, sigma 1.8 px: wide enough that the response is smooth at the
// pixel scale (the quadratic fit needs that), narrow enough to stay on one corner.
const std::array<float, 2 * kWindow + 1>& windowWeights() {
  static const auto w = [] {
    std::array<float, 2 * kWindow + 1> k{};
    double sum = 0;
    for (int i = -kWindow; i <= kWindow; ++i)
      sum += k[static_cast<size_t>(i + kWindow)] = static_cast<float>(std::exp(-i * i / (2 * 1.8 * 1.8)));
    for (auto& v : k) v = static_cast<float>(v / sum);
    return k;
  }();
  return w;
}

// The Harris response on the (2 grid + 1)^2 pixels at the centre of a float patch of side
// 2 (grid + kWindow + 1) + 1: Sobel gradients, their products, a separable Gaussian window.
struct ResponseGrid {
  int grid = 0;
  double r[kMaxSide][kMaxSide];
  double at(int dx, int dy) const { return r[dy + grid][dx + grid]; }
};
ResponseGrid harrisResponse(const cv::Mat& patch, int grid) {
  const int tensor = grid + kWindow, side = 2 * tensor + 1, out = 2 * grid + 1;
  CV_Assert(patch.type() == CV_32F && patch.rows == side + 2 && patch.cols == side + 2);
  float xx[kMaxSide + 2 * kWindow][kMaxSide + 2 * kWindow], xy[kMaxSide + 2 * kWindow][kMaxSide + 2 * kWindow],
      yy[kMaxSide + 2 * kWindow][kMaxSide + 2 * kWindow];
  for (int r = 0; r < side; ++r) {
    const float* up = patch.ptr<float>(r) + 1;
    const float* mid = patch.ptr<float>(r + 1) + 1;
    const float* down = patch.ptr<float>(r + 2) + 1;
    for (int c = 0; c < side; ++c) {
      const float gx = (up[c + 1] - up[c - 1]) + 2 * (mid[c + 1] - mid[c - 1]) + (down[c + 1] - down[c - 1]);
      const float gy = (down[c - 1] - up[c - 1]) + 2 * (down[c] - up[c]) + (down[c + 1] - up[c + 1]);
      xx[r][c] = gx * gx;
      xy[r][c] = gx * gy;
      yy[r][c] = gy * gy;
    }
  }
  const auto& w = windowWeights();
  float hxx[kMaxSide + 2 * kWindow][kMaxSide], hxy[kMaxSide + 2 * kWindow][kMaxSide], hyy[kMaxSide + 2 * kWindow][kMaxSide];
  for (int r = 0; r < side; ++r)
    for (int c = 0; c < out; ++c) {
      float a = 0, b = 0, d = 0;
      for (int k = 0; k <= 2 * kWindow; ++k) {
        a += w[static_cast<size_t>(k)] * xx[r][c + k];
        b += w[static_cast<size_t>(k)] * xy[r][c + k];
        d += w[static_cast<size_t>(k)] * yy[r][c + k];
      }
      hxx[r][c] = a;
      hxy[r][c] = b;
      hyy[r][c] = d;
    }
  ResponseGrid g;
  g.grid = grid;
  for (int r = 0; r < out; ++r)
    for (int c = 0; c < out; ++c) {
      double a = 0, b = 0, d = 0;
      for (int k = 0; k <= 2 * kWindow; ++k) {
        a += w[static_cast<size_t>(k)] * hxx[r + k][c];
        b += w[static_cast<size_t>(k)] * hxy[r + k][c];
        d += w[static_cast<size_t>(k)] * hyy[r + k][c];
      }
      const double trace = a + d;
      g.r[r][c] = a * d - b * b - 0.04 * trace * trace;
    }
  return g;
}

// Newton step to the peak of the quadratic through the 3x3 responses around (cx, cy), or
// nothing when they hold no peak (a saddle, a ridge) or it lies outside them.
std::optional<cv::Point2d> quadraticPeak(const ResponseGrid& g, int cx, int cy) {
  const double r0 = g.at(cx, cy);
  const double dxx = g.at(cx + 1, cy) - 2 * r0 + g.at(cx - 1, cy), dyy = g.at(cx, cy + 1) - 2 * r0 + g.at(cx, cy - 1);
  const double dxy = (g.at(cx + 1, cy + 1) - g.at(cx - 1, cy + 1) - g.at(cx + 1, cy - 1) + g.at(cx - 1, cy - 1)) / 4;
  const double gx = (g.at(cx + 1, cy) - g.at(cx - 1, cy)) / 2, gy = (g.at(cx, cy + 1) - g.at(cx, cy - 1)) / 2;
  const double det = dxx * dyy - dxy * dxy;
  if (det <= 0 || dxx >= 0) return std::nullopt;
  const cv::Point2d step(-(dyy * gx - dxy * gy) / det, -(dxx * gy - dxy * gx) / det);
  if (std::abs(step.x) > 0.6 || std::abs(step.y) > 0.6) return std::nullopt;  // disagrees with the maximum
  return step;
}

}  // namespace

std::optional<cv::Point2f> refineCorner(const cv::Mat& img, cv::Point pixel) {
  CV_Assert(img.type() == CV_8UC1);
  if (pixel.x < kCornerReach || pixel.y < kCornerReach || pixel.x >= img.cols - kCornerReach ||
      pixel.y >= img.rows - kCornerReach)
    return std::nullopt;
  // Whole pixels first: climb the response to its local maximum near the FAST pixel.
  const int half = kMaxGrid + kWindow + 1;
  cv::Mat patch;
  img(cv::Rect(pixel.x - half, pixel.y - half, 2 * half + 1, 2 * half + 1)).convertTo(patch, CV_32F);
  const ResponseGrid coarse = harrisResponse(patch, kMaxGrid);
  int cx = 0, cy = 0;
  for (int step = 0; step <= kCornerClimb; ++step) {
    int bx = cx, by = cy;
    for (int oy = -1; oy <= 1; ++oy)
      for (int ox = -1; ox <= 1; ++ox) {
        const int nx = cx + ox, ny = cy + oy;
        if (std::abs(nx) <= kCornerClimb && std::abs(ny) <= kCornerClimb && coarse.at(nx, ny) > coarse.at(bx, by)) {
          bx = nx;
          by = ny;
        }
      }
    if (bx == cx && by == cy) break;
    cx = bx;
    cy = by;
  }
  if (coarse.at(cx, cy) <= 0) return std::nullopt;  // an edge or a flat patch, not a corner
  for (int oy = -1; oy <= 1; ++oy)
    for (int ox = -1; ox <= 1; ++ox)
      if ((ox || oy) && coarse.at(cx + ox, cy + oy) > coarse.at(cx, cy)) return std::nullopt;  // still rising at the rim
  // A quadratic through responses a pixel apart: pulled toward whole and half pixels where the
  // peak is flat-topped (up to 0.3 px on an axis-aligned checkerboard, whose response is a
  // plateau), within 0.1 px on the corners of textured surfaces.
  const auto peak = quadraticPeak(coarse, cx, cy);
  if (!peak) return std::nullopt;
  return cv::Point2f(static_cast<float>(pixel.x + cx + peak->x), static_cast<float>(pixel.y + cy + peak->y));
}

}  // namespace hiveslam::features
