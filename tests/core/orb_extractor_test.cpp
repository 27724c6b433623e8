#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "common/look_alikes.hpp"
#include "core/features/brief_pattern.hpp"
#include "core/features/hamming.hpp"
#include "core/features/orb_extractor.hpp"
#include "synth/renderer.hpp"
#include "synth/sequence.hpp"
#include "core/rendered_sweep.hpp"

namespace hiveslam::features {
namespace {

cv::Mat renderedImage() {
  synth::SequenceOptions o;
  o.frames = 400;
  const auto model = synth::buildSequence(o);
  return model.renderImage(150, synth::RayTable(model.lens));
}

struct Extracted {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};
Extracted extractDefault(const cv::Mat& img) {
  Extracted e;
  OrbExtractor().extract(img, e.keypoints, e.descriptors);
  return e;
}

TEST(OrbExtractor, FindsTheRequestedNumberSpreadOverTheImage) {
  const cv::Mat img = renderedImage();
  const auto [kps, desc] = extractDefault(img);
  EXPECT_GE(kps.size(), 900u);
  EXPECT_LE(kps.size(), 1000u);
  EXPECT_EQ(desc.rows, static_cast<int>(kps.size()));
  EXPECT_EQ(desc.cols, 32);
  // Every cell of a 4x4 grid over the image holds features: the quadtree spreads them.
  int cells[16] = {};
  for (const auto& k : kps) {
    ASSERT_GE(k.pt.x, 0);
    ASSERT_LT(k.pt.x, img.cols);
    ++cells[std::min(3, static_cast<int>(k.pt.y * 4 / img.rows)) * 4 + std::min(3, static_cast<int>(k.pt.x * 4 / img.cols))];
  }
  for (int c : cells) EXPECT_GT(c, 20);
  // Several pyramid levels take part.
  std::set<int> octaves;
  for (const auto& k : kps) octaves.insert(k.octave);
  EXPECT_GE(octaves.size(), 6u);
}

// Rotating the image must rotate keypoint angles by the same amount and keep descriptors
// close enough to match: the "r" of rBRIEF.
TEST(OrbExtractor, DescriptorsAndAnglesFollowImageRotation) {
  const cv::Mat img = renderedImage();
  const double angle = 30.0;
  const cv::Point2f centre(img.cols / 2.0f, img.rows / 2.0f);
  const cv::Mat M = cv::getRotationMatrix2D(centre, angle, 1.0);
  cv::Mat rotated;
  cv::warpAffine(img, rotated, M, img.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  OrbExtractor orb;
  std::vector<cv::KeyPoint> k1, k2;
  cv::Mat d1, d2;
  orb.extract(img, k1, d1);
  orb.extract(rotated, k2, d2);
  int tested = 0, correct = 0, angle_ok = 0;
  for (size_t i = 0; i < k1.size(); ++i) {
    const cv::Point2f p = k1[i].pt;
    const cv::Point2f q(static_cast<float>(M.at<double>(0, 0) * p.x + M.at<double>(0, 1) * p.y + M.at<double>(0, 2)),
                        static_cast<float>(M.at<double>(1, 0) * p.x + M.at<double>(1, 1) * p.y + M.at<double>(1, 2)));
    if (cv::norm(q - centre) > 180) continue;  // stay clear of the black corners
    ++tested;
    int best = 1 << 30;
    size_t best_j = 0;
    for (size_t j = 0; j < k2.size(); ++j) {
      const int d = hamming(d1.ptr<uchar>(static_cast<int>(i)), d2.ptr<uchar>(static_cast<int>(j)));
      if (d < best) {
        best = d;
        best_j = j;
      }
    }
    if (cv::norm(k2[best_j].pt - q) < 3.0 * orb.scale(k1[i].octave)) {
      ++correct;
      // OpenCV's rotation is counter-clockwise in the image, which lowers our angles.
      double da = std::fmod(k1[i].angle - k2[best_j].angle + 720.0, 360.0);
      if (std::abs(da - angle) < 10.0) ++angle_ok;
    }
  }
  ASSERT_GT(tested, 200);
  EXPECT_GT(static_cast<double>(correct) / tested, 0.45) << correct << "/" << tested;
  EXPECT_GT(static_cast<double>(angle_ok) / std::max(correct, 1), 0.85);
}

// Level-0 descriptors against the definition, one test at a time in plain code: the rotated
// pattern over the 7x7 (sigma 2) smoothed image, bit t of the descriptor set when the first
// point of pair t is darker. The vocabulary and every peer rely on these exact bits.
TEST(OrbExtractor, DescriptorsAreTheRotatedBriefTestsBitForBit) {
  const cv::Mat img = renderedImage();
  const auto [kps, desc] = extractDefault(img);
  cv::Mat padded, smooth;
  cv::copyMakeBorder(img, padded, 19, 19, 19, 19, cv::BORDER_REFLECT_101);
  cv::GaussianBlur(padded, smooth, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
  int checked = 0;
  for (size_t i = 0; i < kps.size(); ++i) {
    if (kps[i].octave != 0) continue;
    const float a = kps[i].angle * static_cast<float>(CV_PI / 180.0);
    const float c = std::cos(a), s = std::sin(a);
    const int cx = cvRound(kps[i].pt.x) + 19, cy = cvRound(kps[i].pt.y) + 19;
    const auto& pattern = briefPattern();
    for (size_t t = 0; t < 256; ++t) {
      const auto at = [&](int x, int y) {
        const float fx = static_cast<float>(x), fy = static_cast<float>(y);
        return smooth.at<uchar>(cy + cvRound(s * fx + c * fy), cx + cvRound(c * fx - s * fy));
      };
      const bool bit = at(pattern[t][0], pattern[t][1]) < at(pattern[t][2], pattern[t][3]);
      const bool got = (desc.at<uchar>(static_cast<int>(i), static_cast<int>(t / 8)) >> (t % 8)) & 1;
      ASSERT_EQ(got, bit) << "keypoint " << i << " test " << t;
    }
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

// Where a corner is measured, against where it truly is: the corners of one rendered view,
// lifted to 3D by the rendered depth and moved into a second view by the true motion, against
// the same corners found there (same level, similar descriptor, nearest). Per matched pair, in
// level pixels; both views' errors are in it.
std::vector<double> pairErrors(bool subpixel, double& rms_per_coordinate) {
  const auto model = testing::renderedSweep();
  const synth::RayTable rays(model.lens);
  OrbOptions options;
  options.subpixel = subpixel;
  const OrbExtractor orb(options);
  const int a = 300, b = 305;
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db, radiance, depth;
  orb.extract(model.renderImage(a, rays), ka, da);
  orb.extract(model.renderImage(b, rays), kb, db);
  synth::renderRadiance(model.scene, rays, model.pose(a), radiance, &depth);
  const Eigen::Isometry3d T_ba = model.pose(b).inverse() * model.pose(a);
  const auto& lens = model.lens;
  std::vector<double> errors;
  double sum2 = 0;
  for (size_t i = 0; i < ka.size(); ++i) {
    const cv::Point2f p = ka[i].pt;
    const int x = static_cast<int>(p.x), y = static_cast<int>(p.y);
    if (x < 3 || y < 3 || x >= depth.cols - 4 || y >= depth.rows - 4) continue;
    cv::Mat around = depth(cv::Rect(x - 3, y - 3, 8, 8));
    double lo = 0, hi = 0;
    cv::minMaxLoc(around, &lo, &hi);
    if (hi - lo > 0.05 * lo) continue;  // an occluding edge: no one depth for the corner
    cv::Mat d;
    cv::getRectSubPix(depth, {1, 1}, p, d);
    const double z = d.at<float>(0, 0);
    const Eigen::Vector3d X = T_ba * Eigen::Vector3d((p.x - lens.cx) / lens.fx * z, (p.y - lens.cy) / lens.fy * z, z);
    const double u = lens.fx * X.x() / X.z() + lens.cx, v = lens.fy * X.y() / X.z() + lens.cy;
    const double level = orb.scale(ka[i].octave);
    double best = 2.0 * level;
    for (size_t j = 0; j < kb.size(); ++j) {
      const double r = std::hypot(kb[j].pt.x - u, kb[j].pt.y - v);
      if (kb[j].octave != ka[i].octave || r >= best) continue;
      if (hamming(da.ptr<uchar>(static_cast<int>(i)), db.ptr<uchar>(static_cast<int>(j))) > 50) continue;
      best = r;
    }
    if (best >= 2.0 * level) continue;
    errors.push_back(best / level);
    sum2 += errors.back() * errors.back();
  }
  rms_per_coordinate = std::sqrt(sum2 / (2.0 * std::max<size_t>(errors.size(), 1)));
  std::sort(errors.begin(), errors.end());
  return errors;
}

// FAST pixels carry up to half a pixel of rounding in each view; refined corners land within a
// tenth of a pixel of where the true motion puts them.
TEST(OrbExtractor, SubPixelCornersMeetTheirTrueProjections) {
  double rms_pixel = 0, rms_sub = 0;
  const auto pixel = pairErrors(false, rms_pixel);
  const auto sub = pairErrors(true, rms_sub);
  ASSERT_GT(pixel.size(), 300u);
  ASSERT_GT(sub.size(), 300u);
  const double median_pixel = pixel[pixel.size() / 2], median_sub = sub[sub.size() / 2];
  RecordProperty("median_pixel", std::to_string(median_pixel));
  RecordProperty("median_subpixel", std::to_string(median_sub));
  EXPECT_GT(median_pixel, 0.35);  // the rounding the test must see to mean anything
  EXPECT_LT(median_sub, 0.15);
  EXPECT_LT(rms_sub, 0.6 * rms_pixel) << rms_sub << " vs " << rms_pixel;
}

// The corners of a chessboard are one corner repeated: each has a twin a few bits away. The
// corners of a rendered room (figure8's procedural texture) mostly do not. Keypoints nearer
// than 16 pixels (one corner at two pyramid levels) are not each other's look-alikes.
TEST(LookAlikes, ARepeatedPatternHasTwinsARandomOneDoesNot) {
  cv::Mat board(480, 640, CV_8U);
  for (int y = 0; y < board.rows; ++y)
    for (int x = 0; x < board.cols; ++x) board.at<uchar>(y, x) = ((x / 40 + y / 40) % 2) ? 220 : 30;
  cv::GaussianBlur(board, board, {0, 0}, 1.0);
  const Extracted b = extractDefault(board), r = extractDefault(renderedImage());
  auto median = [](std::vector<uint8_t> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return static_cast<int>(v[v.size() / 2]);
  };
  const auto board_twins = lookAlikeDistances(b.keypoints, b.descriptors);
  const auto room_twins = lookAlikeDistances(r.keypoints, r.descriptors);
  ASSERT_EQ(board_twins.size(), b.keypoints.size());
  ASSERT_GT(b.keypoints.size(), 50u);
  EXPECT_LT(median(board_twins), 10) << median(board_twins);
  EXPECT_GT(median(room_twins), 25) << median(room_twins);

  std::vector<cv::KeyPoint> two{cv::KeyPoint(100, 100, 31), cv::KeyPoint(110, 100, 31)};
  cv::Mat same(2, 32, CV_8U, cv::Scalar(7));
  EXPECT_EQ(lookAlikeDistances(two, same), (std::vector<uint8_t>{255, 255}));  // 10 px apart
  two[1].pt.x = 130;
  EXPECT_EQ(lookAlikeDistances(two, same), (std::vector<uint8_t>{0, 0}));
}

// A corner found only at the lower threshold is flagged weak: on faint squares beside strong
// ones, the weak corners are all on the faint half and the strong ones all on the other.
TEST(OrbExtractor, FlagsTheCornersFoundOnlyAtTheLowerThreshold) {
  cv::Mat img(480, 640, CV_8U);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const bool square = x % 32 < 12 && y % 32 < 12;
      img.at<uchar>(y, x) = x < 320 ? (square ? 200 : 40) : (square ? 134 : 120);  // contrast 160 | 14
    }
  cv::GaussianBlur(img, img, {0, 0}, 0.7);
  const auto [kps, desc] = extractDefault(img);
  int weak_left = 0, weak_right = 0, strong_right = 0;
  for (const auto& k : kps) {
    if (isWeakCorner(k)) (k.pt.x < 300 ? weak_left : weak_right)++;
    else strong_right += k.pt.x > 340;
  }
  EXPECT_EQ(weak_left, 0);
  EXPECT_GT(weak_right, 50);
  EXPECT_EQ(strong_right, 0);
}

TEST(OrbExtractor, DeterministicAndCheapOnBlankImages) {
  const cv::Mat img = renderedImage();
  OrbExtractor orb;
  std::vector<cv::KeyPoint> a, b;
  cv::Mat da, db;
  orb.extract(img, a, da);
  orb.extract(img, b, db);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(da, db, cv::NORM_HAMMING), 0.0);
  std::vector<cv::KeyPoint> none;
  cv::Mat nd;
  orb.extract(cv::Mat(480, 752, CV_8U, cv::Scalar(0)), none, nd);
  EXPECT_TRUE(none.empty());
}

TEST(Hamming, CountsDifferingBits) {
  unsigned char a[32] = {}, b[32] = {};
  b[0] = 0xff;
  b[31] = 0x01;
  EXPECT_EQ(hamming(a, b), 9);
  EXPECT_EQ(hamming(a, a), 0);
}

}  // namespace
}  // namespace hiveslam::features
