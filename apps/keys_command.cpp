// hiveslam keys --out DIR [--nodes tr,lm,lc,play,view]: what DDS Security needs for one domain
// (communication/security/keystore.hpp), made with OpenSSL.
#include <fmt/format.h>

#include <memory>

#include "apps/commands.hpp"
#include "common/error.hpp"
#include "communication/security/keystore.hpp"

namespace hiveslam::apps {

void addKeysCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("keys", "Make the CAs, node certificates and signed permissions for --secure");
  cmd->footer(
      "Example:\n  hiveslam keys --out keys\n  hiveslam cluster seq/figure8 --nodes 3 --secure keys --out out\n"
      "Each node needs DIR/identity_ca.pem, DIR/permissions_ca.pem, DIR/governance.p7s and its own DIR/NAME;\n"
      "DIR/private holds the CAs' keys: keep it off the nodes. Run again to add nodes with the same CAs.");
  auto o = std::make_shared<communication::security::KeystoreRequest>();
  auto dir = std::make_shared<std::string>();
  auto names = std::make_shared<std::vector<std::string>>(std::vector<std::string>{"tr", "lm", "lc", "play", "view"});
  cmd->add_option("--out", *dir, "Keys folder")->required();
  cmd->add_option("--nodes", *names, "Identities: tr, lm, lc, play (a camera), view, or NAME:ROLE (ROLE tr, lm, lc, camera, view)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--days", o->days, "Validity of the certificates and permissions")->capture_default_str();
  cmd->callback([o, dir, names] {
    o->dir = *dir;
    o->nodes.clear();
    for (const auto& n : *names) o->nodes.push_back(communication::security::parseIdentity(n));
    communication::security::makeKeystore(*o);
    for (const auto& n : o->nodes)
      fmt::print("{} ({})\n", (o->dir / n.name).string(), communication::security::roleName(n.role));
  });
}

}  // namespace hiveslam::apps
