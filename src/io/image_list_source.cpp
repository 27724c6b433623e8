#include "io/image_list_source.hpp"

#include <fmt/format.h>

#include "common/error.hpp"
#include "io/image_file.hpp"

namespace hiveslam::io {

void checkIncreasing(const std::vector<double>& stamps, const std::filesystem::path& file,
                     const std::vector<int>& lines) {
  for (size_t i = 1; i < stamps.size(); ++i)
    if (!(stamps[i] > stamps[i - 1]))
      throw InputError(fmt::format("{}:{}: timestamp {} is not after the previous one ({})",
                                   file.string(), i < lines.size() ? lines[i] : int(i + 1),
                                   stamps[i], stamps[i - 1]));
}

ImageListSource::ImageListSource(std::string format, std::filesystem::path root,
                                 std::vector<ImageEntry> entries, CameraSettings camera,
                                 std::optional<Trajectory> ground_truth)
    : format_(std::move(format)),
      root_(std::move(root)),
      entries_(std::move(entries)),
      camera_(std::move(camera)),
      ground_truth_(std::move(ground_truth)) {
  if (entries_.empty()) throw InputError(format_ + " dataset has no images: " + root_.string());
}

std::optional<Frame> ImageListSource::next() {
  if (cursor_ >= entries_.size()) return std::nullopt;
  const ImageEntry& e = entries_[cursor_];
  Frame frame{cursor_, e.timestamp, readGrayImage(e.path), e.path.string()};
  const auto& cam = *camera_.camera;
  if (frame.image.cols != cam.width() || frame.image.rows != cam.height())
    throw InputError(fmt::format("image {} is {}x{} but the calibration says {}x{}",
                                 e.path.string(), frame.image.cols, frame.image.rows, cam.width(),
                                 cam.height()));
  ++cursor_;
  return frame;
}

std::optional<double> ImageListSource::period() const {
  const double span = entries_.back().timestamp - entries_.front().timestamp;
  return entries_.size() < 2 ? std::nullopt : std::optional<double>(span * static_cast<double>(entries_.size()) / static_cast<double>(entries_.size() - 1));
}

std::string ImageListSource::describe() const {
  return fmt::format("{} {} ({} frames, {}x{} {}{})", format_, root_.string(), entries_.size(),
                     camera_.camera->width(), camera_.camera->height(), camera_.camera->type(),
                     ground_truth_ ? ", with ground truth" : "");
}

}  // namespace hiveslam::io
