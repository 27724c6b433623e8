#pragma once
// The hiveslam binary run with arguments: its exit status and what it printed (stdout and
// stderr together).
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace hiveslam::testing {

struct Output {
  int status = -1;  // the exit status; -1 when it did not exit normally
  std::string text;
};

inline Output runHiveslam(const std::string& args) {
  Output out;
  FILE* pipe = popen((std::string(HIVESLAM_BINARY) + " " + args + " 2>&1").c_str(), "r");
  if (!pipe) return out;
  std::array<char, 256> buf{};
  while (fgets(buf.data(), buf.size(), pipe)) out.text += buf.data();
  const int status = pclose(pipe);
  out.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

}  // namespace hiveslam::testing
