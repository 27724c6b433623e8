#include "viz/local_feed.hpp"

#include <time.h>

#include <algorithm>

#include "common/thread_name.hpp"
#include "core/map/map.hpp"

namespace hiveslam::viz {

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + t.tv_nsec * 1e-9;
}

LocalFeed::LocalFeed(LiveView& view, std::string node, core::SlamSystem& slam, ViewSettings settings,
                     std::function<nlohmann::json()> node_report, std::function<bool()> wants_scene)
    : view_(view),
      node_(std::move(node)),
      slam_(slam),
      settings_(settings),
      node_report_(std::move(node_report)),
      wants_scene_(std::move(wants_scene)) {
  last_cpu_ = processCpuSeconds();
  slam_.setFrameListener([this](const core::FrameRecord& r, const Eigen::Isometry3d& T_cw,
                                const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& gray) {
    onFrame(r, T_cw, keypoints, gray);
  });
  thread_ = std::thread([this] { run(); });
}

LocalFeed::~LocalFeed() {
  stop();
  slam_.setFrameListener(nullptr);
}

void LocalFeed::stop() {
  if (stop_.exchange(true)) return;
  if (thread_.joinable()) thread_.join();
  refreshScene(true);
  refreshPanel(view_.seconds());
}

void LocalFeed::onFrame(const core::FrameRecord& r, const Eigen::Isometry3d& T_cw,
                        const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& gray) {
  LiveFrame f;
  f.index = r.index;
  f.timestamp = r.timestamp;
  f.tracked = r.tracked;
  f.inliers = r.inliers;
  f.map = r.map;
  f.tracking_ms = r.tracking_ms;
  if (r.tracked) f.T_wc = T_cw.inverse();
  f.image = gray;
  f.features.reserve(keypoints.size());
  for (const auto& k : keypoints) f.features.push_back(k.pt);
  f.matched.reserve(r.observations.size());
  for (const auto& o : r.observations) f.matched.emplace_back(o.uv.x(), o.uv.y());
  {
    std::lock_guard lock(counts_mutex_);
    ++frames_;
    if (r.tracked) ++tracked_;
    if (r.keyframe) ++keyframes_made_;
    recent_tracking_ms_.push_back(r.tracking_ms);
  }
  view_.setFrame(node_, std::move(f));
}

void LocalFeed::run() {
  nameThisThread("viz-feed");
  using Clock = std::chrono::steady_clock;
  const auto every = [](double hz) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / std::max(hz, 1e-3)));
  };
  auto next_scene = Clock::now(), next_panel = Clock::now();
  while (!stop_) {
    const auto now = Clock::now();
    // Unwatched, the maps are not copied: their locks stay the tracker's and mapper's. Whether
    // anyone watches is asked again at the scene's rate (the next time must move on either way:
    // left in the past, this loop spun and took 40-50% of a core in every node).
    if (now >= next_scene) {
      if (!wants_scene_ || wants_scene_()) refreshScene(false);
      next_scene = now + every(settings_.cloud_hz);
    }
    if (now >= next_panel) {
      refreshPanel(view_.seconds());
      next_panel = now + every(settings_.status_hz);
    }
    std::this_thread::sleep_until(std::min({next_scene, next_panel, now + std::chrono::milliseconds(100)}));
  }
}

void LocalFeed::refreshScene(bool force) {
  const auto maps = slam_.liveMaps();
  const uint64_t fingerprint = sceneFingerprint(maps);
  if (!force && fingerprint == scene_fingerprint_) return;
  scene_fingerprint_ = fingerprint;
  view_.setScene(node_, std::make_shared<const MapScene>(captureScene(maps)));
}

void LocalFeed::refreshPanel(double seconds) {
  nlohmann::json p;
  p["name"] = node_;
  std::vector<double> ms;
  {
    std::lock_guard lock(counts_mutex_);
    p["frames"] = frames_;
    p["tracked_frames"] = tracked_;
    p["keyframes_made"] = keyframes_made_;
    ms.swap(recent_tracking_ms_);
  }
  if (!ms.empty()) {
    std::nth_element(ms.begin(), ms.begin() + static_cast<long>(ms.size() / 2), ms.end());
    p["tracking_ms"] = ms[ms.size() / 2];
  }
  size_t keyframes = 0, points = 0;
  const auto maps = slam_.liveMaps();
  for (const auto& m : maps) {
    std::lock_guard lock(m->mutex);
    keyframes += m->keyframes.size();
    points += m->points.size();
  }
  p["maps"] = maps.size();
  p["keyframes"] = keyframes;
  p["map_points"] = points;
  const auto counts = slam_.liveCounts();
  p["maps_made"] = counts.maps_made;
  p["loops"] = counts.loops;
  p["merges"] = counts.merges;
  const double cpu = processCpuSeconds(), dt = std::max(seconds - last_seconds_, 1e-3);
  p["cpu_percent"] = 100.0 * (cpu - last_cpu_) / dt;
  last_cpu_ = cpu;
  if (node_report_) {
    const nlohmann::json r = node_report_();
    p["tasks"] = r.value("tasks", nlohmann::json::array());
    p["peers"] = r.value("peers", 0);
    const uint64_t in = r.value("bytes_in", uint64_t{0}), out = r.value("bytes_out", uint64_t{0});
    uint64_t kf_msgs = 0, map_msgs = 0;
    const nlohmann::json topics = r.value("topics", nlohmann::json::object());
    for (const auto& [name, t] : topics.items()) {
      const uint64_t msgs = t.value("messages_in", uint64_t{0}) + t.value("messages_out", uint64_t{0});
      (name.find("keyframes") != std::string::npos ? kf_msgs : map_msgs) += msgs;
    }
    p["kbps_in"] = (in - std::min(in, last_bytes_in_)) * 8.0 / 1000.0 / dt;
    p["kbps_out"] = (out - std::min(out, last_bytes_out_)) * 8.0 / 1000.0 / dt;
    p["keyframe_msgs_hz"] = (kf_msgs - std::min(kf_msgs, last_kf_msgs_)) / dt;
    p["map_msgs_hz"] = (map_msgs - std::min(map_msgs, last_map_msgs_)) / dt;
    last_bytes_in_ = in;
    last_bytes_out_ = out;
    last_kf_msgs_ = kf_msgs;
    last_map_msgs_ = map_msgs;
  } else {
    p["tasks"] = {"tr", "lm", "lc"};
    p["peers"] = 0;
  }
  last_seconds_ = seconds;
  view_.setPanel(node_, std::move(p));
}

}  // namespace hiveslam::viz
