// Every sub-command's --help exits 0 and shows an example. The sub-commands are read from the
// help itself, so a new one is covered without touching this test.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "apps/hiveslam_output.hpp"

namespace {

using hiveslam::testing::Output;
Output run(const std::string& args) { return hiveslam::testing::runHiveslam(args); }

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
