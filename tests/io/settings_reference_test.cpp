// docs/SETTINGS.md is the reference of every settings key: these tests fail when the program
// reads a key the page does not list, or the page lists one the program does not read.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "io/slam_settings_io.hpp"

namespace {

std::string referencePage() {
  std::ifstream in(std::string(HIVESLAM_SOURCE_DIR) + "/docs/SETTINGS.md");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The keys the page's tables list: the first cell of each row, in backquotes.
std::set<std::string> listedKeys(const std::string& page) {
  std::set<std::string> keys;
  const std::regex row(R"(^\| `([a-z0-9_.]+)` \|)", std::regex::multiline);
  for (auto it = std::sregex_iterator(page.begin(), page.end(), row); it != std::sregex_iterator(); ++it)
    keys.insert((*it)[1].str());
  return keys;
}

}  // namespace

TEST(SettingsReference, ListsEveryKeyTheProgramReads) {
  const std::string page = referencePage();
  ASSERT_FALSE(page.empty()) << "docs/SETTINGS.md not found";
  const std::set<std::string> listed = listedKeys(page);
  const std::vector<std::string> keys = hiveslam::io::settingKeys();
  ASSERT_GT(keys.size(), 60u);
  for (const auto& key : keys) EXPECT_TRUE(listed.count(key)) << key << " is missing from docs/SETTINGS.md";
}

TEST(SettingsReference, ListsNoKeyTheProgramDoesNotRead) {
  const std::vector<std::string> keys = hiveslam::io::settingKeys();
  for (const auto& key : listedKeys(referencePage()))
    EXPECT_NE(std::find(keys.begin(), keys.end(), key), keys.end()) << "docs/SETTINGS.md lists " << key;
}
