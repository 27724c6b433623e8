// Bad input gets one clear error naming the file, never a crash or a half-read sequence.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "common/error.hpp"
#include "io/camera_settings.hpp"
#include "io/image_file.hpp"
#include "io/open_dataset.hpp"
#include "io/slam_settings_io.hpp"
#include "synth/sequence.hpp"
#include "temp_dir.hpp"

namespace hiveslam::io {
namespace {

namespace fs = std::filesystem;

// Runs f and returns the InputError message (fails the test when nothing is thrown).
template <typename F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

fs::path makeSequence(const testing::TempDir& dir) {
  synth::SequenceOptions o;
  o.width = 96;
  o.height = 64;
  o.frames = 4;
  synth::writeSequence(o, dir.path());
  return dir.path();
}

std::vector<fs::path> frames(const fs::path& root) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(root / "mav0/cam0/data")) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

void readAll(const fs::path& root) {
  auto source = openDataset(root);
  while (source->next()) {
  }
}

TEST(BadInput, MissingFolder) {
  const std::string msg = errorOf([] { openDataset("/nonexistent/hiveslam/dataset"); });
  EXPECT_NE(msg.find("/nonexistent/hiveslam/dataset"), std::string::npos) << msg;
}

TEST(BadInput, UnknownLayout) {
  testing::TempDir dir;
  std::ofstream(dir / "readme.md") << "hello\n";
  EXPECT_NE(errorOf([&] { openDataset(dir.path()); }).find("cannot tell"), std::string::npos);
}

TEST(BadInput, TruncatedPngNamesTheFile) {
  testing::TempDir dir;
  const auto files = frames(makeSequence(dir));
  fs::resize_file(files[2], fs::file_size(files[2]) / 2);
  const std::string msg = errorOf([&] { readAll(dir.path()); });
  EXPECT_NE(msg.find(files[2].filename().string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
}

TEST(BadInput, CorruptImageNamesTheFile) {
  testing::TempDir dir;
  const auto files = frames(makeSequence(dir));
  std::ofstream(files[1], std::ios::binary) << "this is not an image at all";
  const std::string msg = errorOf([&] { readAll(dir.path()); });
  EXPECT_NE(msg.find(files[1].filename().string()), std::string::npos) << msg;
}

TEST(BadInput, MissingImageNamesTheFile) {
  testing::TempDir dir;
  const auto files = frames(makeSequence(dir));
  fs::remove(files[3]);
  EXPECT_NE(errorOf([&] { readAll(dir.path()); }).find(files[3].filename().string()), std::string::npos);
}

// A file name that starts with a NUL byte names the image folder itself (the system sees the
// name end there): once read as an image of 2^63 bytes, an allocation failure instead of an
// error (fuzz/dataset_fuzzer.cpp found it).
TEST(BadInput, AnImageEntryThatNamesAFolderIsNamed) {
  testing::TempDir dir;
  makeSequence(dir);
  const char list[] = "#timestamp [ns],filename\n1000,\0x.png\n";
  std::ofstream(dir / "mav0/cam0/data.csv") << std::string(list, sizeof list - 1);
  EXPECT_NE(errorOf([&] { readAll(dir.path()); }).find("not an image file"), std::string::npos);
}

TEST(BadInput, TimesOutOfOrderNamesFileAndLine) {
  testing::TempDir dir;
  fs::create_directories(dir / "images");
  for (int i = 0; i < 3; ++i) cv::imwrite((dir / "images" / (std::to_string(i) + ".png")).string(), cv::Mat(8, 8, CV_8U, cv::Scalar(i)));
  std::ofstream(dir / "times.txt") << "0.0\n0.2\n0.1\n";
  std::ofstream(dir / "calib.txt") << "width 8\nheight 8\nfx 5\nfy 5\ncx 4\ncy 4\n";
  const std::string msg = errorOf([&] { openDataset(dir.path()); });
  EXPECT_NE(msg.find("times.txt:3"), std::string::npos) << msg;
}

TEST(BadInput, EurocStampsOutOfOrder) {
  testing::TempDir dir;
  makeSequence(dir);
  std::ofstream(dir / "mav0/cam0/data.csv") << "#timestamp [ns],filename\n2000,a.png\n1000,b.png\n";
  EXPECT_NE(errorOf([&] { openDataset(dir.path()); }).find("data.csv:3"), std::string::npos);
}

TEST(BadInput, TimesCountDifferentFromImageCount) {
  testing::TempDir dir;
  fs::create_directories(dir / "images");
  cv::imwrite((dir / "images/0.png").string(), cv::Mat(8, 8, CV_8U, cv::Scalar(1)));
  std::ofstream(dir / "times.txt") << "0.0\n0.1\n";
  std::ofstream(dir / "calib.txt") << "width 8\nheight 8\nfx 5\nfy 5\ncx 4\ncy 4\n";
  EXPECT_NE(errorOf([&] { openDataset(dir.path()); }).find("2 timestamps"), std::string::npos);
}

TEST(BadInput, CalibrationWithWrongSizes) {
  testing::TempDir dir;
  auto write = [&](const std::string& camera) {
    std::ofstream(dir / "s.yaml") << "camera:\n" << camera;
    return errorOf([&] { loadSettingsCamera(dir / "s.yaml"); });
  };
  EXPECT_NE(write("  model: pinhole\n  width: 10\n  height: 10\n  intrinsics: [5, 5, 5]\n").find("4 values"), std::string::npos);
  EXPECT_NE(write("  model: pinhole\n  width: 10\n  height: 10\n  intrinsics: [5, 5, 5, 5]\n  distortion: [0.1, 0.2, 0.3]\n").find("4 or 5"), std::string::npos);
  EXPECT_NE(write("  model: kannala-brandt\n  width: 10\n  height: 10\n  intrinsics: [5, 5, 5, 5]\n  distortion: [0.1]\n").find("4 coefficients"), std::string::npos);
  EXPECT_NE(write("  model: pinhole\n  width: -3\n  height: 10\n  intrinsics: [5, 5, 5, 5]\n").find("not valid"), std::string::npos);
  EXPECT_NE(write("  model: pinhole\n  width: 10\n  height: 10\n  intrinsics: [-5, 5, 5, 5]\n").find("positive"), std::string::npos);
  EXPECT_NE(write("  model: pinhole\n  width: 10\n  height: 10\n  intrinsics: [5, 5, 50, 5]\n").find("outside"), std::string::npos);
  EXPECT_NE(write("  model: orthographic\n  width: 10\n  height: 10\n  intrinsics: [5, 5, 5, 5]\n").find("unknown camera model"), std::string::npos);
  EXPECT_NE(write("  model: pinhole\n  width: 10\n").find("height"), std::string::npos);
  EXPECT_NE(write("  model: [pinhole\n").find("s.yaml"), std::string::npos);
}

TEST(BadInput, ImageSizeDifferentFromCalibration) {
  testing::TempDir dir;
  makeSequence(dir);
  std::ofstream(dir / "wrong.yaml") << "camera:\n  model: pinhole\n  width: 100\n  height: 64\n  intrinsics: [50, 50, 48, 32]\n";
  const std::string msg = errorOf([&] {
    auto source = openDataset(dir.path(), {dir / "wrong.yaml", std::nullopt});
    source->next();
  });
  EXPECT_NE(msg.find("96x64 but the calibration says 100x64"), std::string::npos) << msg;
}

TEST(BadInput, EurocSensorYamlWithWrongResolution) {
  testing::TempDir dir;
  makeSequence(dir);
  std::ofstream(dir / "mav0/cam0/sensor.yaml") << "resolution: [96]\nintrinsics: [50, 50, 48, 32]\n";
  EXPECT_NE(errorOf([&] { openDataset(dir.path()); }).find("sensor.yaml"), std::string::npos);
}

// Runs `hiveslam ARGS` and checks that it failed with exactly one line of output containing
// `expected`.
void expectOneLineFailure(const std::string& args, const std::string& expected) {
  const std::string cmd = std::string(HIVESLAM_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  std::array<char, 256> buf{};
  while (fgets(buf.data(), buf.size(), pipe)) out += buf.data();
  const int status = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(status)) << args;
  EXPECT_NE(WEXITSTATUS(status), 0) << args;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_NE(out.find(expected), std::string::npos) << out;
}

// The command line turns every one of these into one line on stderr and a non-zero exit.
TEST(BadInput, CommandLinePrintsOneLineAndFails) {
  expectOneLineFailure("info /nonexistent/hiveslam/dataset", "dataset not found: /nonexistent/hiveslam/dataset");
}

// The live view's commands and settings: a bad domain, port, niceness or rate is one line and an exit,
// before anything listens.
TEST(BadInput, TheLiveViewChecksItsDomainPortAndRates) {
  testing::TempDir dir;
  expectOneLineFailure("view --domain 233", "DDS domain must be 0-232");
  expectOneLineFailure("topics --domain 233", "DDS domain must be 0-232");
  expectOneLineFailure("view --port 70000 --seconds 1", "viewer port must be 0-65535");
  expectOneLineFailure("view --nice 20 --seconds 1", "--nice must be 0-19");
  std::ofstream(dir / "slow.yaml") << "view: {cloud_hz: 0}\n";
  expectOneLineFailure("view --seconds 1 --config " + (dir / "slow.yaml").string(), "view settings out of range");
  std::ofstream(dir / "typo.yaml") << "view: {cloud_hzz: 1}\n";
  expectOneLineFailure("view --seconds 1 --config " + (dir / "typo.yaml").string(), "unknown setting 'view.cloud_hzz'");
  // A port another program holds.
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(listen(fd, 1), 0);
  socklen_t len = sizeof a;
  ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len), 0);
  expectOneLineFailure("view --seconds 1 --port " + std::to_string(ntohs(a.sin_port)), "cannot listen on");
  close(fd);
}

TEST(BadInput, ASavedBenchIsCheckedBeforeItIsRead) {
  testing::TempDir dir;
  expectOneLineFailure("eval bench " + (dir / "missing.json").string(), "cannot open");
  std::ofstream(dir / "object.json") << "{\"sequence\": \"sweep\"}";
  expectOneLineFailure("eval bench " + (dir / "object.json").string(), "is not a bench.json");
  std::ofstream(dir / "truncated.json") << "[{\"sequence\": \"sweep\", \"nodes\": ";
  expectOneLineFailure("eval bench " + (dir / "truncated.json").string(), "is not a bench.json");
  std::ofstream(dir / "short_row.json") << "[{\"sequence\": \"sweep\", \"nodes\": 1}]";
  expectOneLineFailure("eval bench " + (dir / "short_row.json").string(), "a row lacks what hiveslam bench writes");
}

TEST(BadInput, EvalLensNamesAMissingAtlasOrCamera) {
  testing::TempDir dir;
  expectOneLineFailure("eval lens " + (dir / "missing.bin").string() + " " + (dir / "missing.yaml").string(),
                       "cannot open atlas");
  std::ofstream(dir / "short.bin") << "hiveslam";
  expectOneLineFailure("eval lens " + (dir / "short.bin").string() + " " + (dir / "missing.yaml").string(), "atlas");
}

TEST(BadInput, DistributionSettingsAreReadAndChecked) {
  testing::TempDir dir;
  const fs::path file = dir / "settings.yaml";
  std::ofstream(file) << "distribution:\n  local_max_batch: 8\n  global_batch_gap_ms: 40\n  min_point_move: 0.001\n"
                          "  point_descriptor_bits: 0\n  lc_global_batch_gap_ms: 100\n";
  distribution::DistributionSettings s;
  applyDistributionSettings(file, s);
  EXPECT_EQ(s.local_max_batch, 8);
  EXPECT_EQ(s.global_batch_gap_ms, 40);
  EXPECT_DOUBLE_EQ(s.min_point_move, 0.001);
  EXPECT_EQ(s.point_descriptor_bits, 0);
  EXPECT_EQ(s.lc_global_batch_gap_ms, 100);
  EXPECT_EQ(s.local_first_batch, 3);  // untouched keys keep the paper's values
  std::ofstream(file) << "distribution:\n  local_max_bach: 8\n";
  EXPECT_NE(errorOf([&] { applyDistributionSettings(file, s); }).find("distribution.local_max_bach"), std::string::npos);
  std::ofstream(file) << "distribution:\n  local_first_batch: 9\n  local_max_batch: 4\n";
  EXPECT_NE(errorOf([&] { applyDistributionSettings(file, s); }).find("out of range"), std::string::npos);
  std::ofstream(file) << "distribution:\n  lc_global_batch_gap_ms: -1\n";
  distribution::DistributionSettings fresh;
  EXPECT_NE(errorOf([&] { applyDistributionSettings(file, fresh); }).find("out of range"), std::string::npos);
  std::ofstream(file) << "distribution:\n  point_normal_deg: -1\n";
  EXPECT_NE(errorOf([&] { applyDistributionSettings(file, s); }).find("point tolerances >= 0"), std::string::npos);
  std::ofstream(file) << "distribution:\n  global_batch: ten\n";
  EXPECT_NE(errorOf([&] { applyDistributionSettings(file, s); }).find("wrong type"), std::string::npos);
}

TEST(BadInput, DdsSettingsAreReadAndChecked) {
  testing::TempDir dir;
  const fs::path file = dir / "settings.yaml";
  std::ofstream(file) << "dds:\n  max_datagram_bytes: 8972\n  heartbeat_ms: 50\n";
  communication::DdsOptions o{12};
  applyDdsSettings(file, o);
  EXPECT_EQ(o.max_datagram_bytes, 8972);
  EXPECT_EQ(o.heartbeat_ms, 50);
  EXPECT_EQ(o.domain, 12);        // the command line's
  EXPECT_EQ(o.history_depth, 64);  // untouched keys keep their defaults
  std::ofstream(file) << "dds:\n  domain: 3\n";
  EXPECT_NE(errorOf([&] { applyDdsSettings(file, o); }).find("unknown setting 'dds.domain'"), std::string::npos);
  std::ofstream(file) << "dds:\n  max_datagram_bytes: 100000\n";
  EXPECT_NE(errorOf([&] { applyDdsSettings(file, o); }).find("max_datagram_bytes 576-65500"), std::string::npos);
  std::ofstream(file) << "dds:\n  heartbeat_ms: 0\n";
  EXPECT_NE(errorOf([&] { applyDdsSettings(file, o); }).find("out of range"), std::string::npos);
  std::ofstream(file) << "dds:\n  heartbeat_ms: fast\n";
  EXPECT_NE(errorOf([&] { applyDdsSettings(file, o); }).find("wrong type"), std::string::npos);
}

TEST(BadInput, ACameraFileIsRecognisedByItsContent) {
  testing::TempDir dir;
  const fs::path seq = makeSequence(dir);
  EXPECT_EQ(loadCameraFile(seq / "mav0/cam0/sensor.yaml").camera->width(), 96);
  const fs::path settings = dir / "camera.yaml";
  writeSettingsCamera(settings, *loadCameraFile(seq / "mav0/cam0/sensor.yaml").camera, 20);
  EXPECT_EQ(loadCameraFile(settings).camera->height(), 64);
  std::ofstream(dir / "calib.txt") << "fx 1\n";
  EXPECT_NE(errorOf([&] { loadCameraFile(dir / "calib.txt"); }).find("calib.txt"), std::string::npos);
}

}  // namespace

