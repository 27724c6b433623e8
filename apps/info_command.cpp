// hiveslam info DATASET: what the readers make of an input; --check decodes every frame.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "io/open_dataset.hpp"

namespace hiveslam::apps {

void addInfoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Describe a dataset (format, camera, frames, ground truth)");
  auto path = std::make_shared<std::string>();
  auto settings = std::make_shared<std::string>();
  auto times = std::make_shared<std::string>();
  auto check = std::make_shared<bool>(false);
  cmd->add_option("DATASET", *path, "EuRoC/TUM-VI folder, TUM RGB-D folder, image folder or video")->required();
  cmd->add_option("--config", *settings, "Settings YAML with a camera section");
  cmd->add_option("--times", *times, "Times file for image folders and videos");
  cmd->add_flag("--check", *check, "Read and decode every frame");
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
