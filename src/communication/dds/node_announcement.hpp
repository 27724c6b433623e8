#pragma once
// A node's announcement (rt/hiveslam/nodes) to and from its IDL type, and the checks a received
// one must pass before the node's peer table takes it: anything else is dropped with one line
// and counted (`announcements_dropped` in the report), never a peer.
#include <cstdint>
#include <optional>
#include <string>

#include "communication/message.hpp"
#include "hiveslam_msgs/msg/NodeInfo.h"

namespace hiveslam::communication {

constexpr uint16_t kAnnouncementVersion = 2;
// Longer names are no node of ours (`--name` is a word); the IDL string itself is unbounded.
constexpr size_t kMaxNodeNameBytes = 64;

hiveslam_msgs::msg::NodeInfo toIdl(const PeerInfo& p);
// The peer, or null with `why` set: another version, a task or hosted bit that does not exist,
// a name too long, a load that is not a number.
std::optional<PeerInfo> fromIdl(const hiveslam_msgs::msg::NodeInfo& m, std::string& why);

// Announcements dropped in this process, for the report.
void noteDroppedAnnouncement();
int droppedAnnouncements();

}  // namespace hiveslam::communication
