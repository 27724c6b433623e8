#include "core/features/orb_extractor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>
#include <numeric>
#include <queue>

#include "core/features/brief_pattern.hpp"
#include "core/features/image_pyramid.hpp"
#include "core/features/corner_refinement.hpp"

namespace hiveslam::features {

namespace {

constexpr int kHalfPatch = 15;  // orientation patch radius
constexpr int kBorder = 19;     // pad so rotated BRIEF pairs and patches stay inside

// Keeps the strongest keypoint of each quadtree leaf, splitting the most populated leaf until
// there are `target` leaves or no leaf holds more than one keypoint. A node is a range of one
// shared index array, split in place by a stable counting sort: no allocation per node (the
// vector-per-node form spent most of its time in malloc). Stable, so each leaf lists its
// keypoints in input order and ties go to the first, as before.
std::vector<cv::KeyPoint> distribute(const std::vector<cv::KeyPoint>& kps, const cv::Rect2f& area, int target) {
  if (kps.empty() || target <= 0) return {};
  struct Node {
    cv::Rect2f rect;
    int begin = 0, end = 0;
    int size() const { return end - begin; }
  };
  thread_local std::vector<int> idx, tmp;
  thread_local std::vector<Node> heap, done;
  idx.resize(kps.size());
  tmp.resize(kps.size());
  heap.clear();
  done.clear();
  // Most populated first; among equals the heap's own order, as std::priority_queue keeps it.
  auto less = [](const Node& a, const Node& b) { return a.size() < b.size(); };
  auto push = [&](const Node& n) {
    if (n.size() == 1) done.push_back(n);
    else if (n.size() > 1) {
      heap.push_back(n);
      std::push_heap(heap.begin(), heap.end(), less);
    }
  };
  // Roughly square initial nodes across the image width, filled in input order.
  const int roots = std::max(1, static_cast<int>(std::lround(area.width / area.height)));
  const float w = area.width / roots;
  std::vector<int> root_of(kps.size()), count(static_cast<size_t>(roots) + 1, 0);
  for (size_t k = 0; k < kps.size(); ++k) {
    root_of[k] = std::clamp(static_cast<int>((kps[k].pt.x - area.x) / w), 0, roots - 1);
    ++count[static_cast<size_t>(root_of[k]) + 1];
  }
  for (int i = 0; i < roots; ++i) count[static_cast<size_t>(i) + 1] += count[static_cast<size_t>(i)];
  std::vector<int> fill(count.begin(), count.end() - 1);
  for (size_t k = 0; k < kps.size(); ++k) idx[static_cast<size_t>(fill[static_cast<size_t>(root_of[k])]++)] = static_cast<int>(k);
  for (int i = 0; i < roots; ++i)
    push({{area.x + i * w, area.y, w, area.height}, count[static_cast<size_t>(i)], count[static_cast<size_t>(i) + 1]});
  while (!heap.empty() && static_cast<int>(heap.size() + done.size()) < target) {
    std::pop_heap(heap.begin(), heap.end(), less);
    const Node n = heap.back();
    heap.pop_back();
    const float hw = n.rect.width / 2, hh = n.rect.height / 2;
    if (hw < 1.0f && hh < 1.0f) {  // cannot split further: points on one pixel
      done.push_back(n);
      continue;
    }
    int c_count[5] = {0, 0, 0, 0, 0};
    auto quadrant = [&](int k) {
      const auto& p = kps[static_cast<size_t>(k)].pt;
      return (p.x >= n.rect.x + hw ? 1 : 0) + (p.y >= n.rect.y + hh ? 2 : 0);
    };
    for (int j = n.begin; j < n.end; ++j) ++c_count[quadrant(idx[static_cast<size_t>(j)]) + 1];
    for (int c = 0; c < 4; ++c) c_count[c + 1] += c_count[c];
    int c_fill[4] = {n.begin + c_count[0], n.begin + c_count[1], n.begin + c_count[2], n.begin + c_count[3]};
    for (int j = n.begin; j < n.end; ++j) {
      const int k = idx[static_cast<size_t>(j)];
      tmp[static_cast<size_t>(c_fill[quadrant(k)]++)] = k;
    }
    std::copy(tmp.begin() + n.begin, tmp.begin() + n.end, idx.begin() + n.begin);
    for (int c = 0; c < 4; ++c)
      push({{n.rect.x + (c % 2) * hw, n.rect.y + (c / 2) * hh, hw, hh}, n.begin + c_count[c], n.begin + c_count[c + 1]});
  }
  // What is left in the heap, in the order std::priority_queue would have popped it.
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), less);
    done.push_back(heap.back());
    heap.pop_back();
  }
  std::vector<cv::KeyPoint> out;
  out.reserve(done.size());
  for (const auto& n : done) {
    int best = idx[static_cast<size_t>(n.begin)];
    for (int j = n.begin; j < n.end; ++j) {
      const int k = idx[static_cast<size_t>(j)];
      if (kps[static_cast<size_t>(k)].response > kps[static_cast<size_t>(best)].response) best = k;
    }
    out.push_back(kps[static_cast<size_t>(best)]);
  }
  if (static_cast<int>(out.size()) > target) {
    std::nth_element(out.begin(), out.begin() + target, out.end(),
                     [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
    out.resize(static_cast<size_t>(target));
  }
  return out;
}

// Per row of the orientation disc, 32 byte weights for the pixels dx = -15 .. 16: 1 inside the
// row's span (|dx| <= w) for the intensity sum, and dx + 15 there for the moment (unsigned, so
// one unsigned dot product does it; the 15 sum is taken off after).
struct DiscWeights {
  alignas(16) std::array<std::array<uchar, 32>, 2 * kHalfPatch + 1> in, shifted_dx;
};
const DiscWeights& discWeights() {
  static const DiscWeights w = [] {
    DiscWeights d{};
    for (int dy = -kHalfPatch; dy <= kHalfPatch; ++dy) {
      const int span = static_cast<int>(std::sqrt(kHalfPatch * kHalfPatch - dy * dy + 0.5));
      for (int j = 0; j < 32; ++j) {
        const int dx = j - kHalfPatch;
        const bool inside = std::abs(dx) <= span;
        d.in[static_cast<size_t>(dy + kHalfPatch)][static_cast<size_t>(j)] = inside ? 1 : 0;
        d.shifted_dx[static_cast<size_t>(dy + kHalfPatch)][static_cast<size_t>(j)] = inside ? static_cast<uchar>(dx + kHalfPatch) : 0;
      }
    }
    return d;
  }();
  return w;
}

// Orientation by the intensity centroid of a disc of radius kHalfPatch, in degrees. Integer
// moments, sixteen pixels at a time: exact (the same angles as a pixel-by-pixel sum), and
// several times faster than one pixel at a time.
float orientation(const cv::Mat& img, cv::Point2f pt) {
  const int cx = cvRound(pt.x), cy = cvRound(pt.y);
  const DiscWeights& w = discWeights();
  cv::v_uint32x4 moment = cv::v_setzero_u32(), total = cv::v_setzero_u32();
  cv::v_int32x4 m01 = cv::v_setzero_s32();
  for (int dy = -kHalfPatch; dy <= kHalfPatch; ++dy) {
    const uchar* row = img.ptr<uchar>(cy + dy) + cx - kHalfPatch;
    const auto& in = w.in[static_cast<size_t>(dy + kHalfPatch)];
    const auto& sdx = w.shifted_dx[static_cast<size_t>(dy + kHalfPatch)];
    const cv::v_uint8x16 a = cv::v_load(row), b = cv::v_load(row + 16);
    const cv::v_uint32x4 sum = cv::v_dotprod_expand(a, cv::v_load_aligned(in.data())) +
                               cv::v_dotprod_expand(b, cv::v_load_aligned(in.data() + 16));
    moment += cv::v_dotprod_expand(a, cv::v_load_aligned(sdx.data())) +
              cv::v_dotprod_expand(b, cv::v_load_aligned(sdx.data() + 16));
    total += sum;
    m01 += cv::v_reinterpret_as_s32(sum) * cv::v_setall_s32(dy);
  }
  const int m10 = static_cast<int>(cv::v_reduce_sum(moment)) - kHalfPatch * static_cast<int>(cv::v_reduce_sum(total));
  const int m01_sum = cv::v_reduce_sum(m01);
  float a = static_cast<float>(std::atan2(static_cast<double>(m01_sum), static_cast<double>(m10)) * 180.0 / CV_PI);
  return a < 0 ? a + 360.0f : a;
}

// The pattern's 512 points as floats, x and y apart, for four-at-a-time rotation.
struct PatternPoints {
  alignas(16) std::array<float, 512> x, y;
};
const PatternPoints& patternPoints() {
  static const PatternPoints pts = [] {
    PatternPoints p;
    const auto& pattern = briefPattern();
    for (size_t t = 0; t < 256; ++t) {
      p.x[2 * t] = static_cast<float>(pattern[t][0]);
      p.y[2 * t] = static_cast<float>(pattern[t][1]);
      p.x[2 * t + 1] = static_cast<float>(pattern[t][2]);
      p.y[2 * t + 1] = static_cast<float>(pattern[t][3]);
    }
    return p;
  }();
  return pts;
}

// The 256 tests of the rotated pattern, pixels read by their offset from the centre. The
// offsets are rotated four at a time with the same float operations and round-to-nearest as
// the one-at-a-time form (row cvRound(s x + c y), column cvRound(c x - s y)): bit-identical
// descriptors, which the vocabulary and every peer rely on.
void describe(const cv::Mat& smooth, const cv::KeyPoint& kp, cv::Point2f at, uchar* out) {
  const PatternPoints& pts = patternPoints();
  const float a = kp.angle * static_cast<float>(CV_PI / 180.0);
  const float c = std::cos(a), s = std::sin(a);
  const uchar* centre = smooth.ptr<uchar>(cvRound(at.y)) + cvRound(at.x);
  const int step = static_cast<int>(smooth.step1());
  alignas(16) std::array<int, 512> offset;
  const cv::v_float32x4 vc = cv::v_setall_f32(c), vs = cv::v_setall_f32(s);
  const cv::v_int32x4 vstep = cv::v_setall_s32(step);
  for (size_t j = 0; j < 512; j += 4) {
    const cv::v_float32x4 x = cv::v_load_aligned(&pts.x[j]), y = cv::v_load_aligned(&pts.y[j]);
    const cv::v_int32x4 row = cv::v_round(vs * x + vc * y), col = cv::v_round(vc * x - vs * y);
    cv::v_store_aligned(&offset[j], row * vstep + col);
  }
  // Pixels gathered first, then compared sixteen tests at a time: a compare-and-branch per
  // test mispredicted half the time (the outcomes are coin flips), which made this the
  // costliest part of extraction after FAST.
  alignas(16) std::array<uchar, 256> first, second;
  for (size_t t = 0; t < 256; ++t) {
    first[t] = centre[offset[2 * t]];
    second[t] = centre[offset[2 * t + 1]];
  }
  for (size_t j = 0; j < 256; j += 16) {
    const int bits = cv::v_signmask(cv::v_load_aligned(&first[j]) < cv::v_load_aligned(&second[j]));
    out[j / 8] = static_cast<uchar>(bits & 0xff);
    out[j / 8 + 1] = static_cast<uchar>(bits >> 8);
  }
}

}  // namespace

