// Writes the announcement fuzzer's seeds: the CDR payloads of a few valid announcements (a TR
// that has heard two peers, an LM hosting LC, a node leaving), so that mutations start from
// what the wire carries.
//
//   announcement_seeds DIR
#include <cstdio>
#include <fstream>
#include <string>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "communication/dds/node_announcement.hpp"
#include "hiveslam_msgs/msg/NodeInfoPubSubTypes.h"

using namespace hiveslam::communication;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: announcement_seeds DIR\n");
    return 2;
  }
  hiveslam_msgs::msg::NodeInfoPubSubType type;
  PeerInfo tr{1, "tr", Task::Tracking, 1, 1700000000000000000ull, 2, 0.8f, false, {2, 3}};
  PeerInfo lm{2, "lm", Task::Mapping, 2 | 4, 1700000000000000001ull, 2, 1.1f, false, {1}};
  PeerInfo leaving{3, "lc", Task::LoopClosing, 4, 1700000000000000002ull, 1, 0.1f, true, {}};
  int n = 0;
  for (const PeerInfo& p : {tr, lm, leaving}) {
    hiveslam_msgs::msg::NodeInfo m = toIdl(p);
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&m)());
    if (!type.serialize(&m, &payload)) return 1;
    std::ofstream(std::string(argv[1]) + "/announcement" + std::to_string(n++), std::ios::binary)
        .write(reinterpret_cast<const char*>(payload.data), payload.length);
  }
  return 0;
}
