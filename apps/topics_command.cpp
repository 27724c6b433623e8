// hiveslam topics [--domain N]: the topics on a DDS domain and their types, as
// `ros2 topic list -t` prints them, for a user without ROS 2.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <thread>

#include "apps/commands.hpp"
#include "apps/secure_option.hpp"
#include "common/error.hpp"
#include "communication/dds/topic_discovery.hpp"

namespace hiveslam::apps {

namespace {

struct TopicsOptions {
  int domain = 0;
  double seconds = 2.0;
  bool all = false, counts = false;
  SecureOption secure;
};

void listTopics(const TopicsOptions& o) {
  if (o.seconds < 0 || o.seconds > 600) throw InputError("--wait must be 0-600 seconds");
  useSecureOption(o.secure, "view");
  communication::TopicDiscovery discovery(o.domain);
  // Discovery announces every 100 ms at first; a participant on a lossy link may need more.
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds));
  int shown = 0;
  for (const auto& t : discovery.topics()) {
    if (t.writers + t.readers == 0) continue;
    const std::string ros = communication::rosTopicName(t.name);
    if (ros.empty() && !o.all) continue;
    std::string line = fmt::format("{} [{}]", ros.empty() ? t.name : ros, communication::rosTypeName(t.type));
    if (o.counts) line += fmt::format("  writers {} readers {}", t.writers, t.readers);
    fmt::print("{}\n", line);
    ++shown;
  }
  if (shown == 0) fmt::print(stderr, "no topics seen on DDS domain {} within {} s\n", o.domain, o.seconds);
}

}  // namespace

void addTopicsCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("topics", "List the topics and types on a DDS domain (as `ros2 topic list -t`)");
  cmd->footer("Example:\n  hiveslam topics --domain 7");
  auto o = std::make_shared<TopicsOptions>();
  cmd->add_option("--domain", o->domain, "DDS domain id (the ROS_DOMAIN_ID)")->capture_default_str();
  cmd->add_option("--wait", o->seconds, "Seconds to listen to discovery (with --secure: 15 unless given)")->capture_default_str();
  cmd->add_flag("--all", o->all, "Also topics that are not ROS 2 topics (DDS names as they are)");
  cmd->add_flag("--counts", o->counts, "Show each topic's writers and readers");
  addSecureOption(cmd, o->secure);
  cmd->callback([o, cmd] {
    if (o->domain < 0 || o->domain > 232) throw InputError("DDS domain must be 0-232");
    // A secure participant hears of another's topics only after their handshake: a 3-node
    // cluster's took 3-15 s to appear whole, against under 2 s open.
    if (!o->secure.dir.empty() && cmd->count("--wait") == 0) o->seconds = 15;
    listTopics(*o);
  });
}

}  // namespace hiveslam::apps
