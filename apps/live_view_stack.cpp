#include "apps/live_view_stack.hpp"

#include <fmt/format.h>

#include "communication/dds/participant_security.hpp"
#include "viz/live_view.hpp"
#include "viz/local_feed.hpp"
#include "viz/ros/ros_messages.hpp"
#include "viz/ros/ros_viz_publisher.hpp"
#include "viz/web/web_viewer.hpp"

namespace hiveslam::apps {

void addViewerOptions(CLI::App* cmd, LiveViewOptions& o) {
  cmd->add_option("--viewer", o.viewer_port, "Serve the live view at http://HOST:PORT/ (0: any free port)");
  cmd->add_option("--viewer-host", o.viewer_host,
                  "Address the live view listens on (0.0.0.0: every interface, for a browser on another device)")
      ->capture_default_str();
}

LiveViewStack::LiveViewStack(const LiveViewOptions& o, core::SlamSystem& slam, std::function<nlohmann::json()> node_report,
                             std::function<bool()> publishes_map)
    : view_(std::make_unique<viz::LiveView>()) {
  if (o.viewer_port >= 0) {
    web_ = std::make_unique<viz::web::WebViewer>(*view_, o.viewer_host, o.viewer_port, o.settings);
    fmt::print(stderr, "live view: http://{}:{}/\n", o.viewer_host == "0.0.0.0" ? "localhost" : o.viewer_host, web_->port());
  }
  // A secure identity may write only its own name's topics: under another name they would be
  // refused one by one, on the publisher's thread.
  const bool ros_allowed = communication::mayWrite(viz::ros::vizTopic(o.node, "pose"));
  if (o.ros && !ros_allowed)
    fmt::print(stderr, "warning: this identity's permissions leave out /hiveslam/{}/...: no ROS 2 topics\n", o.node);
  if (o.ros && ros_allowed)
    ros_ = std::make_unique<viz::ros::RosVizPublisher>(*view_, o.domain, o.node, o.settings, std::move(publishes_map));
  // Last: its thread asks the page and the topics whether anyone reads the maps.
  feed_ = std::make_unique<viz::LocalFeed>(*view_, o.node, slam, o.settings, std::move(node_report), [this] {
    return (web_ && web_->pages() > 0) || (ros_ && ros_->wantsMap());
  });
}

LiveViewStack::~LiveViewStack() {
  feed_.reset();
  ros_.reset();
  view_->close();
  web_.reset();
}

void LiveViewStack::finish() { feed_->stop(); }

int LiveViewStack::port() const { return web_ ? web_->port() : -1; }

}  // namespace hiveslam::apps
