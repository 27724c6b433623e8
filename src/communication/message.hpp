#pragma once
// What the communication layer moves: typed packets on a handful of topics, and the node
// announcements discovery is made of. The distribution layer fills the bodies; this layer
// never looks inside them.
#include <cstdint>
#include <string>
#include <vector>

namespace hiveslam::communication {

// The paper's three tasks; a node is started with one and may host the others.
enum class Task : uint8_t { Tracking = 0, Mapping = 1, LoopClosing = 2 };
constexpr uint8_t taskBit(Task t) { return static_cast<uint8_t>(1u << static_cast<unsigned>(t)); }
const char* taskName(Task t);  // "tr", "lm", "lc"
bool parseTask(const std::string& name, Task& out);

// Topics follow the paper's connectivity scheme, named after the task of the publisher: LM is
// the gateway between TR and LC. DDS names follow ROS 2 (the rt/ prefix).
enum class Topic : uint8_t {
  TrKeyframes,  // TR -> LM: new keyframes
  LmKeyframes,  // LM -> LC: mapped keyframes
  LmMap,        // LM -> TR, LC: local maps, and global maps relayed from LC
  LcMap,        // LC -> LM: global maps
  Count,
};
constexpr int kTopicCount = static_cast<int>(Topic::Count);
const char* topicName(Topic t);  // e.g. "rt/hiveslam/tr/keyframes"

struct Message {
  uint16_t version = 1;  // body encoding version
  uint16_t source = 0;   // sending node
  uint8_t kind = 0;      // distribution::PacketKind
  uint8_t target = 0;
  uint64_t seq = 0;      // per (source, topic), from 1; set by the DDS transport as it writes
  uint64_t map = 0;
  uint64_t epoch = 0;
  uint32_t raw_size = 0;  // body size before compression
  std::vector<uint8_t> body;
  // Bytes on the wire: the CDR header fields plus the body (transport overhead not counted).
  size_t wireSize() const { return 40 + body.size(); }
};

struct PeerInfo {
  uint16_t node = 0;
  std::string name;
  Task task = Task::Tracking;
  uint8_t hosted = 0;        // taskBit()s of what it runs now
  uint64_t incarnation = 0;  // start time: a restarted node is a new incarnation
  uint16_t cores = 1;
  float load = 0;
  bool leaving = false;
  // The peers this node has heard, in id order: a node that sees a peer cannot know whether
  // that peer sees it too (discovery is one-sided; over a lossy link the two directions came
  // seconds apart), and starting to track before it does sent keyframes nobody read.
  std::vector<uint16_t> seen;
};

}  // namespace hiveslam::communication