OrbExtractor::OrbExtractor(const OrbOptions& o) : options_(o) {
  scales_.resize(static_cast<size_t>(o.levels));
  scales_[0] = 1.0;
  for (int i = 1; i < o.levels; ++i) scales_[static_cast<size_t>(i)] = scales_[static_cast<size_t>(i - 1)] * o.scale_factor;
  // Features per level in proportion to the level's linear size (a geometric series).
  const double f = 1.0 / o.scale_factor;
  double n = o.features * (1 - f) / (1 - std::pow(f, o.levels));
  int sum = 0;
  for (int i = 0; i < o.levels - 1; ++i) {
    per_level_.push_back(static_cast<int>(std::lround(n)));
    sum += per_level_.back();
    n *= f;
  }
  per_level_.push_back(std::max(o.features - sum, 0));
}

namespace {

// Per-thread buffers reused from frame to frame: a frame allocates nothing big (the level
// images alone are 1.5 MB, and fresh allocations that size are fresh pages, zeroed by the
// kernel each frame).
struct Scratch {
  std::vector<cv::Mat> padded, smooth;
  std::vector<cv::KeyPoint> found, fast;
  std::vector<int> per_cell, first_pass;
};

// Fills the kBorder-wide frame of `padded` around its interior by BORDER_REFLECT_101, in place
// (what copyMakeBorder does, without copying the interior).
void reflectBorder(cv::Mat& padded) {
  const int W = padded.cols - 2 * kBorder, H = padded.rows - 2 * kBorder;
  for (int y = kBorder; y < kBorder + H; ++y) {
    uchar* row = padded.ptr<uchar>(y);
    for (int i = 1; i <= kBorder; ++i) {
      row[kBorder - i] = row[kBorder + i];
      row[kBorder + W - 1 + i] = row[kBorder + W - 1 - i];
    }
  }
  for (int i = 1; i <= kBorder; ++i) {
    padded.row(kBorder + i).copyTo(padded.row(kBorder - i));
    padded.row(kBorder + H - 1 - i).copyTo(padded.row(kBorder + H - 1 + i));
  }
}

}  // namespace

