// hiveslam run DATASET --out DIR: the standalone SLAM system on any input the readers know.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <chrono>
#include <fstream>
#include <thread>
#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "apps/run_slam.hpp"
#include "apps/progress.hpp"
#include "apps/topic_frame_source.hpp"
#include "common/error.hpp"
#include "communication/dds/dds_transport.hpp"
#include "communication/dds/node_announcement.hpp"
#include "communication/dds/participant_security.hpp"
#include "distribution/distributed_node.hpp"
#include "core/system/slam_system.hpp"
#include "eval/error_plots.hpp"
#include "eval/resource_monitor.hpp"
#include "eval/trajectory_error.hpp"
#include "eval/trajectory_plot.hpp"
#include "io/atlas_file.hpp"
#include "io/vocabulary_file.hpp"
#include "io/open_dataset.hpp"
#include "io/repeated_source.hpp"
#include "io/slam_settings_io.hpp"
#include "io/trajectory_io.hpp"

namespace hiveslam::apps {

void addSecurityReport(nlohmann::json& report) {
  report["secure"] = communication::secure();
  report["failed_handshakes"] = communication::failedHandshakes();
  report["announcements_dropped"] = communication::droppedAnnouncements();
}

nlohmann::json mappingStatsJson(const core::MappingStats& ms) {
  const core::MappingStageMs& t = ms.ms;
  const double n = std::max(ms.keyframes_processed, 1);
  return {{"keyframes_processed", ms.keyframes_processed}, {"points_created", ms.points_created},
          {"points_culled", ms.points_culled}, {"keyframes_culled", ms.keyframes_culled},
          {"local_bas", ms.local_bas}, {"local_bas_discarded", ms.local_bas_discarded},
          {"local_bas_cut_short", ms.local_bas_cut_short},
          {"ms_per_keyframe",
           {{"insert", t.insert / n}, {"cull_points", t.cull_points / n}, {"triangulate", t.triangulate / n},
            {"fuse", t.fuse / n}, {"local_ba_setup", t.local_ba_setup / n}, {"local_ba", t.local_ba / n},
            {"cull_keyframes", t.cull_keyframes / n}, {"total", t.total / n}, {"max_total", t.max_total}}}};
}

nlohmann::json remeasureJson(const core::SlamSystem::RemeasureReport& r, const core::RemeasurementUse& use) {
  return {{"measured_here", r.own},
          {"anchors", r.stats.anchors},
          {"kept_as_found", r.stats.kept},
          {"points_on_a_plane", r.stats.plane_normals},
          {"ms", r.ms},
          {"image_mb", r.image_mb},
          {"pyramids_built", r.pyramids},
          {"held_for_final_ba", r.total},
          {"final_ba", {{"applied", use.applied}, {"other_point", use.other_point}, {"other_anchor", use.other_anchor},
                        {"not_measured", use.not_measured}}}};
}

nlohmann::json loopEventsJson(const core::LoopStats& stats) {
  nlohmann::json events = nlohmann::json::array();
  for (const auto& e : stats.events)
    events.push_back({{"kind", e.kind == core::LoopEvent::Kind::Loop ? "loop" : "merge"},
                      {"timestamp", e.timestamp},
                      {"place_timestamp", e.place_timestamp},
                      {"matches", e.matches},
                      {"scale", e.scale},
                      {"scale_agreement", e.scale_agreement},
                      {"correct_ms", e.correct_ms},
                      {"essential_graph_ms", e.essential_graph_ms}});
  return events;
}

namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5))];
}

// One row per frame: what tracking did with it (the trajectory has the tracked frames' poses
// only). Drift is read against it: inliers that sag after keyframes, keyframes that bunch up.
void writeFrameLog(const std::filesystem::path& path, const std::vector<core::FrameRecord>& frames) {
  std::ofstream f(path);
  // reference: the keyframe the pose is kept relative to; reference_culled: it was erased
  // later, and the pose follows it through its anchor (KeyFrame::pose).
  f << "index,timestamp,tracked,inliers,keyframe,tracking_ms,map,reference,reference_culled\n";
  for (const auto& r : frames)
    f << fmt::format("{},{:.6f},{},{},{},{:.3f},{},{},{}\n", r.index, r.timestamp, r.tracked ? 1 : 0, r.inliers,
                     r.keyframe ? 1 : 0, r.tracking_ms, r.map, r.reference ? r.reference->id : core::kNoId,
                     r.reference && r.reference->bad ? 1 : 0);
  if (!f) throw InputError("cannot write " + path.string());
}

