// hiveslam info DATASET: what the readers make of an input; --check decodes every frame;
// --image-stats measures what a tracker would see in them (eval/image_statistics).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "eval/image_statistics.hpp"
#include "io/open_dataset.hpp"

namespace hiveslam::apps {

void addInfoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Describe a dataset (format, camera, frames, ground truth)");
  cmd->footer("Example:\n  hiveslam info seq/figure8 --check --image-stats --every 10");
  auto path = std::make_shared<std::string>();
  auto settings = std::make_shared<std::string>();
  auto times = std::make_shared<std::string>();
  auto check = std::make_shared<bool>(false);
  auto stats = std::make_shared<bool>(false);
  auto every = std::make_shared<int>(10);
  cmd->add_option("DATASET", *path, "EuRoC/TUM-VI folder, TUM RGB-D folder, image folder or video")->required();
  cmd->add_option("--config", *settings, "Settings YAML with a camera section");
  cmd->add_option("--times", *times, "Times file for image folders and videos");
  cmd->add_flag("--check", *check, "Read and decode every frame");
  cmd->add_flag("--image-stats", *stats,
                "FAST corners per frame, their spread over an 8x6 grid, weak corners in bare cells, grey-level entropy, "
                "gradient and the share of features with a look-alike in the same image (10th, 50th, 90th percentile "
                "over the frames)");
  cmd->add_option("--every", *every, "With --image-stats: every Nth frame")->capture_default_str()->check(CLI::Range(1, 100000));
  cmd->callback([=]() {
    io::DatasetOptions options;
    if (!settings->empty()) options.settings = *settings;
    if (!times->empty()) options.times = *times;
    auto source = io::openDataset(*path, options);
    fmt::print("{}\n", source->describe());
    const auto p = source->camera().camera->parameters();
    fmt::print("camera: {} [{}]\n", source->camera().camera->type(), fmt::join(p, ", "));
    if (const auto& gt = source->groundTruth())
      fmt::print("ground truth: {} poses, {:.2f} m path, {:.2f} s\n", gt->size(), gt->pathLength(),
                 gt->stamps.back() - gt->stamps.front());
    if (*stats) {
      std::vector<eval::ImageStatistics> frames;
      for (size_t i = 0; auto frame = source->next(); ++i)
        if (i % static_cast<size_t>(*every) == 0) frames.push_back(eval::imageStatistics(frame->image));
      const auto s = eval::summarizeStatistics(frames);
      fmt::print("image statistics over {} frames (10th / 50th / 90th percentile), at 640 pixels wide:\n", s.frames);
      for (const auto& [name, v] : {std::pair{"FAST corners", s.corners}, {"cells covered", s.cells_covered},
                                    {"weak corners", s.weak_corners},
                                    {"entropy bits", s.entropy_bits}, {"gradient", s.gradient},
                                    {"look-alikes", s.look_alikes}})
        fmt::print("  {:<14} {:>8.2f} {:>8.2f} {:>8.2f}\n", name, v.p10, v.median, v.p90);
      return;
    }
    if (!*check) return;
    Progress progress("checking");
    const int total = static_cast<int>(source->size().value_or(0));
    int n = 0;
    double first = 0, last = 0;
    while (auto frame = source->next()) {
      if (n == 0) first = frame->timestamp;
      last = frame->timestamp;
      progress.update(++n, std::max(total, n));
    }
    fmt::print("{} frames read, {:.3f} s to {:.3f} s\n", n, first, last);
  });
}

}  // namespace hiveslam::apps
