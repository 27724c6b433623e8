#pragma once
// The standalone SLAM run behind `hiveslam run` (and the demo): dataset in, trajectory files,
// report.json and plot out.
#include <nlohmann/json.hpp>
#include <string>

namespace hiveslam::apps {

struct RunOptions {
  std::string dataset, config, times, out;
  bool sequential = false;
  bool verbose = false;
  bool realtime = false;
  bool no_loop_closing = false;
  std::string atlas_in, atlas_out;  // load maps before the run / save them after it
  bool localization = false;         // track against atlas_in without mapping
  int max_frames = 0;
};

struct RunSummary {
  nlohmann::json report;  // what report.json holds
  std::string line;       // one-line summary
};

RunSummary runSlam(const RunOptions& options);

}  // namespace hiveslam::apps
