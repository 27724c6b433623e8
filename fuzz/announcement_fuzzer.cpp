// libFuzzer target: a node's announcement as it comes off the wire (rt/hiveslam/nodes): the CDR
// payload Fast DDS hands the reader, its deserialization by the fastddsgen type, then the checks
// a node makes before its peer table takes it (communication/dds/node_announcement.hpp). The
// whole input is the payload. Deserialization may fail and the checks may drop the
// announcement; anything else (an exception, a crash, a sanitizer report) is a finding, and
// so is an accepted peer that breaks what PeerInfo promises. Its first finding: a bool byte of 2
// threw out of the generated code and ended the node (communication/dds/checked_type.hpp).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "communication/dds/checked_type.hpp"
#include "communication/dds/node_announcement.hpp"
#include "hiveslam_msgs/msg/NodeInfoPubSubTypes.h"

using namespace hiveslam::communication;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static CheckedType<hiveslam_msgs::msg::NodeInfoPubSubType> type;  // as every node's reader has it
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<uint32_t>(size);
  hiveslam_msgs::msg::NodeInfo m;
  if (!type.deserialize(&payload, &m)) return 0;
  std::string why;
  const auto p = fromIdl(m, why);
  if (!p) {
    if (why.empty()) __builtin_trap();
    return 0;
  }
  if (static_cast<int>(p->task) > 2 || (p->hosted & ~7) || p->name.size() > kMaxNodeNameBytes ||
      !std::is_sorted(p->seen.begin(), p->seen.end()))
    __builtin_trap();
  return 0;
}
