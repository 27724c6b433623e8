#include "core/features/corner_refinement.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <opencv2/core/hal/intrin.hpp>

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

// The Harris response on the kGridSide^2 pixels around `centre`: Sobel gradients of the
// window's pixels, their products, a separable Gaussian window. This runs for every keypoint of
// every frame (a tenth of extraction), so it works four columns at a time: the same float
// products and the same order of additions as one column at a time (no fused multiply-add), so
// the responses, and the corners, are bit-identical to the scalar form.
struct ResponseGrid {
  double r[kGridSide][kGridSide];
  double at(int dx, int dy) const { return r[dy + kGrid][dx + kGrid]; }
};
constexpr int kLanes = 16;  // columns per row of the working arrays: kTensorSide rounded up
static_assert(kTensorSide <= kLanes && kGridSide + 2 * kWindow + 1 <= kLanes);
ResponseGrid harrisResponse(const cv::Mat& img, cv::Point centre) {
  // The pixels the gradients read, copied into rows wide enough for whole vector loads (the
  // image itself need only hold kCornerReach pixels around the corner).
  constexpr int kPixelRows = kTensorSide + 2;
  alignas(16) uchar px[kPixelRows][kLanes + 2] = {};
  for (int r = 0; r < kPixelRows; ++r)
    std::memcpy(px[r], img.ptr<uchar>(centre.y - kTensor - 1 + r) + centre.x - kTensor - 1, kTensorSide + 2);
  alignas(16) float xx[kTensorSide][kLanes], xy[kTensorSide][kLanes], yy[kTensorSide][kLanes];
  for (int r = 0; r < kTensorSide; ++r) {
    // 16-bit gradients (at most 4 x 255 in magnitude), widened to 32 bits and then to float.
    auto row16 = [&](int rr, int off, cv::v_int16x8& lo, cv::v_int16x8& hi) {
      cv::v_uint16x8 a, b;
      cv::v_expand(cv::v_load(px[rr] + off), a, b);
      lo = cv::v_reinterpret_as_s16(a);
      hi = cv::v_reinterpret_as_s16(b);
    };
    cv::v_int16x8 ul, uh, uml, umh, url, urh, ml, mh, mrl, mrh, dl, dh, dml, dmh, drl, drh;
    row16(r, 0, ul, uh);
    row16(r, 1, uml, umh);
    row16(r, 2, url, urh);
    row16(r + 1, 0, ml, mh);
    row16(r + 1, 2, mrl, mrh);
    row16(r + 2, 0, dl, dh);
    row16(r + 2, 1, dml, dmh);
    row16(r + 2, 2, drl, drh);
    const cv::v_int16x8 gx[2] = {(url - ul) + (mrl - ml) + (mrl - ml) + (drl - dl), (urh - uh) + (mrh - mh) + (mrh - mh) + (drh - dh)};
    const cv::v_int16x8 gy[2] = {(dl - ul) + (dml - uml) + (dml - uml) + (drl - url), (dh - uh) + (dmh - umh) + (dmh - umh) + (drh - urh)};
    for (int half = 0; half < 2; ++half) {
      cv::v_int32x4 x0, x1, y0, y1;
      cv::v_expand(gx[half], x0, x1);
      cv::v_expand(gy[half], y0, y1);
      const cv::v_float32x4 fx[2] = {cv::v_cvt_f32(x0), cv::v_cvt_f32(x1)}, fy[2] = {cv::v_cvt_f32(y0), cv::v_cvt_f32(y1)};
      for (int q = 0; q < 2; ++q) {
        const int c = 8 * half + 4 * q;
        cv::v_store_aligned(&xx[r][c], fx[q] * fx[q]);
        cv::v_store_aligned(&xy[r][c], fx[q] * fy[q]);
        cv::v_store_aligned(&yy[r][c], fy[q] * fy[q]);
      }
    }
  }
  const auto& w = windowWeights();
  // Horizontal window: columns 0-7 of each row (0-6 used), each sum from zero in tap order.
  alignas(16) float hxx[kTensorSide][8], hxy[kTensorSide][8], hyy[kTensorSide][8];
  for (int r = 0; r < kTensorSide; ++r)
    for (int c = 0; c < 8; c += 4) {
      cv::v_float32x4 a = cv::v_setzero_f32(), b = a, d = a;
      for (int k = 0; k <= 2 * kWindow; ++k) {
        const cv::v_float32x4 wk = cv::v_setall_f32(w[static_cast<size_t>(k)]);
        a = a + wk * cv::v_load(&xx[r][c + k]);
        b = b + wk * cv::v_load(&xy[r][c + k]);
        d = d + wk * cv::v_load(&yy[r][c + k]);
      }
      cv::v_store_aligned(&hxx[r][c], a);
      cv::v_store_aligned(&hxy[r][c], b);
      cv::v_store_aligned(&hyy[r][c], d);
    }
  // Vertical window: float products summed in double, as before, two columns at a time.
  ResponseGrid g;
  for (int r = 0; r < kGridSide; ++r) {
    alignas(16) double a[8], b[8], d[8];
    for (int c = 0; c < 8; c += 4) {
      cv::v_float64x2 a0 = cv::v_setzero_f64(), a1 = a0, b0 = a0, b1 = a0, d0 = a0, d1 = a0;
      for (int k = 0; k <= 2 * kWindow; ++k) {
        const cv::v_float32x4 wk = cv::v_setall_f32(w[static_cast<size_t>(k)]);
        const cv::v_float32x4 pa = wk * cv::v_load_aligned(&hxx[r + k][c]), pb = wk * cv::v_load_aligned(&hxy[r + k][c]),
                              pd = wk * cv::v_load_aligned(&hyy[r + k][c]);
        a0 = a0 + cv::v_cvt_f64(pa);
        a1 = a1 + cv::v_cvt_f64_high(pa);
        b0 = b0 + cv::v_cvt_f64(pb);
        b1 = b1 + cv::v_cvt_f64_high(pb);
        d0 = d0 + cv::v_cvt_f64(pd);
        d1 = d1 + cv::v_cvt_f64_high(pd);
      }
      cv::v_store_aligned(&a[c], a0);
      cv::v_store_aligned(&a[c + 2], a1);
      cv::v_store_aligned(&b[c], b0);
      cv::v_store_aligned(&b[c + 2], b1);
      cv::v_store_aligned(&d[c], d0);
      cv::v_store_aligned(&d[c + 2], d1);
    }
    for (int c = 0; c < kGridSide; ++c) {
      const double trace = a[c] + d[c];
      g.r[r][c] = a[c] * d[c] - b[c] * b[c] - 0.04 * trace * trace;
    }
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
