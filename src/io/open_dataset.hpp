#pragma once
// Opens any input the project reads, detecting its format from the path:
//  - EuRoC ASL / TUM-VI folder (has mav0/cam0/data.csv, or is mav0/)
//  - TUM RGB-D folder (has rgb.txt)
//  - image folder with a times file (times.txt beside images/, image_0/ or the images)
//  - a video file (OpenCV VideoCapture), with an optional times file
#include <filesystem>
#include <memory>
#include <optional>

#include "io/frame_source.hpp"

namespace hiveslam::io {

struct DatasetOptions {
  // Settings YAML whose `camera:` section overrides (or supplies) the calibration.
  std::optional<std::filesystem::path> settings;
  // Times file (seconds, one per frame) for image folders and videos.
  std::optional<std::filesystem::path> times;
};

std::unique_ptr<FrameSource> openDataset(const std::filesystem::path& path,
                                         const DatasetOptions& options = {});

// The format openers behind openDataset, one file each.
std::unique_ptr<FrameSource> openEuroc(const std::filesystem::path& root,
                                       const DatasetOptions& options);
std::unique_ptr<FrameSource> openTumRgbd(const std::filesystem::path& root,
                                         const DatasetOptions& options);
std::unique_ptr<FrameSource> openImageFolder(const std::filesystem::path& root,
                                             const DatasetOptions& options);
std::unique_ptr<FrameSource> openVideo(const std::filesystem::path& file,
                                       const DatasetOptions& options);

// Calibration: the settings file when given, else `fallback` (the dataset's own file), else
// an InputError asking for --config.
CameraSettings resolveCamera(const DatasetOptions& options,
                             const std::optional<std::filesystem::path>& fallback,
                             CameraSettings (*load_fallback)(const std::filesystem::path&),
                             const std::filesystem::path& dataset);

}  // namespace hiveslam::io
