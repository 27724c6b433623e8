#include "viz/web/view_stream.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace hiveslam::viz::web {

namespace {

constexpr double kCameraHz = 15;  // a browser redraws at 60 Hz; 15 poses a second look smooth

std::string event(const char* name, const nlohmann::json& data) {
  return std::string("event: ") + name + "\ndata: " + data.dump() + "\n\n";
}

template <class T>
std::string base64Of(const std::vector<T>& v) {
  return base64(v.data(), v.size() * sizeof(T));
}

std::vector<float> flatten(const std::vector<Eigen::Vector3f>& v) {
  std::vector<float> out;
  out.reserve(v.size() * 3);
  for (const auto& p : v) out.insert(out.end(), {p.x(), p.y(), p.z()});
  return out;
}

// The image with every keypoint (orange) and those matched to the map (green), as JPEG.
std::string drawnImage(const LiveFrame& f) {
  cv::Mat bgr;
  if (f.image.channels() == 1)
    cv::cvtColor(f.image, bgr, cv::COLOR_GRAY2BGR);
  else
    bgr = f.image.clone();
  const double scale = bgr.cols > 640 ? 640.0 / bgr.cols : 1.0;
  if (scale < 1) cv::resize(bgr, bgr, cv::Size(), scale, scale, cv::INTER_AREA);
  for (const auto& p : f.features) cv::circle(bgr, p * scale, 2, cv::Scalar(0, 140, 255), 1, cv::LINE_AA);
  for (const auto& p : f.matched) cv::rectangle(bgr, cv::Rect2f(p * scale - cv::Point2f(2.5f, 2.5f), cv::Size2f(5, 5)), cv::Scalar(0, 220, 0), 1);
  std::vector<uchar> jpeg;
  cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 60});
  return base64(jpeg.data(), jpeg.size());
}

}  // namespace

