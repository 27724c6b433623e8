#include "io/repeated_source.hpp"

#include <fmt/format.h>

#include "common/error.hpp"

namespace hiveslam::io {

RepeatedSource::RepeatedSource(std::function<std::unique_ptr<FrameSource>()> open, int passes)
    : open_(std::move(open)), passes_(passes), pass_source_(open_()) {
  if (passes_ < 1) throw InputError("--repeat must be at least 1");
  const auto period = pass_source_->period();
  if (!period || !(*period > 0))
    throw InputError("--repeat needs a dataset that lists its frames' stamps (an image folder with times, EuRoC, TUM)");
  period_ = *period;
  if (const auto& truth = pass_source_->groundTruth()) {
    Trajectory all;
    for (int p = 0; p < passes_; ++p)
      for (size_t i = 0; i < truth->size(); ++i) all.add(truth->stamps[i] + p * period_, truth->poses[i]);
    ground_truth_ = std::move(all);
  }
}

std::optional<Frame> RepeatedSource::next() {
  while (true) {
    if (auto frame = pass_source_->next()) {
      frame->timestamp += pass_ * period_;
      frame->index = index_++;
      return frame;
    }
    if (++pass_ >= passes_) return std::nullopt;
    pass_source_ = open_();
  }
}

std::optional<size_t> RepeatedSource::size() const {
  const auto one = pass_source_->size();
  return one ? std::optional<size_t>(*one * static_cast<size_t>(passes_)) : std::nullopt;
}

std::string RepeatedSource::describe() const {
  return fmt::format("{}, {} times in a row ({:.0f} s)", pass_source_->describe(), passes_, period_ * passes_);
}

}  // namespace hiveslam::io
