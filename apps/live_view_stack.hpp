#pragma once
// The live view of one process, as its command line asks: the model, the feed from its SLAM
// system, the web page (--viewer PORT) and the ROS 2 topics (--ros, or a node's default).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <string>

#include "core/system/slam_system.hpp"
#include "viz/view_settings.hpp"

namespace hiveslam::viz {
class LiveView;
class LocalFeed;
namespace web {
class WebViewer;
}
namespace ros {
class RosVizPublisher;
}
}  // namespace hiveslam::viz

namespace hiveslam::apps {

struct LiveViewOptions {
  int viewer_port = -1;  // -1: no web page; 0: any free port
  std::string viewer_host = "127.0.0.1";
  bool ros = false;  // publish the ROS 2 visualization topics
  int domain = 0;
  std::string node = "hiveslam";  // the name in topic names and on the page
  viz::ViewSettings settings;
  bool any() const { return viewer_port >= 0 || ros; }
};

// --viewer PORT and --viewer-host on `cmd`.
void addViewerOptions(CLI::App* cmd, LiveViewOptions& o);

class LiveViewStack {
 public:
  // `node_report`: a distributed node's report, for the panel; `publishes_map`: whether the
  // points and keyframes go out on ROS from this node now (it hosts local mapping).
  LiveViewStack(const LiveViewOptions& o, core::SlamSystem& slam, std::function<nlohmann::json()> node_report,
                std::function<bool()> publishes_map);
  ~LiveViewStack();
  // The run is over: the last maps and panel are shown (the page stays up until destruction).
  void finish();
  int port() const;

 private:
  std::unique_ptr<viz::LiveView> view_;
  std::unique_ptr<viz::LocalFeed> feed_;
  std::unique_ptr<viz::web::WebViewer> web_;
  std::unique_ptr<viz::ros::RosVizPublisher> ros_;
};

}  // namespace hiveslam::apps
