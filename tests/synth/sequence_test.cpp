#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "common/error.hpp"
#include "common/look_alikes.hpp"
#include "io/open_dataset.hpp"
#include <opencv2/imgcodecs.hpp>
#include "synth/renderer.hpp"
#include "synth/sequence.hpp"
#include "synth/suite.hpp"
#include "synth/texture.hpp"
#include "temp_dir.hpp"
#include "warp_error.hpp"

namespace hiveslam::synth {
namespace {

// Ground truth consistent with the images: warp frame i into frame j through the rendered depth
// of i and the poses the dataset reader returns; the true poses make the images agree, a wrong
// pose does not.
TEST(Sequence, GroundTruthIsConsistentWithTheImages) {
  testing::TempDir dir;
  SequenceOptions o;
  // Long enough for realistic speeds (the path always spans the whole sequence), small images.
  o.width = 188;
  o.height = 120;
  o.frames = 200;
  o.seed = 5;
  o.distortion = true;
  writeSequence(o, dir.path());
  auto source = io::openDataset(dir.path());
  std::vector<cv::Mat> images;
  while (auto f = source->next()) images.push_back(f->image);
  const auto& gt = *source->groundTruth();
  const auto& cam = *source->camera().camera;

  const SequenceModel model = buildSequence(o);
  const RayTable rays(model.lens);
  auto warpError = [&](int i, int j, const Eigen::Isometry3d& T_wj) {
    cv::Mat radiance, depth;
    renderRadiance(model.scene, rays, gt.poses[static_cast<size_t>(i)], radiance, &depth);
    return synth::warpError<uchar>(images[static_cast<size_t>(i)], depth, images[static_cast<size_t>(j)],
                                   T_wj.inverse() * gt.poses[static_cast<size_t>(i)], cam);
  };
  const double right = warpError(100, 104, gt.poses[104]);
  const double wrong = warpError(100, 104, gt.poses[108]);
  EXPECT_LT(right, 8.0);  // noise (2 grey levels per image), interpolation and occlusions
  EXPECT_GT(wrong, 2.5 * right);
}

TEST(Sequence, DeterministicPerSeed) {
  SequenceOptions o;
  o.width = 96;
  o.height = 64;
  o.frames = 10;
  const SequenceModel a = buildSequence(o), b = buildSequence(o);
  const RayTable rays(a.lens);
  EXPECT_EQ(cv::norm(a.renderImage(4, rays), b.renderImage(4, rays), cv::NORM_INF), 0.0);
  o.seed = 2;
  const SequenceModel c = buildSequence(o);
  EXPECT_GT(cv::norm(a.renderImage(4, rays), c.renderImage(4, rays), cv::NORM_L1), 1000.0);
  EXPECT_GT((a.pose(5).translation() - c.pose(5).translation()).norm(), 1e-3);
}

// Motions a hand-held camera makes: bounded speeds, never through an obstacle.
class SuiteMotion : public ::testing::TestWithParam<std::string> {};

TEST_P(SuiteMotion, RealisticAndCollisionFree) {
  for (const auto& entry : suite("standard")) {
    if (entry.name != GetParam()) continue;
    const SequenceModel m = buildSequence(entry.options);
    const double dt = 1.0 / entry.options.fps;
    double max_speed = 0, max_turn = 0;
    int blank = 0;
    for (int f = 0; f < entry.options.frames; ++f) {
      const auto T = m.pose(f);
      EXPECT_TRUE(m.scene.isFree(T.translation(), 0.4)) << entry.name << " frame " << f;
      if (m.blank(f)) ++blank;
      if (f == 0) continue;
      const auto P = m.pose(f - 1);
      max_speed = std::max(max_speed, (T.translation() - P.translation()).norm() / dt);
      max_turn = std::max(max_turn, Eigen::AngleAxisd(P.linear().transpose() * T.linear()).angle() / dt);
    }
    EXPECT_LT(max_speed, 1.6) << entry.name;             // m/s, brisk walking at most
    EXPECT_LT(max_turn, 80.0 * M_PI / 180.0) << entry.name;  // rad/s
    const double blank_share = static_cast<double>(blank) / entry.options.frames;
    if (entry.name == "blackout") {
      EXPECT_GT(blank_share, 0.03);
      EXPECT_LT(blank_share, 0.08);
    } else {
      EXPECT_EQ(blank, 0) << entry.name;
    }
    if (entry.name == "figure8" || entry.name == "bigloop") {
      // A place seen at the start is seen again later from nearly the same pose.
      const auto start = m.pose(static_cast<int>(0.03 * entry.options.frames));
      double best = 1e9;
      for (int f = entry.options.frames / 2; f < entry.options.frames; ++f) {
        const auto T = m.pose(f);
        const double angle = Eigen::AngleAxisd(start.linear().transpose() * T.linear()).angle();
        if (angle < 0.35) best = std::min(best, (T.translation() - start.translation()).norm());
      }
      EXPECT_LT(best, 0.5) << entry.name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Standard, SuiteMotion, ::testing::Values("figure8", "blackout", "sweep", "bigloop"));

TEST(Sequence, TexturesFromPhotos) {
  testing::TempDir dir;
  std::filesystem::create_directories(dir / "photos");
  for (int i = 0; i < 2; ++i) {
    cv::Mat photo(120, 160, CV_8U);
    for (int y = 0; y < photo.rows; ++y)
      for (int x = 0; x < photo.cols; ++x) photo.at<uchar>(y, x) = ((x / 20 + y / 20 + i) % 2) ? 220 : 30;
    cv::imwrite((dir / "photos" / (std::to_string(i) + ".png")).string(), photo);
  }
  SequenceOptions o;
  o.width = 96;
  o.height = 64;
  o.frames = 4;
  o.noise = 0;
  o.textures = (dir / "photos").string();
  const SequenceModel m = buildSequence(o);
  const cv::Mat img = m.renderImage(2, RayTable(m.lens));
  cv::Scalar mean, stddev;
  cv::meanStdDev(img, mean, stddev);
  EXPECT_GT(stddev[0], 10.0);  // textured, not blank
  o.textures = (dir / "missing").string();
  EXPECT_THROW(buildSequence(o), InputError);
}

// A calibration chessboard repeats one corner everywhere; smoothed noise, like fur or foliage,
// does not. The realistic suite's default leaves the first out of its textures.
TEST(Sequence, PhotosThatRepeatThemselvesAreLeftOut) {
  testing::TempDir dir;
  std::filesystem::create_directories(dir / "photos");
  cv::Mat board(480, 640, CV_8U);
  for (int y = 0; y < board.rows; ++y)
    for (int x = 0; x < board.cols; ++x) board.at<uchar>(y, x) = ((x / 40 + y / 40) % 2) ? 220 : 30;
  cv::Mat noise(480, 640, CV_32F), blobs;
  cv::RNG(3).fill(noise, cv::RNG::NORMAL, 0, 1);
  cv::GaussianBlur(noise, noise, {0, 0}, 2.0);
  cv::normalize(noise, blobs, 0, 255, cv::NORM_MINMAX, CV_8U);
  EXPECT_GT(lookAlikeShare(board), 0.8);
  EXPECT_LT(lookAlikeShare(blobs), 0.2);
  cv::imwrite((dir / "photos" / "board.png").string(), board);
  cv::imwrite((dir / "photos" / "blobs.png").string(), blobs);
  EXPECT_EQ(loadPhotos((dir / "photos").string()).size(), 2u);
  const auto kept = loadPhotos((dir / "photos").string(), 0.35);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(cv::norm(kept[0], blobs, cv::NORM_INF), 0);
  std::filesystem::remove(dir / "photos" / "blobs.png");
  EXPECT_THROW(loadPhotos((dir / "photos").string(), 0.35), InputError);
}

TEST(Sequence, WritesEurocLayout) {
  testing::TempDir dir;
  SequenceOptions o;
  o.width = 64;
  o.height = 48;
  o.frames = 3;
  o.trajectory = "sweep";
  const auto s = writeSequence(o, dir.path());
  EXPECT_EQ(s.frames, 3);
  for (const char* f : {"mav0/cam0/data.csv", "mav0/cam0/sensor.yaml", "mav0/state_groundtruth_estimate0/data.csv",
                        "sequence.json", "mav0/cam0/data/1000000000000.png", "mav0/cam0/data/1000050000000.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
}

TEST(Sequence, ItsOptionsReadBackRebuildTheSameScene) {
  testing::TempDir dir;
  SequenceOptions o;
  o.width = 64;
  o.height = 48;
  o.frames = 3;
  o.trajectory = "blackout";
  o.seed = 7;
  o.distortion = true;
  o.exposure_changes = true;
  o.noise = 1.5;
  writeSequence(o, dir.path());
  const SequenceOptions back = readSequenceOptions(dir.path());
  EXPECT_EQ(back.trajectory, o.trajectory);
  EXPECT_EQ(back.seed, o.seed);
  EXPECT_EQ(back.frames, o.frames);
  EXPECT_EQ(back.width, o.width);
  EXPECT_EQ(back.height, o.height);
  EXPECT_EQ(back.distortion, o.distortion);
  EXPECT_EQ(back.exposure_changes, o.exposure_changes);
  EXPECT_DOUBLE_EQ(back.noise, o.noise);
  EXPECT_TRUE(back.textures.empty());
  const SequenceModel a = buildSequence(o), b = buildSequence(back);
  ASSERT_EQ(a.scene.boxes.size(), b.scene.boxes.size());
  for (size_t i = 0; i < a.scene.boxes.size(); ++i) EXPECT_EQ(a.scene.boxes[i].center, b.scene.boxes[i].center);
  EXPECT_TRUE(a.pose(2).isApprox(b.pose(2)));

  EXPECT_THROW(readSequenceOptions(dir / "mav0"), InputError);  // no sequence.json there
  std::ofstream(dir / "sequence.json") << "{\"trajectory\": \"sweep\"}";
  EXPECT_THROW(readSequenceOptions(dir.path()), InputError);  // not all of what synth writes
}

}  // namespace
}  // namespace hiveslam::synth