std::atomic<bool> g_interrupted{false};
extern "C" void onInterrupt(int) { g_interrupted = true; }

void waitForInterrupt(const std::string& message) {
  // The handlers first: a script that waits for the message and then interrupts must not find
  // SIGINT still ignored (bash starts a background job so).
  auto previous_int = std::signal(SIGINT, onInterrupt);
  auto previous_term = std::signal(SIGTERM, onInterrupt);
  fmt::print(stderr, "{}\n", message);
  while (!g_interrupted) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
}

}  // namespace

RunSummary runSlam(const RunOptions& o) {
  eval::ResourceMonitor monitor;
  io::DatasetOptions dataset_options;
  if (!o.config.empty()) dataset_options.settings = o.config;
  if (!o.times.empty()) dataset_options.times = o.times;
  std::unique_ptr<io::FrameSource> source;
  if (o.dataset.empty() == o.topic.empty()) throw InputError("give a DATASET or a --topic (one of them)");
  if (o.live.viewer_port > 65535) throw InputError("viewer port must be 0-65535");
  if (o.topic.empty()) {
    if (o.repeat == 1)
      source = io::openDataset(o.dataset, dataset_options);
    else
      source = std::make_unique<io::RepeatedSource>([&] { return io::openDataset(o.dataset, dataset_options); }, o.repeat);
  } else {
    const std::string calibration = o.calibration.empty() ? o.config : o.calibration;
    if (calibration.empty()) throw InputError("an image topic carries no calibration: pass --calibration FILE");
    source = std::make_unique<TopicFrameSource>(o.topic_domain, o.topic, io::loadCameraFile(calibration),
                                                std::chrono::seconds(o.topic_wait_seconds), std::chrono::seconds(3));
  }
  // Checked before the run, not after it: a wrong path must not cost the run its report.
  std::optional<io::Trajectory> truth = source->groundTruth();
  if (!o.ground_truth.empty()) {
    truth = io::openDataset(o.ground_truth)->groundTruth();
    if (!truth) throw InputError(o.ground_truth + " has no ground truth");
  }
  // A live topic paces itself; a dataset is paced here in real-time mode.
  const bool pace = o.realtime && o.topic.empty();
  const std::filesystem::path out(o.out);
  std::filesystem::create_directories(out);
  fmt::print(stderr, "{}\n", source->describe());

  core::SlamSettings settings;
  if (!o.config.empty()) io::applySlamSettings(o.config, settings);
  const auto mode = o.sequential ? core::SlamSystem::Mode::Sequential
                    : o.realtime || !o.topic.empty() ? core::SlamSystem::Mode::Realtime
                                 : core::SlamSystem::Mode::Offline;
  if (o.no_loop_closing || o.localization) settings.loop_closing = false;
  if (o.localization && o.atlas_in.empty()) throw InputError("--localization needs --atlas-in FILE");
  const auto vocabulary = io::loadVocabulary(settings);
  core::SlamSystem slam(settings, source->camera().camera, mode, vocabulary, o.network.enabled ? o.network.id : 0);
  // The distributed TR node: the same system, with the distribution layer on its seam.
  std::unique_ptr<communication::DdsTransport> transport;
  std::unique_ptr<distribution::DistributedNode> node;
  if (o.network.enabled) {
    distribution::DistributionSettings distribution_settings;
    if (!o.config.empty()) io::applyDistributionSettings(o.config, distribution_settings);
    communication::DdsOptions dds{o.network.domain};
    if (!o.config.empty()) io::applyDdsSettings(o.config, dds);
    transport = std::make_unique<communication::DdsTransport>(dds);
    node = std::make_unique<distribution::DistributedNode>(
        slam, *transport,
        distribution::NodeOptions{communication::Task::Tracking, o.network.id, o.network.name, distribution_settings});
    node->start();
    uint8_t want = 0;
    for (const auto& t : o.network.expect) {
      communication::Task task;
      if (!communication::parseTask(t, task)) throw InputError("unknown task '" + t + "' (tr, lm or lc)");
      want |= communication::taskBit(task);
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(o.network.wait_seconds);
    while ((node->mutualTasks() & want) != want && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if ((node->presentTasks() & want) != want)
      throw InputError(fmt::format("the expected peers ({}) did not appear within {} s on DDS domain {}",
                                   fmt::join(o.network.expect, ","), o.network.wait_seconds, o.network.domain));
    if ((node->mutualTasks() & want) != want)
      throw InputError(fmt::format("the expected peers ({}) appeared but did not hear this node within {} s on DDS domain {}",
                                   fmt::join(o.network.expect, ","), o.network.wait_seconds, o.network.domain));
  }
  if (!o.atlas_in.empty()) {
    const auto maps = io::loadAtlas(o.atlas_in, vocabulary.get());
    slam.loadAtlas(maps, o.localization);
    size_t kfs = 0;
    for (const auto& m : maps) kfs += m->keyframes.size();
    fmt::print(stderr, "atlas {}: {} maps, {} keyframes{}\n", o.atlas_in, maps.size(), kfs,
               o.localization ? " (localization only)" : "");
  }
  std::unique_ptr<LiveViewStack> live;
  if (o.live.any()) {
    LiveViewOptions lv = o.live;
    if (!o.config.empty()) io::applyViewSettings(o.config, lv.settings);
    if (node) {
      lv.node = o.network.name;
      lv.domain = o.network.domain;
    } else {
      lv.domain = o.topic_domain;
    }
    std::function<nlohmann::json()> node_report;
    if (node) node_report = [&node, &monitor] { return node->report(monitor.wallSeconds()); };
    live = std::make_unique<LiveViewStack>(lv, slam, node_report, [&slam] { return slam.hosting().mapping; });
  }
  Progress progress("tracking");
  const int total = static_cast<int>(source->size().value_or(0));
  int n = 0, dropped = 0;
  const auto wall_start = std::chrono::steady_clock::now();
  double first_stamp = -1, last_stamp = -1;
  while (auto frame = source->next()) {
    if (pace) {
      // A camera does not wait: a frame whose time has passed by more than a frame period
      // while the previous one was processed is dropped.
      if (first_stamp < 0) first_stamp = frame->timestamp;
      const double period = last_stamp < 0 ? 0.05 : frame->timestamp - last_stamp;
      last_stamp = frame->timestamp;
      const auto due = wall_start + std::chrono::duration<double>(frame->timestamp - first_stamp);
      const auto now = std::chrono::steady_clock::now();
      if (now > due + std::chrono::duration<double>(period)) {
        ++dropped;
        ++n;
        continue;
      }
      std::this_thread::sleep_until(due);
    }
    const auto& r = slam.process(frame->image, frame->timestamp);
    if (o.verbose)
      fmt::print(stderr, "frame {} t {:.3f} {} inliers {} {}\n", r.index, r.timestamp, r.tracked ? "tracked" : "LOST",
                 r.inliers, r.keyframe ? "keyframe" : "");
    else
      progress.update(++n, total > 0 ? std::max(total, n) : 0);
    if (o.verbose) ++n;
    if (o.max_frames > 0 && n >= o.max_frames) break;
  }
  nlohmann::json node_report;
  if (node) {
    const bool completed = node->finishRun(std::chrono::seconds(120));
    if (!completed)
      fmt::print(stderr, "warning: the end-of-run exchange did not complete; the maps may differ between nodes\n");
    node_report = node->report(monitor.wallSeconds());
    node_report["end_of_run"] = completed ? "completed" : "incomplete";
    addSecurityReport(node_report);
  } else {
    slam.drain();  // the end of the run: the last keyframes mapped, the final global BA
  }
  if (live) live->finish();  // the final maps on the page, before the node leaves
  // Before the threads end: a thread that has ended is no longer in /proc.
  const auto thread_cpu = eval::ResourceMonitor::threadCpuSeconds();
  if (node) node->stop();
  slam.finish();
  const int frames_refined = slam.refineFrames();

  // Trajectory: every tracked frame of the largest map, through its reference keyframe.
  io::Trajectory estimate, keyframes;
  std::vector<double> tracking_ms;
  int tracked = 0;
  const auto map = slam.largestMap();
  for (const auto& r : slam.frames()) {
    tracking_ms.push_back(r.tracking_ms);
    if (!r.tracked) continue;
    ++tracked;
    if (map && slam.currentMapId(r.map) == map->id) estimate.add(r.timestamp, slam.poseOf(r));
  }
  const auto maps = slam.liveMaps();
  size_t keyframe_count = 0;
  for (const auto& m : maps) keyframe_count += m->keyframes.size();
  if (map) {
    std::vector<std::shared_ptr<core::KeyFrame>> kfs;
    for (const auto& [id, kf] : map->keyframes) kfs.push_back(kf);
    std::sort(kfs.begin(), kfs.end(), [](const auto& a, const auto& b) { return a->frame.timestamp < b->frame.timestamp; });
    for (const auto& kf : kfs) keyframes.add(kf->frame.timestamp, kf->T_cw.inverse());
  }
  io::writeTrajectory(out / "trajectory.tum", estimate, io::TrajectoryFormat::Tum);
  if (!o.atlas_out.empty()) io::saveAtlas(o.atlas_out, slam.liveMaps());
  io::writeTrajectory(out / "keyframes.tum", keyframes, io::TrajectoryFormat::Tum);
  writeFrameLog(out / "frames.csv", slam.frames());

  nlohmann::json report;
  report["dataset"] = o.dataset;
  report["frames"] = n;
  report["tracked_frames"] = tracked;
  report["frames_refined"] = frames_refined;
  report["failures"] = slam.failures();
  report["relocalized_in_known_map"] = slam.relocalizedInKnownMap();
  report["keyframes_deferred"] = slam.keyframesDeferred();
  report["keyframes_made_busy"] = slam.keyframesMadeBusy();
  report["keyframes"] = keyframe_count;
  report["maps"] = maps.size();
  report["map_keyframes"] = nlohmann::json::array();
  for (const auto& m : maps) report["map_keyframes"].push_back(m->keyframes.size());
  size_t point_count = 0;
  for (const auto& m : maps) point_count += m->points.size();
  report["map_points"] = point_count;
  const auto& ls = slam.loopStats();
  report["loop_closing"] = settings.loop_closing;
  report["loops"] = ls.loops;
  report["merges"] = ls.merges;
  report["global_bas"] = ls.global_bas;
  report["remeasured"] = remeasureJson(slam.remeasureReport(), ls.remeasured);
  std::vector<eval::PlotEvent> plot_events;
  report["loop_events"] = loopEventsJson(ls);
  for (const auto& e : ls.events) plot_events.push_back({e.timestamp, e.kind == core::LoopEvent::Kind::Loop ? "loop" : "merge"});
  report["loop_timing"] = {{"keyframes_checked", ls.keyframes_checked},
                           {"query_ms_mean", ls.query_ms_total / std::max(ls.keyframes_checked, 1)},
                           {"rejected_geometry", ls.rejected_geometry},
                           {"global_bas_discarded", ls.global_bas_discarded},
                           {"global_ba_ms", ls.global_ba_ms},
                           {"global_ba_sigma", ls.global_ba_sigma},
                           {"global_ba_scale_drift", ls.global_ba_scale_drift}};
  if (const auto* topic = dynamic_cast<const TopicFrameSource*>(source.get()))
    dropped += static_cast<int>(topic->dropped());  // images the reader had to let go
  const bool realtime = mode == core::SlamSystem::Mode::Realtime;
  report["mode"] = o.sequential ? "sequential" : realtime ? "realtime" : "offline";
  report["localization_only"] = o.localization;
  if (realtime) report["dropped_frames"] = dropped;
  report["cpu_seconds"] = monitor.cpuSeconds();
  report["thread_cpu_seconds"] = thread_cpu;
  report["wall_seconds"] = monitor.wallSeconds();
  report["cpu_percent"] = monitor.cpuPercent();
  report["peak_rss_mb"] = eval::ResourceMonitor::peakRssBytes() / 1048576.0;
  double sum = 0;
  for (double t : tracking_ms) sum += t;
  report["tracking_ms"] = {{"median", percentile(tracking_ms, 0.5)},
                           {"mean", tracking_ms.empty() ? 0.0 : sum / tracking_ms.size()},
                           {"p95", percentile(tracking_ms, 0.95)}};
  const auto& ms = slam.mappingStats();
  report["mapping"] = mappingStatsJson(ms);
  std::string ate_line = "no ground truth";
  if (truth && estimate.size() >= 3) {
    try {
      const auto ate = eval::computeAte(*truth, estimate);
      report["ate"] = eval::toJson(ate.stats);
      report["ate"]["path_length"] = ate.reference_length;
      report["ate"]["percent_of_path"] = 100.0 * ate.stats.rmse / std::max(ate.reference_length, 1e-9);
      const std::string title =
          fmt::format("ATE RMSE {:.4f} m over {:.1f} m ({} poses)", ate.stats.rmse, ate.reference_length, ate.stats.count);
      eval::plotTopView(out / "trajectory.png", ate.pair.ref, ate.pair.est, {title, 900, plot_events});
      eval::plotErrorOverTime(out / "error_time.png", ate, title);
      eval::plotAxisErrors(out / "error_axes.png", ate, title);
      ate_line = fmt::format("ATE RMSE {:.4f} m ({:.2f}% of {:.1f} m)", ate.stats.rmse,
                             100.0 * ate.stats.rmse / std::max(ate.reference_length, 1e-9), ate.reference_length);
    } catch (const InputError& e) {
      ate_line = std::string("ATE not computed: ") + e.what();
    }
  }
  if (node) report.update(node_report);
  std::ofstream(out / "report.json") << report.dump(2) << "\n";
  if (live && o.viewer_wait && live->port() >= 0) waitForInterrupt(fmt::format("run over: the live view stays at port {} until Ctrl-C", live->port()));
  RunSummary summary;
  summary.report = report;
  summary.line = fmt::format("frames {} tracked {} ({:.1f}%) failures {} keyframes {} maps {} | {} | tracking median {:.1f} ms",
                             n, tracked, 100.0 * tracked / std::max(n, 1), slam.failures(), keyframe_count,
                             maps.size(), ate_line, percentile(tracking_ms, 0.5));
  if (settings.loop_closing) summary.line += fmt::format(" | loops {} merges {}", ls.loops, ls.merges);
  return summary;
}

void addRunCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "Run standalone monocular SLAM on a dataset");
  cmd->footer("Example:\n  hiveslam run seq/figure8 --realtime --out out/figure8 --viewer 8080   (then open http://localhost:8080/)");
  auto o = std::make_shared<RunOptions>();
  cmd->add_option("DATASET", o->dataset, "EuRoC/TUM-VI folder, TUM RGB-D folder, image folder or video");
  cmd->add_option("--topic", o->topic, "Instead of a DATASET: a ROS 2 sensor_msgs/msg/Image topic (e.g. /camera/image_raw)");
  cmd->add_option("--calibration", o->calibration, "With --topic: camera file (settings YAML, sensor.yaml or calib.txt)");
  cmd->add_option("--domain", o->topic_domain, "With --topic: DDS domain id (the ROS_DOMAIN_ID)")->capture_default_str();
  cmd->add_option("--ground-truth", o->ground_truth, "Score against this dataset's ground truth (for --topic)");
  cmd->add_option("--config", o->config, "Settings YAML: its camera section replaces the dataset's calibration, its slam, distribution and dds sections override the defaults");
  cmd->add_option("--times", o->times, "Times file for image folders and videos");
  cmd->add_option("--out", o->out, "Output folder")->required();
  cmd->add_flag("--sequential", o->sequential, "Lockstep tracking and mapping on one thread (deterministic)");
  cmd->add_flag("--realtime", o->realtime, "Feed frames at their timestamps; tracking never waits for mapping");
  cmd->add_option("--max-frames", o->max_frames, "Stop after this many frames");
  cmd->add_option("--repeat", o->repeat, "Play the DATASET this many times in a row (a long run out of a short sequence)");
  cmd->add_flag("--no-loop-closing", o->no_loop_closing, "Switch loop closing and map merging off");
  cmd->add_option("--atlas-in", o->atlas_in, "Load the maps of a saved atlas before the run");
  cmd->add_option("--atlas-out", o->atlas_out, "Save the maps to an atlas file after the run");
  cmd->add_flag("--localization", o->localization, "Track against --atlas-in without mapping");
  cmd->add_flag("--verbose", o->verbose, "One line per frame instead of the progress line");
  addViewerOptions(cmd, o->live);
  addSecureOption(cmd, o->secure);
  cmd->add_flag("--viewer-wait", o->viewer_wait, "With --viewer: keep serving the page after the run, until Ctrl-C");
  cmd->add_flag("--ros", o->live.ros, "Publish the ROS 2 visualization topics (/hiveslam/<name>/pose, path, tf, points, keyframe_markers, status) on --domain");
  cmd->add_option("--name", o->live.node, "With --ros or --viewer: the name in topic names and on the page")->capture_default_str();
  cmd->callback([o]() {
    useSecureOption(o->secure, "tr");  // a standalone system is a tracking node
    fmt::print("{}\n", runSlam(*o).line);
  });
}

}  // namespace hiveslam::apps
