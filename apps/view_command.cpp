// hiveslam view --domain N --port P: the live view of a running cluster, read from its ROS 2
// topics and announcements. It joins as a listener with no task: no node sees it as a peer.
#include <fmt/format.h>
#include <sys/resource.h>

#include <atomic>
#include <csignal>
#include <chrono>
#include <memory>
#include <thread>

#include "apps/commands.hpp"
#include "apps/secure_option.hpp"
#include "common/error.hpp"
#include "io/slam_settings_io.hpp"
#include "viz/live_view.hpp"
#include "viz/ros/ros_viz_reader.hpp"
#include "viz/web/web_viewer.hpp"

namespace hiveslam::apps {

namespace {

std::atomic<bool> g_stop_view{false};
extern "C" void onViewSignal(int) { g_stop_view = true; }

struct ViewOptions {
  int domain = 0, port = 8080;
  std::string host = "127.0.0.1", config;
  double seconds = 0;  // 0: until Ctrl-C
  int nice = 10;
  SecureOption secure;
};

void serveView(const ViewOptions& o) {
  // Before any thread starts (Fast DDS's, the web server's): threads take their creator's
  // niceness. A view on a device that runs SLAM nodes gives way to them.
  if (o.nice > 0 && setpriority(PRIO_PROCESS, 0, o.nice) != 0)
    fmt::print(stderr, "view: could not lower its priority (nice {}); it runs at the default\n", o.nice);
  viz::ViewSettings settings;
  if (!o.config.empty()) io::applyViewSettings(o.config, settings);
  useSecureOption(o.secure, "view");
  viz::LiveView view;
  viz::ros::RosVizReader reader(view, o.domain);
  viz::web::WebViewer web(view, o.host, o.port, settings);
  fmt::print(stderr, "live view of DDS domain {}: http://{}:{}/\n", o.domain, o.host == "0.0.0.0" ? "localhost" : o.host,
             web.port());
  std::signal(SIGINT, onViewSignal);
  std::signal(SIGTERM, onViewSignal);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.seconds);
  while (!g_stop_view && (o.seconds <= 0 || std::chrono::steady_clock::now() < end))
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  view.close();
  fmt::print("view: {} messages read, {} dropped, {} KB sent to pages\n", reader.received(), reader.dropped(),
             web.bytesSent() / 1000);
}

}  // namespace

void addViewCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("view", "Serve the live view of a running cluster (joins as a listener, takes no task)");
  cmd->footer("Example:\n  hiveslam view --domain 7 --port 8080   (then open http://localhost:8080/)");
  auto o = std::make_shared<ViewOptions>();
  cmd->add_option("--domain", o->domain, "DDS domain id of the cluster")->capture_default_str();
  cmd->add_option("--port", o->port, "HTTP port (0: any free port)")->capture_default_str();
  cmd->add_option("--host", o->host, "Address to listen on (0.0.0.0: every interface)")->capture_default_str();
  cmd->add_option("--config", o->config, "Settings YAML: its view section sets the rates and the page's byte budget");
  cmd->add_option("--seconds", o->seconds, "Stop after this many seconds (default: at Ctrl-C)");
  cmd->add_option("--nice", o->nice, "Niceness of the view's threads (0-19): it gives way to SLAM nodes on the same device")
      ->capture_default_str();
  addSecureOption(cmd, o->secure);
  cmd->callback([o] {
    if (o->nice < 0 || o->nice > 19) throw InputError("--nice must be 0-19");
    if (o->domain < 0 || o->domain > 232) throw InputError("DDS domain must be 0-232");
    if (o->port < 0 || o->port > 65535) throw InputError("viewer port must be 0-65535");
    serveView(*o);
  });
}

}  // namespace hiveslam::apps