void OrbExtractor::extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors) const {
  CV_Assert(gray.type() == CV_8UC1);
  keypoints.clear();
  thread_local Scratch scratch;
  const size_t levels = static_cast<size_t>(options_.levels);
  if (scratch.padded.size() < levels) {
    scratch.padded.resize(levels);
    scratch.smooth.resize(levels);
  }
  // One descriptor block per frame, filled level by level: each level keeps at most its
  // per_level_ share. Fresh every call, so the rows handed out share memory with nothing.
  cv::Mat all_desc(std::max(std::accumulate(per_level_.begin(), per_level_.end(), 0), 1), 32, CV_8U);
  int n_desc = 0;
  for (int level = 0; level < options_.levels; ++level) {
    const double s = scales_[static_cast<size_t>(level)];
    const cv::Size size = pyramidLevelSize(gray.size(), s);
    if (size.width < 2 * kBorder || size.height < 2 * kBorder) break;
    cv::Mat& padded = scratch.padded[static_cast<size_t>(level)];
    padded.create(size.height + 2 * kBorder, size.width + 2 * kBorder, CV_8U);
    cv::Mat level_img = padded(cv::Rect(kBorder, kBorder, size.width, size.height));
    if (level == 0) gray.copyTo(level_img);
    else cv::resize(gray, level_img, size, 0, 0, cv::INTER_LINEAR);
    reflectBorder(padded);
    const double sx = static_cast<double>(gray.cols) / level_img.cols;
    const double sy = static_cast<double>(gray.rows) / level_img.rows;
    // FAST over the whole level at the first threshold (one call, no per-cell overhead), then
    // again at the lower threshold in the cells where it found nothing: the adaptive threshold.
    std::vector<cv::KeyPoint>& found = scratch.found;
    found.clear();
    const int W = level_img.cols, H = level_img.rows, cs = options_.cell_size;
    const int cols = (W + cs - 1) / cs, rows = (H + cs - 1) / cs;
    std::vector<int>& per_cell = scratch.per_cell;
    per_cell.assign(static_cast<size_t>(cols * rows), 0);
    auto keep = [&](cv::KeyPoint kp, float dx, float dy) {
      kp.pt.x += dx;
      kp.pt.y += dy;
      if (kp.pt.x < 0 || kp.pt.y < 0 || kp.pt.x > W - 1 || kp.pt.y > H - 1) return;
      ++per_cell[static_cast<size_t>(static_cast<int>(kp.pt.y) / cs * cols + static_cast<int>(kp.pt.x) / cs)];
      found.push_back(kp);
    };
    auto weak = [](cv::KeyPoint kp) {
      kp.class_id = kWeakCorner;
      return kp;
    };
    std::vector<cv::KeyPoint>& k = scratch.fast;
    // The whole level with a 3 px margin for the FAST circle, taken from the reflected border.
    const cv::Rect all(kBorder - 3, kBorder - 3, W + 6, H + 6);
    cv::FAST(padded(all), k, options_.fast_threshold, true);
    for (const auto& kp : k) keep(kp, -3.0f, -3.0f);
    scratch.first_pass = per_cell;
    const auto empty_cells = std::count(per_cell.begin(), per_cell.end(), 0);
    if (2 * empty_cells > static_cast<long>(per_cell.size())) {
      // Mostly bare (a dark or blank view): one pass at the lower threshold over the whole level,
      // keeping the corners of the empty cells, costs a fraction of a FAST call per cell.
      cv::FAST(padded(all), k, options_.min_fast_threshold, true);
      for (const auto& kp : k) {
        const int x = static_cast<int>(kp.pt.x - 3), y = static_cast<int>(kp.pt.y - 3);
        if (x < 0 || y < 0 || x >= W || y >= H) continue;
        if (scratch.first_pass[static_cast<size_t>(y / cs * cols + x / cs)] == 0) keep(weak(kp), -3.0f, -3.0f);
      }
    } else {
      for (int cy = 0; cy < rows; ++cy)
        for (int cx = 0; cx < cols; ++cx) {
          if (scratch.first_pass[static_cast<size_t>(cy * cols + cx)] > 0) continue;
          const int x0 = cx * cs, y0 = cy * cs;
          const cv::Rect cell(x0 + kBorder - 3, y0 + kBorder - 3, std::min(cs, W - x0) + 6, std::min(cs, H - y0) + 6);
          cv::FAST(padded(cell), k, options_.min_fast_threshold, true);
          for (const auto& kp : k) {
            // Only corners inside this cell: its neighbours already have their own.
            if (kp.pt.x - 3 < 0 || kp.pt.y - 3 < 0 || kp.pt.x - 3 >= std::min(cs, W - x0) || kp.pt.y - 3 >= std::min(cs, H - y0))
              continue;
            keep(weak(kp), static_cast<float>(x0 - 3), static_cast<float>(y0 - 3));
          }
        }
    }
    std::vector<cv::KeyPoint> kept = distribute(found, cv::Rect2f(0, 0, static_cast<float>(W), static_cast<float>(H)),
                                                per_level_[static_cast<size_t>(level)]);
    if (kept.empty()) continue;  // nothing to describe: no smoothing either
    cv::Mat& smooth = scratch.smooth[static_cast<size_t>(level)];
    cv::GaussianBlur(padded, smooth, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
    CV_Assert(n_desc + static_cast<int>(kept.size()) <= all_desc.rows);
    for (size_t i = 0; i < kept.size(); ++i) {
      cv::KeyPoint& kp = kept[i];
      cv::Point2f at(kp.pt.x + kBorder, kp.pt.y + kBorder);
      if (options_.subpixel) {
        const auto corner = refineCorner(padded, cv::Point(cvRound(at.x), cvRound(at.y)));
        // Inside the level, so the patches below stay inside the padding.
        if (corner && corner->x >= kBorder && corner->y >= kBorder && corner->x <= kBorder + W - 1 &&
            corner->y <= kBorder + H - 1) {
          at = *corner;
          kp.pt = at - cv::Point2f(kBorder, kBorder);
        }
      }
      // Orientation and descriptor at the pixel nearest the corner.
      const cv::Point2f pixel(static_cast<float>(cvRound(at.x)), static_cast<float>(cvRound(at.y)));
      kp.angle = orientation(padded, pixel);
      describe(smooth, kp, pixel, all_desc.ptr<uchar>(n_desc++));
      kp.octave = level;
      kp.size = static_cast<float>(31.0 * s);
      // resize maps pixel centres: level pixel x sits at (x + 0.5) sx - 0.5 on level 0, with
      // the level's true ratio sx = width0 / width (rounded sizes make it differ from s by up
      // to 0.3%: 0.4 px at the image edge, a zoom that differs per level and reads as motion
      // along the optical axis when a point changes level between views).
      kp.pt.x = static_cast<float>((kp.pt.x + 0.5) * sx - 0.5);
      kp.pt.y = static_cast<float>((kp.pt.y + 0.5) * sy - 0.5);
      keypoints.push_back(kp);
    }
  }
  if (n_desc == 0) descriptors.release();
  else descriptors = all_desc.rowRange(0, n_desc);
}

}  // namespace hiveslam::features
