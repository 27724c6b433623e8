#include <gtest/gtest.h>

#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/error.hpp"
#include "io/open_dataset.hpp"
#include "io/repeated_source.hpp"
#include "io/trajectory_io.hpp"
#include "synth/sequence.hpp"
#include "temp_dir.hpp"

namespace hiveslam::io {
namespace {

namespace fs = std::filesystem;

synth::SequenceOptions tiny(int frames = 6) {
  synth::SequenceOptions o;
  o.width = 160;
  o.height = 120;
  o.frames = frames;
  o.seed = 11;
  return o;
}

void writeSettings(const fs::path& file, int w, int h) {
  std::ofstream(file) << "camera:\n  model: pinhole\n  width: " << w << "\n  height: " << h
                      << "\n  intrinsics: [100, 100, " << w / 2 << ", " << h / 2 << "]\n  fps: 10\n";
}

cv::Mat pattern(int w, int h, int seed) {
  cv::Mat m(h, w, CV_8U);
  cv::randu(m, seed, 255);
  return m;
}

TEST(EurocDataset, ReadsASyntheticSequenceWithGroundTruth) {
  testing::TempDir dir;
  synth::writeSequence(tiny(), dir.path());
  auto source = openDataset(dir.path());
  EXPECT_NE(source->describe().find("EuRoC"), std::string::npos);
  ASSERT_EQ(source->size(), 6u);
  EXPECT_EQ(source->camera().camera->width(), 160);
  EXPECT_DOUBLE_EQ(source->camera().fps, 20.0);
  ASSERT_TRUE(source->groundTruth());
  EXPECT_EQ(source->groundTruth()->size(), 6u);
  int n = 0;
  double last = -1;
  while (auto f = source->next()) {
    EXPECT_EQ(f->image.type(), CV_8U);
    EXPECT_EQ(f->image.size(), cv::Size(160, 120));
    EXPECT_GT(f->timestamp, last);
    EXPECT_NEAR(f->timestamp, source->groundTruth()->stamps[static_cast<size_t>(n)], 1e-9);
    last = f->timestamp;
    ++n;
  }
  EXPECT_EQ(n, 6);
  // The mav0 folder itself is accepted too.
  EXPECT_EQ(openDataset(dir / "mav0")->size(), 6u);
}

// --repeat: the passes follow each other by the sequence's period (6 frames at 20 Hz: 0.3 s),
// as one stream with increasing stamps and indices, and the ground truth repeats with them.
TEST(RepeatedSource, PlaysTheSequenceAgainAfterItsPeriod) {
  testing::TempDir dir;
  synth::writeSequence(tiny(), dir.path());
  RepeatedSource source([&] { return openDataset(dir.path()); }, 3);
  ASSERT_EQ(source.size(), 18u);
  ASSERT_TRUE(source.groundTruth());
  ASSERT_EQ(source.groundTruth()->size(), 18u);
  std::vector<double> stamps;
  while (auto f = source.next()) {
    EXPECT_EQ(f->index, stamps.size());
    EXPECT_NEAR(f->timestamp, source.groundTruth()->stamps[stamps.size()], 1e-9);
    stamps.push_back(f->timestamp);
  }
  ASSERT_EQ(stamps.size(), 18u);
  EXPECT_NEAR(stamps[6] - stamps[0], 0.3, 1e-9);
  EXPECT_NEAR(stamps[12] - stamps[6], 0.3, 1e-9);
  for (size_t i = 1; i < stamps.size(); ++i) EXPECT_NEAR(stamps[i] - stamps[i - 1], 0.05, 1e-9) << i;
  EXPECT_TRUE(source.groundTruth()->poses[7].isApprox(source.groundTruth()->poses[1]));
}

TEST(RepeatedSource, NeedsOnePassAtLeast) {
  testing::TempDir dir;
  synth::writeSequence(tiny(), dir.path());
  EXPECT_THROW(RepeatedSource([&] { return openDataset(dir.path()); }, 0), InputError);
}

TEST(EurocDataset, ASettingsFileWithoutCameraKeepsTheDatasetCalibration) {
  testing::TempDir dir;
  synth::writeSequence(tiny(2), dir.path());
  std::ofstream(dir / "slam_only.yaml") << "slam:\n  local_ba_iterations: 20\n";
  EXPECT_EQ(openDataset(dir.path(), {dir / "slam_only.yaml", std::nullopt})->camera().camera->width(), 160);
  // A camera section still replaces it.
  writeSettings(dir / "settings.yaml", 64, 48);
  EXPECT_EQ(openDataset(dir.path(), {dir / "settings.yaml", std::nullopt})->camera().camera->width(), 64);
}

TEST(EurocDataset, AppliesTheBodyToCameraTransformToGroundTruth) {
  testing::TempDir dir;
  synth::writeSequence(tiny(2), dir.path());
  const fs::path yaml = dir.path() / "mav0/cam0/sensor.yaml";
  std::ifstream in(yaml);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  // T_BS = a translation of 1 m along the camera x axis.
  const std::string identity = "data: [1.0, 0.0, 0.0, 0.0,";
  text.replace(text.find(identity), identity.size(), "data: [1.0, 0.0, 0.0, 1.0,");
  std::ofstream(yaml) << text;
  auto source = openDataset(dir.path());
  const auto body = readTrajectory(dir.path() / "mav0/state_groundtruth_estimate0/data.csv");
  const auto& cam = *source->groundTruth();
  const Eigen::Vector3d expected = body.poses[0] * Eigen::Vector3d(1, 0, 0);
  EXPECT_LT((cam.poses[0].translation() - expected).norm(), 1e-9);
}

TEST(TumRgbdDataset, ReadsRgbListAndGroundTruth) {
  testing::TempDir dir;
  fs::create_directories(dir / "rgb");
  std::ofstream list(dir / "rgb.txt");
  std::ofstream gt(dir / "groundtruth.txt");
  list << std::setprecision(17) << "# timestamp filename\n";
  gt << std::setprecision(17);
  for (int i = 0; i < 4; ++i) {
    const std::string name = "rgb/" + std::to_string(i) + ".png";
    cv::Mat color;
    cv::cvtColor(pattern(64, 48, i), color, cv::COLOR_GRAY2BGR);
    cv::imwrite((dir / name).string(), color);
    list << 1305031102.175304 + 0.033 * i << " " << name << "\n";
    gt << 1305031102.17 + 0.033 * i << " 1 2 3 0 0 0 1\n";
  }
  list.close();
  gt.close();
  writeSettings(dir / "settings.yaml", 64, 48);
  auto source = openDataset(dir.path(), {dir / "settings.yaml", std::nullopt});
  EXPECT_EQ(source->size(), 4u);
  ASSERT_TRUE(source->groundTruth());
  auto f = source->next();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->image.channels(), 1);  // colour converted to grey
  EXPECT_NEAR(f->timestamp, 1305031102.175304, 1e-6);
  // Without calibration the format cannot be used.
  EXPECT_THROW(openDataset(dir.path()), InputError);
}

TEST(ImageFolderDataset, ReadsImagesTimesAndCalibTxt) {
  testing::TempDir dir;
  fs::create_directories(dir / "images");
  std::ofstream times(dir / "times.txt");
  for (int i = 0; i < 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%06d.png", i);
    cv::imwrite((dir / "images" / name).string(), pattern(80, 40, i));
    times << 0.1 * i << "\n";
  }
  times.close();
  std::ofstream(dir / "calib.txt") << "# test\nwidth 80\nheight 40\nfx 50\nfy 50\ncx 40\ncy 20\n";
  auto source = openDataset(dir.path());
  EXPECT_EQ(source->size(), 3u);
  EXPECT_FALSE(source->groundTruth());
  int n = 0;
  while (auto f = source->next()) {
    EXPECT_NEAR(f->timestamp, 0.1 * n, 1e-12);
    ++n;
  }
  EXPECT_EQ(n, 3);
}

TEST(VideoSource, ReadsFramesWithATimesFile) {
  testing::TempDir dir;
  const fs::path video = dir / "clip.avi";
  cv::VideoWriter writer(video.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, {64, 48}, false);
  if (!writer.isOpened()) GTEST_SKIP() << "OpenCV cannot write MJPG video here";
  for (int i = 0; i < 5; ++i) writer.write(pattern(64, 48, i));
  writer.release();
  std::ofstream(dir / "times.txt") << "10.0\n10.1\n10.2\n10.3\n10.4\n";
  writeSettings(dir / "settings.yaml", 64, 48);
  auto source = openDataset(video, {dir / "settings.yaml", dir / "times.txt"});
  int n = 0;
  while (auto f = source->next()) {
    EXPECT_NEAR(f->timestamp, 10.0 + 0.1 * n, 1e-9);
    EXPECT_EQ(f->image.type(), CV_8U);
    ++n;
  }
  EXPECT_EQ(n, 5);
  // No settings: no calibration, a clear error.
  EXPECT_THROW(openDataset(video), InputError);
}

// The real KITTI excerpts from shared/, read with the settings files shipped in configs/.
TEST(RealData, KittiExcerptsOpenWithShippedConfigs) {
  const fs::path root = HIVESLAM_REAL_DATA;
  if (!fs::exists(root / "kitti07_f000-159")) GTEST_SKIP() << "real data not present at " << root;
  for (auto [name, frames] : {std::pair{"kitti07_f000-159", 160}, {"kitti06_f000-050", 51}}) {
    const std::string config = std::string(HIVESLAM_SOURCE_DIR) + "/configs/" + std::string(name).substr(0, 7) + ".yaml";
    auto source = openDataset(root / name, {config, std::nullopt});
    EXPECT_EQ(source->size(), static_cast<size_t>(frames)) << name;
    ASSERT_TRUE(source->groundTruth()) << name;
    EXPECT_EQ(source->groundTruth()->size(), static_cast<size_t>(frames));
    auto f = source->next();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->image.size(), cv::Size(1226, 370));
  }
}

}  // namespace
}  // namespace hiveslam::io
