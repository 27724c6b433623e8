#pragma once
// DDS Security for every participant of this process. A process is one node, one player or
// one viewer, so its participants (the node's transport, its image reader, its ROS 2 topics)
// share one identity: set once at start-up from `--secure DIR`, before the first participant.
#include <optional>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include "communication/security/keystore.hpp"

namespace hiveslam::communication {

void useSecurity(std::optional<security::SecureIdentity> identity);
bool secure();
// With an identity set: the builtin plugins on `qos` (PKI-DH authentication,
// Access-Permissions, AES-GCM-GMAC), reading that identity's files, and its UDP transports'
// datagrams all of kSecureDatagramBytes. Without: no change. Call it after the transports are set.
void applySecurity(eprosima::fastdds::dds::DomainParticipantQos& qos);

// A secure handshake message (certificate and signed permissions, about 4 KB) goes in one
// datagram: Fast DDS 2.9 does not fragment it, and with the nodes' 1400-byte datagrams it
// "cannot serialize" it and no peer ever authenticates. And every participant of a process
// sends datagrams of one size: with a node's ROS 2 participant at Fast DDS's 65500 beside its
// 8 KB transport, a pair of nodes never authenticated in about 1 run in 10 (4 of 45 3-node
// clusters; 0 of 30 with both at 8 KB, 0 of 30 without the ROS 2 participant).
constexpr int kSecureDatagramBytes = 8192;

// Whether this process's permissions let it write / read DDS topic `name` (always, without
// an identity). Asked before making a writer or reader: Fast DDS refuses one it does not allow,
// with an error in its log.
bool mayWrite(const std::string& name);
bool mayRead(const std::string& name);

// Remote participants whose handshake failed (no keys, or keys of another CA), as the
// participants of this process saw them.
void noteFailedHandshake();
int failedHandshakes();

}  // namespace hiveslam::communication