TEST(BadInput, AnUnknownCameraKeyIsNamed) {
  testing::TempDir dir;
  const fs::path file = dir / "settings.yaml";
  std::ofstream(file) << "camera:\n  model: pinhole-radtan\n  width: 640\n  height: 480\n"
                         "  intrinsics: [500, 500, 320, 240]\n  focal: 500\n";
  EXPECT_NE(errorOf([&] { loadSettingsCamera(file); }).find("unknown setting 'camera.focal'"), std::string::npos);
}

// Fuzzer findings (fuzz/settings_fuzzer.cpp): files that are not maps of keys escaped as
// yaml-cpp's own exceptions without the file's name, and ORB settings and a calibration size
// out of range read outside buffers or cast a value no int holds.
TEST(BadInput, SettingsFilesThatAreNotMapsOrOutOfRangeAreNamed) {
  testing::TempDir dir;
  const fs::path file = dir / "settings.yaml";
  const auto slamError = [&](const std::string& text) {
    std::ofstream(file) << text;
    core::SlamSettings s;
    return errorOf([&] { applySlamSettings(file, s); });
  };
  for (const std::string text : {"T\n", "- 1\n", "slam: 5\n", "slam: [1, 2]\n", "slam:\n  [a]: 1\n", "slam:\n  orb: 3\n"})
    EXPECT_NE(slamError(text).find("settings.yaml"), std::string::npos) << text;
  for (const std::string bad : {"levels: 0", "cell_size: 0", "cell_size: -7", "scale_factor: 0.5", "features: 0"})
    EXPECT_NE(slamError("slam:\n  orb:\n    " + bad + "\n").find("out of range"), std::string::npos) << bad;
  std::ofstream(file) << "";
  core::SlamSettings untouched;
  applySlamSettings(file, untouched);  // an empty file sets nothing
  EXPECT_EQ(untouched.orb.levels, 8);
  std::ofstream(file) << "dds: 1\n";
  communication::DdsOptions dds;
  EXPECT_NE(errorOf([&] { applyDdsSettings(file, dds); }).find("'dds' is not a map"), std::string::npos);
  std::ofstream(file) << "camera: pinhole\n";
  EXPECT_NE(errorOf([&] { loadSettingsCamera(file); }).find("'camera' is not a map"), std::string::npos);
  std::ofstream(file) << "just words\n";
  EXPECT_NE(errorOf([&] { loadCameraFile(file); }).find("settings.yaml: not a YAML map"), std::string::npos);
  std::ofstream(file) << "resolution: [64, 48]\nintrinsics: [50, 50, 32, 24]\nT_BS: 7\n";
  EXPECT_NE(errorOf([&] { loadEurocSensorYaml(file); }).find("'T_BS' is not a map"), std::string::npos);
  std::ofstream(dir / "calib.txt") << "width 1e30\nheight 40\nfx 50\nfy 50\ncx 40\ncy 20\n";
  EXPECT_NE(errorOf([&] { loadCalibTxt(dir / "calib.txt"); }).find("'width' must be"), std::string::npos);
  std::ofstream(dir / "calib.txt") << "width nan\nheight 40\nfx 50\nfy 50\ncx 40\ncy 20\n";
  EXPECT_NE(errorOf([&] { loadCalibTxt(dir / "calib.txt"); }).find("calib.txt"), std::string::npos);
}

}  // namespace hiveslam::io
