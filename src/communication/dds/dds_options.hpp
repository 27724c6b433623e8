#pragma once
// What a node's DDS participant is made with; the `dds:` section of a settings file overrides
// all but the domain (io/slam_settings_io.hpp).
#include <functional>

namespace hiveslam::communication {

struct DdsOptions {
  int domain = 0;          // the ROS_DOMAIN_ID; set by --domain
  int history_depth = 64;  // packets kept per writer for late acknowledgements
  // UDP datagrams no larger than an Ethernet frame's payload: a 64 KB datagram is ~45 IP
  // fragments, and one lost fragment loses all of it (at 2% packet loss, a keyframe message got
  // through whole less than half the time). MTU-sized datagrams are RTPS fragments that a
  // reader asks for again one by one.
  int max_datagram_bytes = 1400;
  // How often a reliable writer with unacknowledged packets says what it has sent, so that a
  // reader notices a lost last fragment (Fast DDS's default is 3 s).
  int heartbeat_ms = 100;
  // A leaving node waits up to this long for its peers to acknowledge what it has written (the
  // end-of-run Done and the last snapshot before it). A dead peer is no longer waited for once
  // its lease ends (2 s); a live one on a slow link is: over a 5 Mbit/s link the last snapshot
  // took longer than the 1 s once waited, and TR then waited 120 s for a Done that never came.
  int leave_flush_ms = 20000;
  // stop() waits this much longer than leave_flush_ms for Fast DDS to shut down, then leaves
  // the teardown behind (DdsTransport::teardownsRunning()).
  int teardown_margin_ms = 10000;
  // Tests only: runs first on the teardown thread (to stand in for a teardown that hangs).
  std::function<void()> teardown_hook{};
};

}  // namespace hiveslam::communication
