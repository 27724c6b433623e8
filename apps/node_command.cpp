// hiveslam node --task tr|lm|lc: one node of the distributed system on a DDS domain. TR reads a
// dataset (what `hiveslam run` reads) and writes what `run` writes; LM and LC serve until the
// end-of-run exchange completes (or SIGINT/SIGTERM, or an LC's gateway left it alone after it
// answered), then write DIR/report.json.
#include <fmt/format.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "apps/run_slam.hpp"
#include "apps/secure_option.hpp"
#include "common/error.hpp"
#include "communication/dds/dds_transport.hpp"
#include "core/system/slam_system.hpp"
#include "distribution/distributed_node.hpp"
#include "eval/resource_monitor.hpp"
#include "io/atlas_file.hpp"
#include "io/slam_settings_io.hpp"
#include "io/vocabulary_file.hpp"

namespace hiveslam::apps {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop = true; }

struct NodeCommandOptions {
  std::string task = "tr", name, dataset, out, config, times, expect, topic, calibration, ground_truth, atlas_out;
  int domain = 0, id = 0;
  bool realtime = false, no_loop_closing = false;
  int repeat = 1;
  int wait_seconds = 20;
  bool no_ros = false;
  LiveViewOptions live;
  SecureOption secure;
};

uint16_t defaultId(communication::Task t) { return static_cast<uint16_t>(static_cast<int>(t) + 1); }

// LM and LC: a SLAM system without tracking, fed and drained by the distribution layer.
void serve(const NodeCommandOptions& o, communication::Task task) {
  eval::ResourceMonitor monitor;
  core::SlamSettings settings;
  if (!o.config.empty()) io::applySlamSettings(o.config, settings);
  if (o.no_loop_closing) settings.loop_closing = false;
  const auto vocabulary = io::loadVocabulary(settings);
  const uint16_t id = o.id > 0 ? static_cast<uint16_t>(o.id) : defaultId(task);
  core::SlamSystem slam(settings, nullptr, core::SlamSystem::Mode::Offline, vocabulary, id);
  communication::DdsOptions dds{o.domain};
  if (!o.config.empty()) io::applyDdsSettings(o.config, dds);
  communication::DdsTransport transport(dds);
  distribution::DistributionSettings distribution_settings;
  if (!o.config.empty()) io::applyDistributionSettings(o.config, distribution_settings);
  distribution::DistributedNode node(
      slam, transport, {task, id, o.name.empty() ? communication::taskName(task) : o.name, distribution_settings});
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  node.start();
  LiveViewOptions lv = o.live;
  lv.ros = !o.no_ros;
  lv.domain = o.domain;
  lv.node = o.name.empty() ? communication::taskName(task) : o.name;
  if (!o.config.empty()) io::applyViewSettings(o.config, lv.settings);
  std::unique_ptr<LiveViewStack> live;
  if (lv.any())
    live = std::make_unique<LiveViewStack>(lv, slam, [&node, &monitor] { return node.report(monitor.wallSeconds()); },
                                           [&slam] { return slam.hosting().mapping; });
  fmt::print(stderr, "node {} ({}) on DDS domain {}: waiting for keyframes\n", id, communication::taskName(task), o.domain);
  bool done = false;
  while (!g_stop && !(done = node.waitUntilDone(std::chrono::milliseconds(200)))) {
  }
  if (live) live->finish();
  nlohmann::json report = node.report(monitor.wallSeconds());
  report["thread_cpu_seconds"] = eval::ResourceMonitor::threadCpuSeconds();  // before threads end
  addSecurityReport(report);
  node.stop();
  slam.finish();
  const auto& ms = slam.mappingStats();
  const auto& ls = slam.loopStats();
  // Incomplete: an LC whose gateway left before its last snapshot, alone now. Released: TR's
  // link was too slow, and TR went on alone (its map is the run's map).
  report["end_of_run"] = !done ? "interrupted" : node.released() ? "released" : node.completed() ? "completed" : "incomplete";
  if (done && !node.completed() && !node.released())
    fmt::print(stderr, "warning: the gateway left before the end-of-run exchange completed; this node's map may lack its last snapshot\n");
  report["mapping"] = mappingStatsJson(ms);  // points_culled too: LM's report lacked it
  report["loop_closing"] = settings.loop_closing;
  report["loops"] = ls.loops;
  report["merges"] = ls.merges;
  report["global_bas"] = ls.global_bas;
  report["global_bas_discarded"] = ls.global_bas_discarded;  // the map moved while one ran: solved again later
  report["remeasured"] = remeasureJson(slam.remeasureReport(), ls.remeasured);
  report["global_ba_sigma"] = ls.global_ba_sigma;  // 0 on a node that ran none
  report["global_ba_scale_drift"] = ls.global_ba_scale_drift;  // 1 on a node that ran none
  report["loop_events"] = loopEventsJson(ls);
  size_t kfs = 0, points = 0;
  report["map_keyframes"] = nlohmann::json::array();
  for (const auto& m : slam.liveMaps()) {
    std::lock_guard lock(m->mutex);
    kfs += m->keyframes.size();
    points += m->points.size();
    report["map_keyframes"].push_back(m->keyframes.size());
  }
  report["map_points"] = points;
  report["keyframes"] = kfs;
  report["maps"] = report["map_keyframes"].size();
  report["cpu_seconds"] = monitor.cpuSeconds();
  report["wall_seconds"] = monitor.wallSeconds();
  report["cpu_percent"] = monitor.cpuPercent();
  report["peak_rss_mb"] = eval::ResourceMonitor::peakRssBytes() / 1048576.0;
  std::filesystem::create_directories(o.out);
  std::ofstream(std::filesystem::path(o.out) / "report.json") << report.dump(2) << "\n";
  if (!o.atlas_out.empty()) io::saveAtlas(o.atlas_out, slam.liveMaps());
  fmt::print("node {} ({}): {} keyframes mapped, {} loops, {} merges, {:.1f} s CPU, {:.2f} Mbps\n", id,
             communication::taskName(task), ms.keyframes_processed, ls.loops, ls.merges, monitor.cpuSeconds(),
             report["bandwidth_mbps"].get<double>());
}

}  // namespace

void addNodeCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("node", "Run one node (tr, lm or lc) of the distributed system over Fast DDS");
  cmd->footer("Example:\n  hiveslam node --task lm --domain 7 --out lm   (then, on the camera device:)\n  hiveslam node --task tr seq/figure8 --realtime --domain 7 --expect lm --out tr");
  auto o = std::make_shared<NodeCommandOptions>();
  cmd->add_option("--task", o->task, "tr (tracking), lm (local mapping) or lc (loop closing)")->required();
  cmd->add_option("DATASET", o->dataset, "TR's input: what `hiveslam run` reads");
  cmd->add_option("--topic", o->topic, "TR's input instead of a DATASET: a ROS 2 sensor_msgs/msg/Image topic (e.g. /camera/image_raw)");
  cmd->add_option("--calibration", o->calibration, "TR with --topic: camera file (settings YAML, sensor.yaml or calib.txt)");
  cmd->add_option("--ground-truth", o->ground_truth, "TR: score against this dataset's ground truth (for --topic)");
  cmd->add_option("--out", o->out, "Output folder")->required();
  cmd->add_option("--domain", o->domain, "DDS domain id (the ROS_DOMAIN_ID)")->capture_default_str();
  cmd->add_option("--name", o->name, "Node name (default: the task)");
  cmd->add_option("--id", o->id, "Node id, 1-65535: the high bits of the ids it makes (default: 1 tr, 2 lm, 3 lc)");
  cmd->add_option("--expect", o->expect, "TR: comma-separated tasks to wait for before the first frame (lm,lc), until they have heard this node too");
  cmd->add_option("--wait", o->wait_seconds, "TR: seconds to wait for --expect")->capture_default_str();
  cmd->add_option("--config", o->config, "Settings YAML");
  cmd->add_option("--times", o->times, "TR: times file for image folders and videos");
  cmd->add_flag("--realtime", o->realtime, "TR: feed frames at their timestamps");
  cmd->add_option("--repeat", o->repeat, "TR: play the DATASET this many times in a row (a long run out of a short sequence)");
  cmd->add_flag("--no-loop-closing", o->no_loop_closing, "Switch loop closing off");
  addViewerOptions(cmd, o->live);
  cmd->add_flag("--no-ros", o->no_ros, "Do not publish the ROS 2 visualization topics (/hiveslam/<name>/...)");
  cmd->add_option("--atlas-out", o->atlas_out, "Save the node's maps to an atlas file after the run (the same on every node after the end-of-run exchange)");
  addSecureOption(cmd, o->secure);
  cmd->callback([o]() {
    communication::Task task;
    if (!communication::parseTask(o->task, task)) throw InputError("unknown task '" + o->task + "' (tr, lm or lc)");
    if (o->domain < 0 || o->domain > 232) throw InputError("DDS domain must be 0-232");
    if (o->id < 0 || o->id > 65535) throw InputError("node id must be 1-65535");
    useSecureOption(o->secure, o->name.empty() ? communication::taskName(task) : o->name);
    if (task != communication::Task::Tracking) {
      if (!o->dataset.empty() || !o->topic.empty()) throw InputError("only a tr node reads images");
      serve(*o, task);
      return;
    }
    if (o->dataset.empty() == o->topic.empty()) throw InputError("a tr node reads a DATASET or a --topic (one of them)");
    RunOptions run;
    run.dataset = o->dataset;
    run.out = o->out;
    run.config = o->config;
    run.times = o->times;
    run.realtime = o->realtime;
    run.repeat = o->repeat;
    run.topic = o->topic;
    run.calibration = o->calibration;
    run.topic_domain = o->domain;
    run.ground_truth = o->ground_truth;
    run.no_loop_closing = o->no_loop_closing;
    run.atlas_out = o->atlas_out;
    run.network.enabled = true;
    run.network.domain = o->domain;
    run.network.id = o->id > 0 ? static_cast<uint16_t>(o->id) : 1;
    run.network.name = o->name.empty() ? "tr" : o->name;
    run.network.wait_seconds = o->wait_seconds;
    run.live = o->live;
    run.live.ros = !o->no_ros;
    std::string rest = o->expect;
    while (!rest.empty()) {
      const auto comma = rest.find(',');
      run.network.expect.push_back(rest.substr(0, comma));
      rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
    }
    fmt::print("{}\n", runSlam(run).line);
  });
}

}  // namespace hiveslam::apps
