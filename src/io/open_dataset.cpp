#include "io/open_dataset.hpp"

#include "common/error.hpp"

namespace hiveslam::io {

namespace fs = std::filesystem;

CameraSettings resolveCamera(const DatasetOptions& options, const std::optional<fs::path>& fallback,
                             CameraSettings (*load_fallback)(const fs::path&),
                             const fs::path& dataset) {
  const bool own = fallback && fs::exists(*fallback);
  if (options.settings && (!own || hasCameraSection(*options.settings))) return loadSettingsCamera(*options.settings);
  if (own) return load_fallback(*fallback);
  throw InputError("no camera calibration for " + dataset.string() +
                   ": pass a settings file with --config");
}

std::unique_ptr<FrameSource> openDataset(const fs::path& path, const DatasetOptions& options) {
  if (!fs::exists(path)) throw InputError("dataset not found: " + path.string());
  if (fs::is_regular_file(path)) return openVideo(path, options);
  if (!fs::is_directory(path)) throw InputError("not a folder or a video file: " + path.string());
  if (fs::exists(path / "mav0" / "cam0" / "data.csv") || fs::exists(path / "cam0" / "data.csv"))
    return openEuroc(path, options);
  if (fs::exists(path / "rgb.txt")) return openTumRgbd(path, options);
  if (fs::exists(path / "times.txt") || options.times) return openImageFolder(path, options);
  throw InputError("cannot tell the dataset format of " + path.string() +
                   " (expected mav0/cam0/data.csv, rgb.txt or times.txt)");
}

}  // namespace hiveslam::io
