// DDS Security end to end, as separate processes: a 3-node cluster made secure with `hiveslam
// keys` maps as an open one does, while an LM without keys and an LM with another domain's
// keys, started on the same domain, hear nothing and receive nothing.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "rendered_sequence.hpp"
#include "temp_dir.hpp"

namespace hiveslam {
namespace {

namespace fs = std::filesystem;

const std::string kBinary = HIVESLAM_BINARY;

nlohmann::json report(const fs::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in.good()) << file;
  return in ? nlohmann::json::parse(in) : nlohmann::json::object();
}

std::string logOf(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

int run(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(SecureDomain, AClusterWithKeysMapsAndStrangersHearNothing) {
  testing::TempDir dir;
  const fs::path& loop = testing::renderedLoop(240);
  ASSERT_EQ(run(kBinary + " keys --out " + (dir / "keys").string() + " > /dev/null"), 0);
  ASSERT_EQ(run(kBinary + " keys --out " + (dir / "other").string() + " --nodes lm > /dev/null"), 0);
  const std::string domain = "231";
  // The strangers first, so that they are there for the whole run; stopped (SIGTERM) at its end,
  // they write their reports.
  const std::string strangers =
      kBinary + " node --task lm --name stranger --id 7 --no-ros --domain " + domain + " --out " + (dir / "nokeys").string() +
      " > " + (dir / "nokeys.log").string() + " 2>&1 & a=$!; " + kBinary + " node --task lm --id 8 --no-ros --domain " +
      domain + " --secure " + (dir / "other").string() + " --out " + (dir / "otherca").string() + " > " +
      (dir / "otherca.log").string() + " 2>&1 & b=$!; sleep 1; ";
  const std::string cluster = kBinary + " cluster --nodes 3 --domain " + domain + " --secure " + (dir / "keys").string() + " " +
                              loop.string() + " --out " + (dir / "out").string() + " > " +
                              (dir / "cluster.log").string() + " 2>&1; s=$?; kill $a $b; wait $a $b; exit $s";
  ASSERT_EQ(run("bash -c '" + strangers + cluster + "'"), 0) << logOf(dir / "cluster.log");
  const auto tr = report(dir / "out" / "tr" / "report.json"), lm = report(dir / "out" / "lm" / "report.json"),
             lc = report(dir / "out" / "lc" / "report.json");
  EXPECT_TRUE(tr.value("secure", false));
  EXPECT_TRUE(lm.value("secure", false));
  EXPECT_TRUE(lc.value("secure", false));
  EXPECT_EQ(tr.value("peers", -1), 2);
  EXPECT_EQ(tr.value("tasks", nlohmann::json::array()), nlohmann::json::array({"tr"}));
  EXPECT_EQ(lm.value("keyframes_received", -1), tr.value("keyframes_published", -2));
  // Seen twice in fresh-clone CI runs: LC ended with none of TR's 66-67 keyframes, the test
  // taking 42-47 s against 12-38 here. The second log showed TR matching both LM and LC while
  // LM and LC never matched each other (neither logged the other joining), so LM took loop
  // closing over and LC waited: a secure handshake between two keyed nodes that never
  // completed under CI's load. The log says what LC heard, and when.
  EXPECT_EQ(lc.value("keyframes", -1), tr.value("keyframes", -2)) << logOf(dir / "cluster.log");
  EXPECT_GT(tr.value("tracked_frames", 0), 200);
  EXPECT_EQ(lm.value("map_points", -1), tr.value("map_points", -2));  // the end-of-run exchange went through
  // Its accuracy against an open cluster's is a benchmark's question (docs/BENCHMARKS.md).
  // The stranger with another domain's keys failed its handshakes with the cluster's nodes (on
  // the side of each pair that started it).
  EXPECT_GT(tr.value("failed_handshakes", 0) + lm.value("failed_handshakes", 0) + lc.value("failed_handshakes", 0), 0);
  for (const char* stranger : {"nokeys", "otherca"}) {
    const auto s = report(dir / stranger / "report.json");
    EXPECT_EQ(s.value("peers", -1), 0) << stranger << "\n" << logOf(dir / (std::string(stranger) + ".log"));
    EXPECT_EQ(s.value("keyframes_received", -1), 0) << stranger;
    EXPECT_EQ(s.value("keyframes", -1), 0) << stranger;
  }
  EXPECT_FALSE(report(dir / "nokeys" / "report.json").value("secure", true));
  EXPECT_TRUE(report(dir / "otherca" / "report.json").value("secure", false));
}

TEST(SecureDomain, ANodeRefusesAKeyOthersCanReadOrAMissingIdentity) {
  testing::TempDir dir;
  ASSERT_EQ(run(kBinary + " keys --out " + (dir / "keys").string() + " --nodes lm > /dev/null"), 0);
  ASSERT_EQ(run("chmod 644 " + (dir / "keys" / "lm" / "key.pem").string()), 0);
  const std::string node = kBinary + " node --task lm --no-ros --domain 230 --out " + (dir / "out").string() + " --secure " +
                           (dir / "keys").string();
  EXPECT_EQ(run(node + " > " + (dir / "log").string() + " 2>&1"), 1);
  const std::string log = logOf(dir / "log");
  EXPECT_NE(log.find("readable by others"), std::string::npos) << log;
  EXPECT_EQ(log.find("BEGIN"), std::string::npos) << "the key's text in the error";
  EXPECT_EQ(run(node + " --identity lc > " + (dir / "log2").string() + " 2>&1"), 1);
  EXPECT_NE(logOf(dir / "log2").find("missing"), std::string::npos) << logOf(dir / "log2");
}

}  // namespace
}  // namespace hiveslam
