#include "core/features/corner_refinement.hpp"

#include <array>
#include <cmath>

namespace hiveslam::features {

namespace {

constexpr int kWindow = 3;                // Gaussian window radius
constexpr int kGrid = kCornerClimb + 1;   // response grid radius: the climb and the fit
constexpr int kGridSide = 2 * kGrid + 1;
constexpr int kTensor = kGrid + kWindow;  // radius of the gradient products the window reads
constexpr int kTensorSide = 2 * kTensor + 1;
static_assert(kTensor + 1 <= kCornerReach, "the Sobel of the window's rim must be inside the reach");

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

// The Harris response on the kGridSide^2 pixels around `centre`: Sobel gradients read straight
// from the 8-bit image (no patch copied per corner: this runs for every keypoint of every
// frame), their products, a separable Gaussian window.
struct ResponseGrid {
  double r[kGridSide][kGridSide];
  double at(int dx, int dy) const { return r[dy + kGrid][dx + kGrid]; }
};
ResponseGrid harrisResponse(const cv::Mat& img, cv::Point centre) {
  float xx[kTensorSide][kTensorSide], xy[kTensorSide][kTensorSide], yy[kTensorSide][kTensorSide];
  for (int r = 0; r < kTensorSide; ++r) {
    const int y = centre.y - kTensor + r, x0 = centre.x - kTensor;
    const uchar* up = img.ptr<uchar>(y - 1) + x0;
    const uchar* mid = img.ptr<uchar>(y) + x0;
    const uchar* down = img.ptr<uchar>(y + 1) + x0;
    for (int c = 0; c < kTensorSide; ++c) {
      const float gx = static_cast<float>((up[c + 1] - up[c - 1]) + 2 * (mid[c + 1] - mid[c - 1]) + (down[c + 1] - down[c - 1]));
      const float gy = static_cast<float>((down[c - 1] - up[c - 1]) + 2 * (down[c] - up[c]) + (down[c + 1] - up[c + 1]));
      xx[r][c] = gx * gx;
      xy[r][c] = gx * gy;
      yy[r][c] = gy * gy;
    }
  }
  const auto& w = windowWeights();
  float hxx[kTensorSide][kGridSide], hxy[kTensorSide][kGridSide], hyy[kTensorSide][kGridSide];
  for (int r = 0; r < kTensorSide; ++r)
    for (int c = 0; c < kGridSide; ++c) {
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
  for (int r = 0; r < kGridSide; ++r)
    for (int c = 0; c < kGridSide; ++c) {
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
  const ResponseGrid coarse = harrisResponse(img, pixel);
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
