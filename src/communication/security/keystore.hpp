#pragma once
// A domain's keys on disk, as `hiveslam keys --out DIR` writes them:
//   DIR/identity_ca.pem, DIR/permissions_ca.pem   the two CAs' certificates (public)
//   DIR/governance.p7s                            the domain's rules, signed by the permissions CA
//   DIR/<name>/cert.pem, key.pem                  a node's identity (key.pem mode 0600)
//   DIR/<name>/permissions.p7s                    its topics, signed by the permissions CA
//   DIR/private/                                  the CAs' keys (mode 0700): kept off the nodes
// A node needs the first three and its own folder. Run again on the same DIR, it reuses the CAs
// and adds or renews the named nodes.
#include <filesystem>
#include <string>
#include <vector>

#include "communication/security/grants.hpp"

namespace hiveslam::communication::security {

struct KeystoreRequest {
  std::filesystem::path dir;
  std::vector<Identity> nodes;
  int days = 365;
};
void makeKeystore(const KeystoreRequest& request);

// What a participant is made with: file paths of one identity in a keystore.
struct SecureIdentity {
  std::string name;
  std::filesystem::path identity_ca, permissions_ca, governance, certificate, private_key, permissions;
  // The topic patterns its signed permissions let it write and read ('*': any run of characters).
  std::vector<std::string> publish, subscribe;
};
// Checks that every file is there, the private key is readable by its owner only and the
// permissions carry the permissions CA's signature; throws InputError naming the file
// otherwise. Reads no private key.
SecureIdentity loadIdentity(const std::filesystem::path& dir, const std::string& name);

}  // namespace hiveslam::communication::security
