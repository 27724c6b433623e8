#include "communication/dds/participant_security.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fnmatch.h>

#include <algorithm>
#include <atomic>
#include <mutex>

namespace hiveslam::communication {

namespace {

std::mutex g_mutex;
std::optional<security::SecureIdentity> g_identity;
std::atomic<int> g_failed{0};

std::string fileUri(const std::filesystem::path& p) { return "file://" + p.string(); }

bool granted(const std::vector<std::string>& patterns, const std::string& name) {
  // fnmatch without FNM_PATHNAME: '*' crosses '/', as in Fast DDS's own matching.
  return std::any_of(patterns.begin(), patterns.end(), [&](const std::string& p) { return fnmatch(p.c_str(), name.c_str(), 0) == 0; });
}

}  // namespace

void useSecurity(std::optional<security::SecureIdentity> identity) {
  std::lock_guard lock(g_mutex);
  g_identity = std::move(identity);
}

bool secure() {
  std::lock_guard lock(g_mutex);
  return g_identity.has_value();
}

void applySecurity(eprosima::fastdds::dds::DomainParticipantQos& qos) {
  std::lock_guard lock(g_mutex);
  if (!g_identity) return;
  const auto& id = *g_identity;
  auto& p = qos.properties().properties();
  p.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", fileUri(id.identity_ca));
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", fileUri(id.certificate));
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", fileUri(id.private_key));
  p.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", fileUri(id.permissions_ca));
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", fileUri(id.governance));
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", fileUri(id.permissions));
  p.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
  for (auto& t : qos.transport().user_transports)
    if (auto udp = std::dynamic_pointer_cast<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(t))
      udp->maxMessageSize = kSecureDatagramBytes;
}

bool mayWrite(const std::string& name) {
  std::lock_guard lock(g_mutex);
  return !g_identity || granted(g_identity->publish, name);
}

bool mayRead(const std::string& name) {
  std::lock_guard lock(g_mutex);
  return !g_identity || granted(g_identity->subscribe, name);
}

void noteFailedHandshake() { ++g_failed; }
int failedHandshakes() { return g_failed.load(); }

}  // namespace hiveslam::communication
