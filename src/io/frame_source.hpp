#pragma once
// One interface for every input: frames stream lazily, one image in memory at a time.
#include <filesystem>
#include <optional>
#include <opencv2/core.hpp>
#include <string>

#include "io/camera_settings.hpp"
#include "io/trajectory.hpp"

namespace hiveslam::io {

struct Frame {
  size_t index = 0;
  double timestamp = 0.0;  // seconds
  cv::Mat image;           // 8-bit grayscale, the calibrated size
  std::string source;      // file (or video position) it came from, for messages
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Next frame, or nullopt at the end. Throws InputError on an unreadable frame.
  virtual std::optional<Frame> next() = 0;
  // Number of frames when the format says it up front.
  virtual std::optional<size_t> size() const = 0;
  virtual const CameraSettings& camera() const = 0;
  // Ground-truth camera poses (T_w_cam) when the dataset has them.
  virtual const std::optional<Trajectory>& groundTruth() const = 0;
  // One line: format, location, frame count.
  virtual std::string describe() const = 0;
  // When the format lists every stamp up front: from the first frame to one mean frame interval
  // past the last, the time a replay of the whole sequence takes (io/repeated_source.hpp).
  virtual std::optional<double> period() const { return std::nullopt; }
};

}  // namespace hiveslam::io
