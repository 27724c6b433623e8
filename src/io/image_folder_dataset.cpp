// A folder of images plus a times file (KITTI odometry style): times.txt beside images/,
// image_0/ or the images themselves; optional calib.txt and groundtruth_tum.txt /
// groundtruth.txt (TUM format) beside them.
#include <algorithm>
#include <fmt/format.h>

#include "common/error.hpp"
#include "io/image_list_source.hpp"
#include "io/open_dataset.hpp"
#include "io/times_file.hpp"
#include "io/trajectory_io.hpp"

namespace hiveslam::io {

namespace fs = std::filesystem;

namespace {

bool isImageFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".pgm" || ext == ".ppm" ||
         ext == ".bmp" || ext == ".tif" || ext == ".tiff";
}

}  // namespace

std::unique_ptr<FrameSource> openImageFolder(const fs::path& root, const DatasetOptions& options) {
  CameraSettings camera = resolveCamera(options, root / "calib.txt", &loadCalibTxt, root);
  fs::path dir = root;
  for (const char* sub : {"images", "image_0", "data"})
    if (fs::is_directory(root / sub)) {
      dir = root / sub;
      break;
    }
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && isImageFile(e.path())) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError("no images in " + dir.string());

  const fs::path times_path = options.times ? *options.times : root / "times.txt";
  const std::vector<double> stamps = readTimesFile(times_path);
  if (stamps.size() != files.size())
    throw InputError(fmt::format("{} has {} timestamps but {} holds {} images",
                                 times_path.string(), stamps.size(), dir.string(), files.size()));
  std::vector<ImageEntry> entries;
  for (size_t i = 0; i < files.size(); ++i) entries.push_back({stamps[i], files[i]});

  std::optional<Trajectory> gt;
  for (const char* name : {"groundtruth_tum.txt", "groundtruth.txt"})
    if (fs::exists(root / name)) {
      gt = readTrajectory(root / name, TrajectoryFormat::Tum);
      break;
    }
  return std::make_unique<ImageListSource>("image folder", root, std::move(entries),
                                           std::move(camera), std::move(gt));
}

}  // namespace hiveslam::io
