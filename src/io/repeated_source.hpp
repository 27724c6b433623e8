#pragma once
// A dataset played several times in a row, as one stream: each pass's stamps follow the last
// pass's by the sequence's period, and so does its ground truth. For long runs (a soak of a
// cluster: scripts/soak) out of a sequence of a minute.
#include <functional>
#include <memory>

#include "io/frame_source.hpp"

namespace hiveslam::io {

class RepeatedSource final : public FrameSource {
 public:
  // `open` opens the dataset afresh for each pass. Throws InputError when the format does not
  // list its stamps up front (a video without a times file, a live topic).
  RepeatedSource(std::function<std::unique_ptr<FrameSource>()> open, int passes);

  std::optional<Frame> next() override;
  std::optional<size_t> size() const override;
  const CameraSettings& camera() const override { return pass_source_->camera(); }
  const std::optional<Trajectory>& groundTruth() const override { return ground_truth_; }
  std::string describe() const override;
  std::optional<double> period() const override { return period_ * passes_; }

 private:
  std::function<std::unique_ptr<FrameSource>()> open_;
  int passes_ = 1, pass_ = 0;
  double period_ = 0;
  size_t index_ = 0;
  std::unique_ptr<FrameSource> pass_source_;
  std::optional<Trajectory> ground_truth_;
};

}  // namespace hiveslam::io