std::string base64(const void* data, size_t size) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* b = static_cast<const uint8_t*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 3 <= size; i += 3) {
    const uint32_t v = (uint32_t{b[i]} << 16) | (uint32_t{b[i + 1]} << 8) | b[i + 2];
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  if (i < size) {
    const uint32_t v = (uint32_t{b[i]} << 16) | (i + 1 < size ? uint32_t{b[i + 1]} << 8 : 0);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < size ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

ViewStream::ViewStream(const LiveView& view, ViewSettings settings) : view_(view), settings_(settings) {
  tokens_ = settings_.web_kbytes_per_s * 1000.0;  // the first map goes at once
}

std::string ViewStream::next(std::chrono::milliseconds wait) {
  // Also wakes for due work when nothing changed (a map held back by the budget).
  if (seen_ != ~uint64_t{0}) view_.waitForChange(seen_, wait);
  if (view_.closed()) return "";
  seen_ = view_.version();
  std::string out = collect();
  bytes_ += out.size();
  return out;
}

std::string ViewStream::collect() {
  const auto now = Clock::now();
  const double rate = settings_.web_kbytes_per_s * 1000.0;
  tokens_ = std::min(tokens_ + rate * std::chrono::duration<double>(now - last_refill_).count(), rate);
  last_refill_ = now;
  auto every = [](double hz) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / std::max(hz, 1e-3)));
  };

  // Copies under the view's lock; encoding after it.
  struct Work {
    std::string node;
    std::optional<LiveFrame> camera, image;
    std::vector<PathPose> path_tail;
    bool path_reset = false;
    std::shared_ptr<const MapScene> scene;
  };
  std::vector<Work> work;
  nlohmann::json panel;
  bool panel_changed = false;
  view_.read([&](const std::map<std::string, NodeState>& nodes) {
    uint64_t stamp = nodes.size();
    for (const auto& [name, n] : nodes) stamp = stamp * 1000003 + n.panel_version * 7919 + n.events_total;
    // Also once a second unchanged: a page sees that the node is there after its run ended.
    panel_changed = stamp != panel_stamp_ || now - panel_sent_ >= std::chrono::seconds(1);
    panel_stamp_ = stamp;
    if (panel_changed) panel_sent_ = now;
    if (panel_changed) {
      panel = nlohmann::json::array();
      for (const auto& [name, n] : nodes) {
        nlohmann::json events = nlohmann::json::array();
        for (const auto& e : n.events) events.push_back({{"t", std::round(e.seconds * 10) / 10}, {"text", e.text}});
        panel.push_back({{"name", name}, {"values", n.panel}, {"events", events}});
      }
    }
    for (const auto& [name, n] : nodes) {
      Sent& s = sent_[name];
      Work w;
      w.node = name;
      if (n.frame && n.frame_version != s.frame_version && now >= s.next_camera) {
        w.camera = LiveFrame{n.frame->index, n.frame->timestamp, n.frame->tracked, n.frame->inliers, n.frame->map,
                             n.frame->tracking_ms, n.frame->T_wc, cv::Mat(), {}, {}};
        s.frame_version = n.frame_version;
        s.next_camera = now + every(kCameraHz);
      }
      if (n.frame && !n.frame->image.empty() && n.frame->index != s.image_frame && now >= s.next_image && tokens_ > 0) {
        w.image = *n.frame;
        s.image_frame = n.frame->index;
        s.next_image = now + every(settings_.image_hz);
      }
      // The path goes with the camera (at most kCameraHz), not with every frame.
      const bool path_due = w.camera.has_value() || n.path_epoch != s.path_epoch;
      if (path_due && (n.path_epoch != s.path_epoch || n.path.size() < s.path_size)) {
        w.path_reset = true;
        s.path_epoch = n.path_epoch;
        s.path_size = 0;
      }
      if (path_due && n.path.size() > s.path_size) {
        w.path_tail.assign(n.path.begin() + static_cast<long>(s.path_size), n.path.end());
        s.path_size = n.path.size();
      }
      if (n.scene && n.scene_version != s.scene_version && now >= s.next_scene && tokens_ > 0) {
        w.scene = n.scene;
        s.scene_version = n.scene_version;
        s.next_scene = now + every(settings_.cloud_hz);
      }
      work.push_back(std::move(w));
    }
  });

  std::string out;
  if (panel_changed) out += event("panel", {{"nodes", panel}, {"t", view_.seconds()}});
  for (const auto& w : work) {
    if (w.camera) {
      const Eigen::Matrix4f T = w.camera->T_wc.matrix().cast<float>();
      out += event("camera", {{"node", w.node},
                              {"frame", w.camera->index},
                              {"tracked", w.camera->tracked},
                              {"inliers", w.camera->inliers},
                              {"T", std::vector<float>(T.data(), T.data() + 16)}});
    }
    if (w.path_reset || !w.path_tail.empty()) {
      std::vector<float> xyz;
      xyz.reserve(w.path_tail.size() * 3);
      for (const auto& p : w.path_tail) {
        const Eigen::Vector3d t = p.T_wc.translation();
        xyz.insert(xyz.end(), {static_cast<float>(t.x()), static_cast<float>(t.y()), static_cast<float>(t.z())});
      }
      out += event("path", {{"node", w.node}, {"reset", w.path_reset}, {"xyz", base64Of(xyz)}});
    }
    if (w.scene) {
      const MapScene& s = *w.scene;
      std::vector<float> xyz;
      std::vector<uint8_t> label;
      std::vector<uint64_t> maps;  // label i: the i-th map met (index 255 takes the rest)
      xyz.reserve(s.points.size() * 3);
      label.reserve(s.points.size());
      for (const auto& p : s.points) {
        xyz.insert(xyz.end(), {p.x, p.y, p.z});
        auto it = std::find(maps.begin(), maps.end(), p.map);
        if (it == maps.end() && maps.size() < 255) it = maps.insert(maps.end(), p.map);
        label.push_back(static_cast<uint8_t>(std::min<long>(it - maps.begin(), 255)));
      }
      const SceneLines lines = sceneLines(s);
      const std::string e = event("scene", {{"node", w.node},
                                            {"points", base64Of(xyz)},
                                            {"labels", base64Of(label)},
                                            {"maps", maps.size()},
                                            {"frusta", base64Of(flatten(lines.frusta))},
                                            {"covisibility", base64Of(flatten(lines.covisibility))},
                                            {"loops", base64Of(flatten(lines.loops))}});
      tokens_ -= static_cast<double>(e.size());
      out += e;
    }
    if (w.image) {
      const std::string e = event("image", {{"node", w.node}, {"frame", w.image->index}, {"jpeg", drawnImage(*w.image)}});
      tokens_ -= static_cast<double>(e.size());
      out += e;
    }
  }
  return out;
}

}  // namespace hiveslam::viz::web
