// libFuzzer target: the readers of what a user hands to hiveslam besides settings (those are
// settings_fuzzer's): saved atlases (`--atlas-in`), the image lists of EuRoC and TUM RGB-D
// folders, ground-truth trajectories in TUM, EuRoC and KITTI form, and image files (PNG through
// io/png_gray_decoder.cpp, anything else through OpenCV). The first byte picks the
// reader; the rest is the file. A reader may accept the file or throw InputError (one line, the
// command exits non-zero); anything else (another exception, a crash, a hang, a sanitizer
// report) is a finding. What a reader accepts must then be safe to use: an atlas's spanning tree
// leads every keyframe to a root, its numbers are finite; a dataset's frames can be asked for.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/error.hpp"
#include "io/atlas_file.hpp"
#include "io/image_file.hpp"
#include "io/open_dataset.hpp"
#include "io/trajectory_io.hpp"

using namespace hiveslam;
namespace fs = std::filesystem;

namespace {

// One scratch folder per process, rewritten for each input: the readers take paths.
const fs::path& scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("hiveslam_dataset_fuzz_" + std::to_string(getpid()));
    fs::create_directories(d / "euroc/mav0/cam0/data");
    fs::create_directories(d / "tum");
    std::ofstream(d / "euroc/mav0/cam0/sensor.yaml")
        << "sensor_type: camera\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n"
           "rate_hz: 20\nresolution: [64, 48]\ncamera_model: pinhole\nintrinsics: [50, 50, 32, 24]\n"
           "distortion_model: radial-tangential\ndistortion_coefficients: [0, 0, 0, 0]\n";
    std::ofstream(d / "tum/calib.txt") << "width 64\nheight 48\nfx 50\nfy 50\ncx 32\ncy 24\n";
    return d;
  }();
  return dir;
}

void write(const fs::path& file, const uint8_t* data, size_t size) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

void finding() { __builtin_trap(); }

void useAtlas(const std::vector<std::shared_ptr<core::Map>>& maps) {
  for (const auto& map : maps)
    for (const auto& [id, kf] : map->keyframes) {
      // The spanning tree: every parent chain ends (loop correction walks it).
      size_t steps = 0;
      for (const core::KeyFrame* k = kf.get(); k; k = k->parent)
        if (++steps > map->keyframes.size()) finding();
      if (!kf->T_cw.matrix().allFinite()) finding();
      for (const auto& p : kf->points)
        if (p && !p->position.allFinite()) finding();
      (void)kf->bestCovisible(5);
    }
}

void useDataset(io::FrameSource& source) {
  (void)source.describe();
  (void)source.size();
  try {
    (void)source.next();  // the images do not exist: a one-line InputError
  } catch (const InputError&) {
  }
}

void useTrajectory(const io::Trajectory& t) {
  if (t.stamps.size() != t.poses.size()) finding();
  for (double s : t.stamps)
    if (!std::isfinite(s)) finding();
  for (const auto& T : t.poses)
    if (!T.matrix().allFinite()) finding();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const fs::path& dir = scratch();
  try {
    switch (data[0] % 7) {
      case 0:
        write(dir / "atlas.bin", data + 1, size - 1);
        useAtlas(io::loadAtlas(dir / "atlas.bin"));
        break;
      case 1: {
        write(dir / "euroc/mav0/cam0/data.csv", data + 1, size - 1);
        auto source = io::openEuroc(dir / "euroc", {});
        useDataset(*source);
        break;
      }
      case 2: {
        write(dir / "tum/rgb.txt", data + 1, size - 1);
        auto source = io::openTumRgbd(dir / "tum", {});
        useDataset(*source);
        break;
      }
      case 6: {
        write(dir / "image", data + 1, size - 1);
        const cv::Mat gray = io::readGrayImage(dir / "image");
        if (gray.empty() || gray.type() != CV_8UC1) finding();
        break;
      }
      default: {
        const io::TrajectoryFormat format[] = {io::TrajectoryFormat::Tum, io::TrajectoryFormat::Euroc,
                                               io::TrajectoryFormat::Kitti};
        write(dir / "trajectory.txt", data + 1, size - 1);
        useTrajectory(io::readTrajectory(dir / "trajectory.txt", format[data[0] % 7 - 3]));
      }
    }
  } catch (const InputError&) {
  }
  return 0;
}
