// Every sub-command's --help exits 0 and shows an example. The sub-commands are read from the
// help itself, so a new one is covered without touching this test.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Output {
  int status = -1;
  std::string text;
};

Output run(const std::string& args) {
  Output out;
  FILE* pipe = popen((std::string(HIVESLAM_BINARY) + " " + args + " 2>&1").c_str(), "r");
  if (!pipe) return out;
  std::array<char, 256> buf{};
  while (fgets(buf.data(), buf.size(), pipe)) out.text += buf.data();
  const int status = pclose(pipe);
  out.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

// The names CLI11 lists under "Subcommands:", one per line, each followed by its description.
std::vector<std::string> subcommands(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help);
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      inside = true;
      continue;
    }
    if (!inside) continue;
    if (line.rfind("  ", 0) != 0) break;  // the section ends at the first unindented line
    std::istringstream words(line);
    std::string name;
    if (words >> name) names.push_back(name);
  }
  return names;
}

void expectHelpWithExample(const std::string& command) {
  const Output out = run(command + " --help");
  EXPECT_EQ(out.status, 0) << command << ":\n" << out.text;
  EXPECT_NE(out.text.find("Example:\n  hiveslam"), std::string::npos) << command << " --help shows no example:\n"
                                                                      << out.text;
}

}  // namespace

TEST(CommandHelp, EverySubCommandExitsZeroAndShowsAnExample) {
  const Output top = run("--help");
  ASSERT_EQ(top.status, 0) << top.text;
  expectHelpWithExample("");
  const std::vector<std::string> commands = subcommands(top.text);
  ASSERT_GE(commands.size(), 10u) << top.text;
  for (const auto& command : commands) {
    expectHelpWithExample(command);
    for (const auto& sub : subcommands(run(command + " --help").text)) expectHelpWithExample(command + " " + sub);
  }
}
