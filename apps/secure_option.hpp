#pragma once
// `--secure DIR [--identity NAME]` on every command that joins a DDS domain: its participants
// authenticate with DIR/NAME's keys (made by `hiveslam keys`), encrypt what they send and keep
// to NAME's permissions. NAME defaults to what the command is: its node name, "play" or "view".
#include <CLI/CLI.hpp>

#include <string>

namespace hiveslam::apps {

struct SecureOption {
  std::string dir, identity;
};

void addSecureOption(CLI::App* cmd, SecureOption& o);
// Before the first participant: reads and checks the identity's files (throws InputError).
void useSecureOption(const SecureOption& o, const std::string& default_identity);

}  // namespace hiveslam::apps
