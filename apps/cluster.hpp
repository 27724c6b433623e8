#pragma once
// The distributed system on this machine: TR, LM and LC as separate processes (hiveslam node)
// on a DDS domain of their own, or the standalone system for one node. Behind
// `hiveslam cluster` and `hiveslam bench`.
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace hiveslam::apps {

struct ClusterOptions {
  int nodes = 3;  // 1: standalone; 2: TR + LM (LM hosts LC); 3: TR + LM + LC
  std::string dataset, out, config;
  bool realtime = false;
  bool no_loop_closing = false;
  bool save_atlases = false;  // each node saves its maps to DIR/<task>/atlas.bin
  int domain = -1;  // -1: one picked from the process id (concurrent clusters stay apart)
  int timeout_seconds = 900;
  // The paper's feed: the dataset played as a ROS 2 image topic by a `hiveslam play` process,
  // so TR gets raw pixels as from a camera driver (and decodes no image files). The
  // calibration is the dataset's sensor.yaml, or --config.
  bool feed_topic = false;
  std::string secure;  // DDS Security: the keys folder (hiveslam keys); empty: off
};

struct ClusterResult {
  std::map<std::string, nlohmann::json> reports;  // by task: "tr", "lm", "lc"
};

ClusterResult runCluster(const ClusterOptions& options);

}  // namespace hiveslam::apps
