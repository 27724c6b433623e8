#pragma once
// The standalone SLAM run behind `hiveslam run` (and the demo): dataset in, trajectory files,
// report.json and plot out.
#include <nlohmann/json.hpp>

#include "apps/secure_option.hpp"
#include "core/loop/loop_closer.hpp"
#include "core/mapping/local_mapper.hpp"
#include "apps/live_view_stack.hpp"
#include "core/system/slam_system.hpp"
#include <string>
#include <vector>

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
  int repeat = 1;  // the dataset played this many times in a row (io/repeated_source.hpp)
  // Instead of a dataset: a ROS 2 sensor_msgs/msg/Image topic on DDS domain topic_domain, with
  // the calibration from a file (settings YAML, sensor.yaml or calib.txt).
  std::string topic, calibration;
  int topic_domain = 0;
  int topic_wait_seconds = 30;  // for the first image
  // A dataset whose ground truth scores the run (for a topic, which carries none).
  std::string ground_truth;
  // The live view (web page, ROS 2 topics); a TR node publishes the topics unless told not to.
  LiveViewOptions live;
  bool viewer_wait = false;  // keep serving the page after the run, until Ctrl-C
  SecureOption secure;        // DDS Security for the image topic and the ROS 2 topics (run --secure)
  // As the TR node of a distributed system (hiveslam node --task tr): on a DDS domain, waiting
  // for the peers it expects before the first frame.
  struct Network {
    bool enabled = false;
    int domain = 0;
    uint16_t id = 1;
    std::string name = "tr";
    std::vector<std::string> expect;  // tasks of the peers to wait for ("lm", "lc")
    int wait_seconds = 20;
  } network;
};

// Each loop closure and merge as a report entry: kind, timestamp of the keyframe that
// recognized the place, matches, the Sim3's scale (the drift seen), timings.
nlohmann::json loopEventsJson(const core::LoopStats& stats);
// The re-measurement of observations before the final global BA (SlamSettings::remeasure).
nlohmann::json remeasureJson(const core::SlamSystem::RemeasureReport& r, const core::RemeasurementUse& use);
// Local mapping's counts (keyframes processed and culled, points made and culled, local BAs).
nlohmann::json mappingStatsJson(const core::MappingStats& stats);
// A node's DDS Security: "secure" (joined with --secure) and "failed_handshakes" (remote
// participants that could not authenticate: no keys, or another domain's), and
// "announcements_dropped" (node announcements that failed their checks: communication/dds/node_announcement.hpp).
void addSecurityReport(nlohmann::json& report);

struct RunSummary {
  nlohmann::json report;  // what report.json holds
  std::string line;       // one-line summary
};

RunSummary runSlam(const RunOptions& options);

}  // namespace hiveslam::apps
