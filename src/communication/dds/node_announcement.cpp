#include "communication/dds/node_announcement.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace hiveslam::communication {

namespace {
std::atomic<int> g_dropped{0};
}  // namespace

hiveslam_msgs::msg::NodeInfo toIdl(const PeerInfo& p) {
  hiveslam_msgs::msg::NodeInfo m;
  m.version(kAnnouncementVersion);
  m.node(p.node);
  m.name(p.name);
  m.task(static_cast<uint8_t>(p.task));
  m.hosted(p.hosted);
  m.incarnation(p.incarnation);
  m.cores(p.cores);
  m.load(p.load);
  m.leaving(p.leaving);
  // Bounded in the IDL; a network of more nodes than that announces the first of them.
  m.seen(std::vector<uint16_t>(p.seen.begin(), p.seen.begin() + static_cast<long>(std::min<size_t>(p.seen.size(), 256))));
  return m;
}

std::optional<PeerInfo> fromIdl(const hiveslam_msgs::msg::NodeInfo& m, std::string& why) {
  constexpr uint8_t kAllTasks = 1 | 2 | 4;
  if (m.version() != kAnnouncementVersion)
    why = "announcement version " + std::to_string(m.version()) + ", this build reads " + std::to_string(kAnnouncementVersion);
  else if (m.task() > 2)
    why = "task " + std::to_string(m.task()) + " does not exist";
  else if (m.hosted() & ~kAllTasks)
    why = "hosted tasks " + std::to_string(m.hosted()) + " do not exist";
  else if (m.name().size() > kMaxNodeNameBytes)
    why = "a name of " + std::to_string(m.name().size()) + " bytes";
  else if (!std::isfinite(m.load()) || m.load() < 0)
    why = "a load that is not a number";
  if (!why.empty()) return std::nullopt;
  PeerInfo p;
  p.node = m.node();
  p.name = m.name();
  p.task = static_cast<Task>(m.task());
  p.hosted = m.hosted();
  p.incarnation = m.incarnation();
  p.cores = m.cores();
  p.load = m.load();
  p.leaving = m.leaving();
  p.seen = m.seen();
  std::sort(p.seen.begin(), p.seen.end());  // in id order, as PeerInfo says
  p.seen.erase(std::unique(p.seen.begin(), p.seen.end()), p.seen.end());
  return p;
}

void noteDroppedAnnouncement() { ++g_dropped; }
int droppedAnnouncements() { return g_dropped.load(); }

}  // namespace hiveslam::communication
