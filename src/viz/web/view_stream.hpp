#pragma once
// What one web page is sent, as server-sent events: the panel of every node (on change), each
// node's camera (at most 15 Hz), its trajectory (appended positions), its maps (points, map
// labels, keyframe frusta and edges, when changed, at most ViewSettings::cloud_hz) and its
// image with its features drawn (image_hz). Maps and images share a byte budget per page
// (web_kbytes_per_s, a token bucket): over a slow link they come less often, the rest keeps
// coming. One stream per page, used on that page's HTTP thread.
#include <chrono>
#include <map>
#include <string>

#include "viz/live_view.hpp"
#include "viz/view_settings.hpp"

namespace hiveslam::viz::web {

class ViewStream {
 public:
  ViewStream(const LiveView& view, ViewSettings settings);
  // The next events, "event: NAME\ndata: JSON\n\n" each; waits at most `wait` for something to
  // send, and returns "" when there was none (or the view closed).
  std::string next(std::chrono::milliseconds wait);
  // Bytes returned so far.
  uint64_t bytes() const { return bytes_; }

 private:
  using Clock = std::chrono::steady_clock;
  struct Sent {
    uint64_t frame_version = 0, scene_version = 0, path_epoch = 0, image_frame = ~uint64_t{0};
    size_t path_size = 0;
    Clock::time_point next_camera{}, next_scene{}, next_image{};
  };
  std::string collect();
  const LiveView& view_;
  ViewSettings settings_;
  std::map<std::string, Sent> sent_;
  uint64_t seen_ = ~uint64_t{0};
  uint64_t panel_stamp_ = 0;
  Clock::time_point panel_sent_{};
  double tokens_ = 0;  // bytes the budget allows now (may go negative after a large message)
  Clock::time_point last_refill_ = Clock::now();
  uint64_t bytes_ = 0;
};

// Standard base64 (RFC 4648, with padding).
std::string base64(const void* data, size_t size);

}  // namespace hiveslam::viz::web
