#include "apps/secure_option.hpp"

#include "communication/dds/participant_security.hpp"

namespace hiveslam::apps {

void addSecureOption(CLI::App* cmd, SecureOption& o) {
  cmd->add_option("--secure", o.dir, "DDS Security: the keys folder `hiveslam keys` made (authenticated, encrypted, topic permissions)");
  cmd->add_option("--identity", o.identity, "With --secure: whose keys (DIR/NAME; default: the node's name, play or view)");
}

void useSecureOption(const SecureOption& o, const std::string& default_identity) {
  if (o.dir.empty()) return;
  communication::useSecurity(
      communication::security::loadIdentity(o.dir, o.identity.empty() ? default_identity : o.identity));
}

}  // namespace hiveslam::apps
