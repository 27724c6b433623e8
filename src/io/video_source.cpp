// A video file read with OpenCV's VideoCapture. Stamps come from a times file when given
// (one per frame), else from the container's position in milliseconds.
#include <fmt/format.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/error.hpp"
#include "io/open_dataset.hpp"
#include "io/times_file.hpp"

namespace hiveslam::io {

namespace fs = std::filesystem;

namespace {

class VideoSource final : public FrameSource {
 public:
  VideoSource(fs::path file, CameraSettings camera, std::optional<std::vector<double>> times)
      : file_(std::move(file)), camera_(std::move(camera)), times_(std::move(times)) {
    if (!capture_.open(file_.string()) || !capture_.isOpened())
      throw InputError("cannot open video " + file_.string());
    const double n = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    if (n > 0) count_ = static_cast<size_t>(n);
    fps_ = capture_.get(cv::CAP_PROP_FPS);
  }

  std::optional<Frame> next() override {
    cv::Mat image;
    if (!capture_.read(image) || image.empty()) return std::nullopt;
    double t = 0.0;
    if (times_) {
      if (index_ >= times_->size())
        throw InputError(fmt::format("video {} has more frames than its times file ({})",
                                     file_.string(), times_->size()));
      t = (*times_)[index_];
    } else {
      t = fps_ > 0 ? static_cast<double>(index_) / fps_
                   : capture_.get(cv::CAP_PROP_POS_MSEC) / 1000.0;
    }
    if (image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
    const auto& cam = *camera_.camera;
    if (image.cols != cam.width() || image.rows != cam.height())
      throw InputError(fmt::format("video {} is {}x{} but the calibration says {}x{}",
                                   file_.string(), image.cols, image.rows, cam.width(),
                                   cam.height()));
    Frame frame{index_, t, image, fmt::format("{}#{}", file_.string(), index_)};
    ++index_;
    return frame;
  }

  std::optional<size_t> size() const override {
    if (times_) return times_->size();
    return count_;
  }
  const CameraSettings& camera() const override { return camera_; }
  const std::optional<Trajectory>& groundTruth() const override { return gt_; }
  std::string describe() const override {
    return fmt::format("video {} ({} frames, {}x{} {})", file_.string(), count_.value_or(0),
                       camera_.camera->width(), camera_.camera->height(), camera_.camera->type());
  }

 private:
  fs::path file_;
  CameraSettings camera_;
  std::optional<std::vector<double>> times_;
  std::optional<Trajectory> gt_;
  cv::VideoCapture capture_;
  std::optional<size_t> count_;
  double fps_ = 0.0;
  size_t index_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> openVideo(const fs::path& file, const DatasetOptions& options) {
  CameraSettings camera = resolveCamera(options, std::nullopt, &loadCalibTxt, file);
  std::optional<std::vector<double>> times;
  if (options.times) times = readTimesFile(*options.times);
  return std::make_unique<VideoSource>(file, std::move(camera), std::move(times));
}

}  // namespace hiveslam::io
