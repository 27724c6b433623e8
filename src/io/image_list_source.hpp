#pragma once
// The part every image-per-file format shares (EuRoC, TUM RGB-D, image folders): a list of
// (time, file) read up front, images decoded lazily one at a time and checked against the
// calibration.
#include <vector>

#include "io/frame_source.hpp"

namespace hiveslam::io {

struct ImageEntry {
  double timestamp;
  std::filesystem::path path;
};

class ImageListSource final : public FrameSource {
 public:
  // Throws InputError when the entries are empty or their stamps do not increase.
  ImageListSource(std::string format, std::filesystem::path root, std::vector<ImageEntry> entries,
                  CameraSettings camera, std::optional<Trajectory> ground_truth);

  std::optional<Frame> next() override;
  std::optional<size_t> size() const override { return entries_.size(); }
  const CameraSettings& camera() const override { return camera_; }
  const std::optional<Trajectory>& groundTruth() const override { return ground_truth_; }
  std::string describe() const override;
  std::optional<double> period() const override;

 private:
  std::string format_;
  std::filesystem::path root_;
  std::vector<ImageEntry> entries_;
  CameraSettings camera_;
  std::optional<Trajectory> ground_truth_;
  size_t cursor_ = 0;
};

// Rejects a list whose stamps do not strictly increase, naming `file` and the 1-based row.
void checkIncreasing(const std::vector<double>& stamps, const std::filesystem::path& file,
                     const std::vector<int>& lines);

}  // namespace hiveslam::io
