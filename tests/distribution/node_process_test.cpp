// The node program as separate processes over Fast DDS: on loopback (hiveslam cluster), and in
// three network namespaces joined by a bridge, each node with its own network stack as on
// separate devices (root only; skipped with a message where namespaces cannot be made).
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "io/atlas_file.hpp"
#include "rendered_sequence.hpp"
#include "temp_dir.hpp"

extern char** environ;

namespace hiveslam {
namespace {

namespace fs = std::filesystem;

// Instrumented (sanitizer) builds run many times slower than the camera: there TR reads its
// frames as fast as it goes instead of at their timestamps, and the player plays slower. The
// tests then check what the nodes do (take-over, hand-over, one map at the end), not how many
// frames a real-time run keeps; the release build checks both.
constexpr bool kSanitized = HIVESLAM_SANITIZED;
const std::string kRealtime = kSanitized ? "" : " --realtime";
const std::string kPlayRate = kSanitized ? " --rate 0.1" : "";

// The rendered loop of these tests: 240 frames, or 900.
const fs::path& sequence(int frames = 240) { return testing::renderedLoop(frames); }

nlohmann::json report(const fs::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in.good()) << file;
  return in ? nlohmann::json::parse(in) : nlohmann::json::object();
}

// The sockets a process holds open now: its descriptors that link to "socket:[inode]".
int openSockets(pid_t pid) {
  int n = 0;
  std::error_code ec;
  for (const auto& fd : fs::directory_iterator(fs::path("/proc") / std::to_string(pid) / "fd", ec)) {
    std::error_code gone;  // a descriptor closed between the listing and the read
    n += fs::read_symlink(fd.path(), gone).string().starts_with("socket:");
  }
  return n;
}

// The processes whose parent is `parent`, from /proc/N/stat ("N (comm) state ppid ...").
std::vector<pid_t> childrenOf(pid_t parent) {
  std::vector<pid_t> children;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/proc", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    std::getline(stat, line);
    const auto comm_end = line.rfind(')');  // the command's name may hold spaces and brackets
    if (comm_end == std::string::npos) continue;
    std::istringstream rest(line.substr(comm_end + 1));
    char state = 0;
    pid_t ppid = 0;
    if (rest >> state >> ppid && ppid == parent) children.push_back(std::stoi(name));
  }
  return children;
}

// Whether a node's frame log (frames.csv: index, timestamp, tracked, ...) shows it tracking
// through the last quarter of its run: at least 10 frames there and 9 in 10 of them tracked.
::testing::AssertionResult tracksTheLastQuarter(const fs::path& frame_log) {
  std::ifstream in(frame_log);
  std::string line;
  std::getline(in, line);  // the header
  std::vector<std::pair<double, bool>> frames;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string index, stamp, tracked;
    std::getline(row, index, ',');
    std::getline(row, stamp, ',');
    std::getline(row, tracked, ',');
    frames.emplace_back(std::stod(stamp), tracked == "1");
  }
  if (frames.empty()) return ::testing::AssertionFailure() << "no frames in " << frame_log;
  const double from = frames.front().first + 0.75 * (frames.back().first - frames.front().first);
  int seen = 0, tracked = 0;
  for (const auto& [stamp, ok] : frames)
    if (stamp >= from) ++seen, tracked += ok;
  if (seen >= 10 && 10 * tracked >= 9 * seen) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << tracked << " of the last quarter's " << seen << " frames tracked";
}

// A shell loop that returns once TR (pid $tr, progress in `log`) has read frame `frame` of 240 or
// has ended. TR prints its progress every 10% at the first frame it processes past each step: a
// real-time TR that drops the step's own frame prints a later one ("tracking 123/240"), and a
// wait for the exact number then lasted until TR had ended (the node it was to start found no
// one left to join).
std::string untilFrame(int frame, const fs::path& log) {
  return "until ! kill -0 $tr || [ \"$(grep -o \"tracking [0-9]*/240\" " + log.string() +
         " | tail -n 1 | cut -d\" \" -f2 | cut -d/ -f1)\" -ge " + std::to_string(frame) +
         " ] 2>/dev/null; do sleep 0.05; done; ";
}

// A shell loop that returns once the process $`name` has ended, or after 60 s.
std::string awaitExit(const std::string& name) {
  return "for i in $(seq 600); do kill -0 $" + name + " 2>/dev/null || break; sleep 0.1; done; ";
}

std::vector<std::string> tasks(const nlohmann::json& r) { return r.value("tasks", std::vector<std::string>{}); }

// Every keyframe of a node's S_full is in its SLAM map too: a keyframe known only by its record
// (its features never came) cannot be tracked against, matched or corrected there.
void expectSFullInMap(const nlohmann::json& r, const std::string& node) {
  ASSERT_TRUE(r.contains("s_full_keyframes_not_in_map")) << node;
  EXPECT_TRUE(r["s_full_keyframes_not_in_map"].empty()) << node << ": " << r["s_full_keyframes_not_in_map"].dump();
}

// After a run the three nodes hold the same maps: the same keyframes and points in their SLAM
// maps, the same keyframes in S_full, and nothing in S_full that their SLAM map lacks.
void expectSameMaps(const nlohmann::json& tr, const nlohmann::json& lm, const nlohmann::json& lc) {
  for (const auto* r : {&lm, &lc}) {
    EXPECT_EQ(r->value("keyframes", -1), tr.value("keyframes", -2)) << r->value("task", "");
    EXPECT_EQ(r->value("map_points", -1), tr.value("map_points", -2)) << r->value("task", "");
    EXPECT_EQ(r->value("s_full_keyframes", -1), tr.value("s_full_keyframes", -2)) << r->value("task", "");
  }
  expectSFullInMap(tr, "tr");
  expectSFullInMap(lm, "lm");
  expectSFullInMap(lc, "lc");
}

// Each node's saved maps (cluster --atlases): every keyframe and point in all three, each where
// TR has it to within 1 mm. The reports compare counts; this compares the poses themselves.
void expectSamePoses(const fs::path& out) {
  const auto tr = io::loadAtlas(out / "tr" / "atlas.bin");
  ASSERT_FALSE(tr.empty());
  for (const char* node : {"lm", "lc"}) {
    const auto other = io::loadAtlas(out / node / "atlas.bin");
    ASSERT_EQ(other.size(), tr.size()) << node;
    for (const auto& m : tr) {
      const auto it = std::find_if(other.begin(), other.end(), [&](const auto& o) { return o->id == m->id; });
      ASSERT_NE(it, other.end()) << node << " lacks map " << m->id;
      const core::Map& o = **it;
      ASSERT_EQ(o.keyframes.size(), m->keyframes.size()) << node;
      ASSERT_EQ(o.points.size(), m->points.size()) << node;
      double worst_kf = 0, worst_point = 0;
      for (const auto& [id, kf] : m->keyframes) {
        const auto k = o.keyframes.find(id);
        ASSERT_NE(k, o.keyframes.end()) << node << " lacks keyframe " << id;
        worst_kf = std::max(worst_kf, (k->second->center() - kf->center()).norm());
      }
      for (const auto& [id, p] : m->points) {
        const auto q = o.points.find(id);
        ASSERT_NE(q, o.points.end()) << node << " lacks point " << id;
        worst_point = std::max(worst_point, (q->second->position - p->position).norm());
      }
      EXPECT_LT(worst_kf, 1e-3) << node;
      EXPECT_LT(worst_point, 1e-3) << node;
    }
  }
}

// The same maps, and TR's trajectory right.
void expectOneMap(const nlohmann::json& tr, const nlohmann::json& lm, const nlohmann::json& lc) {
  expectSameMaps(tr, lm, lc);
  EXPECT_LT(tr["ate"]["percent_of_path"].get<double>(), 1.0);
}

// What each node's report and frame log say in brief: its map, its loops and merges (where,
// at what scale), the stretches of frames it tracked in each map, and every 20th estimated
// position. A failed accuracy check is read from this in CI, where the folder is gone.
std::string nodeDigest(const fs::path& node) {
  std::ostringstream o;
  std::ifstream in(node / "report.json");
  if (!in) return "";
  const auto r = nlohmann::json::parse(in, nullptr, false);
  if (r.is_discarded()) return "";
  o << "=== " << node.filename().string() << ": keyframes " << r.value("keyframes", -1) << ", points "
    << r.value("map_points", -1) << ", maps " << r.value("maps", -1);
  if (r.contains("tracked_frames")) o << ", tracked " << r.value("tracked_frames", -1);
  if (r.contains("ate")) o << ", ATE " << r["ate"].value("percent_of_path", -1.0) << "% (max " << r["ate"].value("max", -1.0) << " m)";
  // The most a global BA's free scale wandered before it was put back (1: none wandered or ran).
  if (r.contains("global_ba_scale_drift")) o << ", global BA scale drift " << r.value("global_ba_scale_drift", -1.0);
  o << "\n";
  for (const auto& e : r.value("loop_events", nlohmann::json::array()))
    o << "  " << e.value("kind", "") << " at " << e.value("timestamp", 0.0) << " to " << e.value("place_timestamp", 0.0)
      << ": " << e.value("matches", 0) << " matches, scale " << e.value("scale", 0.0) << " (agreed by "
      << e.value("scale_agreement", 0.0) << " of the inliers)\n";
  std::ifstream frames(node / "frames.csv");
  std::string line, last_map, first;
  std::getline(frames, line);  // the header
  int run = 0;
  auto flush = [&] {
    if (run > 0) o << "  frames from " << first << ": " << run << " in map " << last_map << "\n";
  };
  while (std::getline(frames, line)) {
    std::vector<std::string> col;
    std::istringstream row(line);
    for (std::string c; std::getline(row, c, ',');) col.push_back(c);
    if (col.size() < 7) break;
    const std::string map = col[2] == "1" ? col[6] : "(lost)";
    if (map != last_map) flush(), first = col[0], last_map = map, run = 0;
    ++run;
  }
  flush();
  std::ifstream trajectory(node / "trajectory.tum");
  for (int i = 0; std::getline(trajectory, line); ++i)
    if (i % 20 == 0) {
      std::istringstream row(line);
      std::string t, x, y, z;
      row >> t >> x >> y >> z;
      o << "  " << t << " at " << x << " " << y << " " << z << "\n";
    }
  return o.str();
}

// The event lines (peers, hand-overs, ignored or cut-short maps) of every node log in `out`,
// without the progress lines, then each node's digest: what a failed run's cause is read from
// in CI, where the test's folder is gone afterwards.
// Runs the bash command line `run` (no single quotes in it) and returns std::system's status.
// Past `seconds` it is killed (exit status 124), once every hiveslam process under it has left
// each thread's stack in out/stacks.log, which nodeEvents shows: a node that hangs once in a
// hundred runs (TR after releasing its peers, once) says where.
int runWithin(int seconds, const fs::path& out, const std::string& run) {
  const std::string script = std::string(HIVESLAM_SOURCE_DIR) + "/tests/run_with_stacks.sh";
  return std::system(("bash " + script + " " + std::to_string(seconds) + " " + out.string() + " '" + run + "'").c_str());
}

std::string nodeEvents(const fs::path& out) {
  std::string all;
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.path().extension() != ".log") continue;
    all += "--- " + entry.path().filename().string() + "\n";
    std::ifstream in(entry.path());
    for (std::string line; std::getline(in, line);)
      if (line.find("tracking ") == std::string::npos) all += line + "\n";
  }
  for (const auto& entry : fs::directory_iterator(out))
    if (entry.is_directory()) all += nodeDigest(entry.path());
  return all;
}

TEST(NodeProcesses, ThreeNodesOverLoopback) {
  testing::TempDir out;
  const std::string cmd = std::string(HIVESLAM_BINARY) + " cluster --nodes 3 --atlases " + sequence().string() + " --out " +
                          out.path().string() + " > " + (out / "log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << std::ifstream(out / "log").rdbuf();
  EXPECT_TRUE(fs::exists(out / "trajectory.tum"));
  const auto tr = report(out / "tr" / "report.json"), lm = report(out / "lm" / "report.json"),
             lc = report(out / "lc" / "report.json");
  EXPECT_EQ(tasks(tr), std::vector<std::string>{"tr"});
  EXPECT_EQ(tasks(lm), std::vector<std::string>{"lm"});
  EXPECT_EQ(tasks(lc), std::vector<std::string>{"lc"});
  EXPECT_GT(tr.value("tracked_frames", 0), 200);
  EXPECT_LT(tr["ate"]["percent_of_path"].get<double>(), 1.0);
  EXPECT_GT(tr.value("bytes_out", 0), 0);
  EXPECT_GT(tr.value("bytes_in", 0), 0);
  EXPECT_EQ(tr.value("keyframes_published", 0), lm.value("keyframes_received", -1));
  EXPECT_EQ(lm["mapping"]["keyframes_processed"], tr.value("keyframes_published", -1));
  EXPECT_EQ(lm.value("end_of_run", ""), "completed");
  EXPECT_EQ(lc.value("end_of_run", ""), "completed");
  EXPECT_EQ(tr.value("messages_dropped", -1), 0);
  // Every keyframe's round trip to LM, as TR saw it.
  ASSERT_TRUE(tr.contains("keyframe_ack_ms"));
  EXPECT_GT(tr["keyframe_ack_ms"]["count"].get<int>(), 0);
  EXPECT_LE(tr["keyframe_ack_ms"]["count"].get<int>(), tr.value("keyframes_published", 0));
  EXPECT_GT(tr["keyframe_ack_ms"]["median"].get<double>(), 0.0);
  EXPECT_LE(tr["keyframe_ack_ms"]["median"].get<double>(), tr["keyframe_ack_ms"]["max"].get<double>());
  // The same keyframes in S_full everywhere after the end-of-run exchange.
  EXPECT_EQ(tr.value("s_full_keyframes", 0), lm.value("s_full_keyframes", -1));
  EXPECT_EQ(lc.value("s_full_keyframes", 0), lm.value("s_full_keyframes", -1));
  expectSFullInMap(tr, "tr");
  expectSFullInMap(lm, "lm");
  expectSFullInMap(lc, "lc");
  expectSamePoses(out.path());
}

TEST(NodeProcesses, OneNodeIsTheStandaloneSystem) {
  testing::TempDir out;
  // The counter sees a socket where there is one: one this process opens.
  const int before = openSockets(getpid());
  const int own = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(own, 0);
  EXPECT_EQ(openSockets(getpid()), before + 1);
  close(own);
  const std::string cmd = "exec " + std::string(HIVESLAM_BINARY) + " cluster --nodes 1 " + sequence().string() +
                          " --out " + out.path().string() + " > " + (out / "log").string() + " 2>&1";
  const char* argv[] = {"/bin/sh", "-c", cmd.c_str(), nullptr};
  pid_t cluster = 0;
  ASSERT_EQ(posix_spawn(&cluster, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ), 0);
  // Looked at while it runs: a DDS participant holds its UDP sockets from its start to its end,
  // so one made by the cluster command or its TR process (`hiveslam run`) would be seen.
  int looks_at_tr = 0, sockets = 0, status = 0;
  while (waitpid(cluster, &status, WNOHANG) == 0) {
    sockets = std::max(sockets, openSockets(cluster));
    for (const pid_t tr : childrenOf(cluster)) ++looks_at_tr, sockets = std::max(sockets, openSockets(tr));
    usleep(20'000);
  }
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << std::ifstream(out / "log").rdbuf();
  EXPECT_GT(looks_at_tr, 10);
  EXPECT_EQ(sockets, 0);
  const auto tr = report(out / "tr" / "report.json");
  EXPECT_FALSE(tr.contains("topics"));  // no transport was made
  EXPECT_FALSE(fs::exists(out / "lm"));
  EXPECT_GT(tr.value("tracked_frames", 0), 200);
}

// The paper's set-up: a recording played as a ROS 2 image topic, tracked by a TR node that has
// only the topic and a calibration file.
TEST(NodeProcesses, PlayFeedsATrackingNodeOverAnImageTopic) {
  testing::TempDir out;
  const std::string domain = std::to_string(100 + getpid() % 50);
  const std::string bin = HIVESLAM_BINARY;
  const std::string tr = bin + " node --task tr --topic /cam0/image_raw --calibration " +
                         (sequence() / "mav0/cam0/sensor.yaml").string() + " --domain " + domain + " --out " +
                         (out / "tr").string() + " > " + (out / "tr.log").string() + " 2>&1 &";
  ASSERT_EQ(std::system(tr.c_str()), 0);
  const std::string play = bin + " play " + sequence().string() + kPlayRate + " --topic /cam0/image_raw --domain " + domain +
                           " > " + (out / "play.log").string() + " 2>&1";
  ASSERT_EQ(std::system(play.c_str()), 0) << std::ifstream(out / "play.log").rdbuf();
  // The TR node ends when the player leaves; its report is its last act.
  for (int i = 0; i < 600 && !fs::exists(out / "tr" / "report.json"); ++i) usleep(100'000);
  usleep(300'000);
  const auto r = report(out / "tr" / "report.json");
  EXPECT_EQ(tasks(r), (std::vector<std::string>{"tr", "lm", "lc"})) << std::ifstream(out / "tr.log").rdbuf();
  // Best effort: a sample or two may go before both ends have matched each other.
  EXPECT_GE(r.value("frames", 0) + r.value("dropped_frames", 0), 235);
  EXPECT_GT(r.value("tracked_frames", 0), 180);
  EXPECT_GT(r.value("keyframes", 0), 5);
}

TEST(NodeProcesses, ATrackingNodeNeedsOneInputAndACalibration) {
  testing::TempDir out;
  const std::string calibration = (sequence() / "mav0/cam0/sensor.yaml").string();
  // Without a calibration, with both inputs, with a name ROS 2 would refuse: refused up front.
  const std::string bin = HIVESLAM_BINARY;
  EXPECT_NE(std::system((bin + " node --task tr --topic /x --out " + out.path().string() + " 2>/dev/null").c_str()), 0);
  EXPECT_NE(std::system((bin + " node --task tr " + sequence().string() + " --topic /x --calibration " + calibration +
                         " --out " + out.path().string() + " 2>/dev/null").c_str()), 0);
  EXPECT_NE(std::system((bin + " node --task tr --topic '/bad name' --calibration " + calibration + " --out " +
                         out.path().string() + " 2>/dev/null").c_str()), 0);
}
// A node that dies mid-run: TR notices the LM's lease expire, takes local mapping back (the
// policy with LC present and no LM) and finishes the sequence with its own map copy. The LM
// dies once TR has read 30% of the frames (its progress line), not after a fixed time: on a
// loaded machine a fixed 6 s could leave too little of the 12 s sequence to map after the
// take-over (CI: no keyframe mapped by TR).
TEST(NodeProcesses, TrackingTakesMappingBackWhenTheMappingNodeDies) {
  testing::TempDir out;
  const std::string bin = HIVESLAM_BINARY, domain = " --domain " + std::to_string(150 + getpid() % 50);
  const std::string run =
      bin + " node --task lm" + domain + " --out " + (out / "lm").string() + " > " + (out / "lm.log").string() +
      " 2>&1 & lm=$!; " + bin + " node --task lc" + domain + " --out " + (out / "lc").string() + " > " +
      (out / "lc.log").string() + " 2>&1 & lc=$!; " + bin + " node --task tr " + sequence().string() + domain +
      " --expect lm,lc" + kRealtime + " --out " + (out / "tr").string() + " > " + (out / "tr.log").string() +
      " 2>&1 & tr=$!; " + untilFrame(72, out / "tr.log") + "kill -9 $lm; wait $tr; status=$?; " + awaitExit("lc") +
      "kill -0 $lc 2>/dev/null && { echo LC still waiting >> " + (out / "lc.log").string() + "; kill $lc; }; wait; exit $status";
  const int status = runWithin(300, out.path(), run);
  ASSERT_EQ(status, 0) << std::ifstream(out / "tr.log").rdbuf();
  const auto tr = report(out / "tr" / "report.json");
  const auto hosted = tasks(tr);
  EXPECT_NE(std::find(hosted.begin(), hosted.end(), "lm"), hosted.end()) << tr.dump();
  // The take-over costs frames today: TR's map gets no new points from the death until the
  // lease ends, tracking is lost for about a second and the slow relocalization attempts make
  // a real-time TR drop frames. How many it keeps depends on
  // the machine's load (149 to 167 of 240 seen with a second test running), so the test asks
  // what does not: that TR tracks again after the take-over and to the end.
  EXPECT_TRUE(tracksTheLastQuarter(out / "tr" / "frames.csv"));
  EXPECT_LT(tr["ate"]["percent_of_path"].get<double>(), 1.0);
  EXPECT_GT(tr["mapping"]["keyframes_processed"].get<int>(), 0);  // it mapped after the LM left
  // LC, fed by TR from the take-over on, ends the run by itself, with TR's map.
  const auto lc = report(out / "lc" / "report.json");
  EXPECT_EQ(lc.value("end_of_run", ""), "completed") << nodeEvents(out.path());
  EXPECT_EQ(lc.value("keyframes", -1), tr.value("keyframes", -2));
  EXPECT_EQ(lc.value("map_points", -1), tr.value("map_points", -2));
  EXPECT_EQ(lc.value("s_full_keyframes", -1), tr.value("s_full_keyframes", -2));
}

// LM, LC and TR as processes on `domain`, TR on the test sequence in real time. The node of
// `task` is killed with kill -9 when TR reaches frame 48 of 240 and started again, with its
// old id and nothing held, writing to <out>/<task>2: an LM or LC at frame 120, a TR at once (on
// the whole sequence again). After TR's end the others get a minute each to finish, then they
// are stopped. Gives the exit status of the TR that ran last, and each task's report (the
// restarted node's from <task>2).
struct RestartRun {
  int status = -1;
  nlohmann::json tr, lm, lc;
};

RestartRun runWithARestart(const fs::path& out, const std::string& task, int domain) {
  const std::string bin = HIVESLAM_BINARY, d = " --domain " + std::to_string(domain);
  auto reached = [&](int frame) { return untilFrame(frame, out / "tr.log"); };
  auto start = [&](const std::string& t, const std::string& name) {
    const std::string input = t == "tr" ? " " + sequence().string() + " --expect lm,lc" + kRealtime : "";
    return bin + " node --task " + t + input + d + " --out " + (out / name).string() + " > " +
           (out / (name + ".log")).string() + " 2>&1 & " + name + "=$!; ";
  };
  const bool tracking = task == "tr";
  const std::string last_tr = tracking ? "tr2" : "tr";
  std::vector<std::string> others;  // the nodes to let finish after TR
  for (const std::string t : {"lm", "lc"}) others.push_back(t == task ? t + "2" : t);
  const std::string run = start("lm", "lm") + start("lc", "lc") + start("tr", "tr") + reached(48) + "kill -9 $" + task +
                          "; " + (tracking ? "" : reached(120)) + start(task, task + "2") + "wait $" + last_tr +
                          "; status=$?; " + awaitExit(others[0]) + awaitExit(others[1]) + "kill $" + others[0] + " $" +
                          others[1] + " 2>/dev/null; wait; exit $status";
  RestartRun r;
  r.status = runWithin(300, out, run);
  if (r.status != 0) return r;
  auto of = [&](const std::string& t) { return report(out / (t == task ? t + "2" : t) / "report.json"); };
  r.tr = of("tr");
  r.lm = of("lm");
  r.lc = of("lc");
  return r;
}

// The mapping node dies at 20% of the frames and is started again at 50%, as it was (the same
// id, nothing held): TR notices the death after the 2 s lease, maps alone, then hands the
// newcomer the map it kept over DDS once the newcomer's readers have matched, and gives
// mapping up to it. At the end all three hold the same map. (A newcomer that starts after TR has gone waits for
// keyframes for good: it gets a minute after TR's end, then it is stopped.)
TEST(NodeProcesses, ARestartedMappingNodeTakesTheMapOverFromTracking) {
  testing::TempDir out;
  const auto [status, tr, lm2, lc] = runWithARestart(out.path(), "lm", 200 + getpid() % 30);
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  EXPECT_EQ(tasks(tr), std::vector<std::string>{"tr"}) << tr.dump();
  EXPECT_EQ(lm2.value("end_of_run", ""), "completed") << std::ifstream(out / "lm2.log").rdbuf();
  EXPECT_GT(tr["mapping"]["keyframes_processed"].get<int>(), 0);   // TR mapped during the outage
  EXPECT_GT(lm2["mapping"]["keyframes_processed"].get<int>(), 0);  // and the newcomer after it
  // The newcomer holds the whole map, not only what it mapped itself.
  expectOneMap(tr, lm2, lc);
  if (HasFailure()) std::cout << nodeEvents(out.path());
}

// The loop-closing node dies at 20% of the frames and is started again at 50%: the gateway
// (LM) closes loops itself meanwhile, then hands the newcomer the map with every keyframe's
// features and gives loop closing back. The newcomer must end the run holding the whole map
// in its SLAM map, not only in S_full: it once joined while LM was sending a global map of
// the same epoch label, took that map's last batch as its snapshot's and never made the
// snapshot's last keyframes (observer_test has the mechanism).
TEST(NodeProcesses, ARestartedLoopClosingNodeTakesTheWholeMapFromTheGateway) {
  testing::TempDir out;
  const auto [status, tr, lm, lc2] = runWithARestart(out.path(), "lc", 50 + getpid() % 50);
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  EXPECT_EQ(tasks(tr), std::vector<std::string>{"tr"}) << tr.dump();
  EXPECT_EQ(tasks(lm), std::vector<std::string>{"lm"}) << std::ifstream(out / "lm.log").rdbuf();
  EXPECT_EQ(lm.value("end_of_run", ""), "completed");
  EXPECT_EQ(lc2.value("end_of_run", ""), "completed") << std::ifstream(out / "lc2.log").rdbuf();
  // The newcomer holds the whole map in its SLAM map and in S_full, as TR and LM do.
  expectOneMap(tr, lm, lc2);
  if (HasFailure()) std::cout << nodeEvents(out.path());
}

// The tracking node dies at 20% of the frames and a new one starts the sequence again from its
// first frame: the gateway hands it the map so far (features included), and whether it
// relocalizes in that map or starts a new one that LC merges, all three end the run with one map.
TEST(NodeProcesses, ARestartedTrackingNodeGetsTheMapAndEndsWithOneMap) {
  testing::TempDir out;
  const auto [status, tr2, lm, lc] = runWithARestart(out.path(), "tr", 10 + getpid() % 40);
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  EXPECT_EQ(tasks(tr2), std::vector<std::string>{"tr"}) << tr2.dump();
  EXPECT_EQ(lm.value("end_of_run", ""), "completed") << std::ifstream(out / "lm.log").rdbuf();
  EXPECT_EQ(lc.value("end_of_run", ""), "completed") << std::ifstream(out / "lc.log").rdbuf();
  EXPECT_EQ(tr2.value("maps", 0), 1) << std::ifstream(out / "tr2.log").rdbuf();
  EXPECT_GT(tr2.value("tracked_frames", 0), 200);
  expectOneMap(tr2, lm, lc);
  if (HasFailure()) std::cout << nodeEvents(out.path());
}

// Three network namespaces joined by a bridge, each with its own network stack as on separate
// devices, made by the test (root) and removed when it ends. `loss_per_mille` > 0 drops that
// share of the IPv4 packets crossing the bridge (an nftables rule: this kernel has no netem),
// discovery included.
class Namespaces {
 public:
  // `loss_per_mille`: packets the bridge drops; `tr_link_kbit`: the rate TR's link carries each
  // way (a tbf queue at both of its ends, 300 ms deep), 0 for the veth's own.
  explicit Namespaces(int loss_per_mille = 0, int tr_link_kbit = 0)
      : tag_(std::to_string(getpid() % 100000)), br_("hsbr" + tag_) {
    std::string setup = "set -e; ip link add " + br_ + " type bridge; ip link set " + br_ + " up;";
    for (int i = 1; i <= 3; ++i) {
      const std::string v = "hv" + tag_ + std::to_string(i);
      setup += "ip netns add " + name(i) + "; ip link add " + v + " type veth peer name " + v + "p; ip link set " + v +
               "p master " + br_ + "; ip link set " + v + "p up; ip link set " + v + " netns " + name(i) + ";" +
               "ip netns exec " + name(i) + " ip addr add 10.213." + std::to_string(getpid() % 200) + "." +
               std::to_string(i) + "/24 dev " + v + "; ip netns exec " + name(i) + " ip link set " + v +
               " up; ip netns exec " + name(i) + " ip link set lo up; ip netns exec " + name(i) +
               " ip route add 224.0.0.0/4 dev " + v + ";";
    }
    if (std::system(("(" + setup + ") > /dev/null 2>&1").c_str()) != 0) {
      skip_ = "cannot make network namespaces here (ip netns / veth / bridge failed)";
      return;
    }
    if (tr_link_kbit > 0) {
      const std::string v = "hv" + tag_ + "1", tbf = " root tbf rate " + std::to_string(tr_link_kbit) + "kbit burst 16kb latency 300ms";
      const std::string cap = "tc qdisc add dev " + v + "p" + tbf + " && ip netns exec " + name(1) + " tc qdisc add dev " + v + tbf;
      if (std::system(("(" + cap + ") > /dev/null 2>&1").c_str()) != 0)
        skip_ = "cannot cap a link's rate (tc from Debian's iproute2, with sch_tbf in the kernel)";
    }
    if (loss_per_mille > 0) {
      const std::string rule = "nft add table bridge " + table() + " && nft add chain bridge " + table() +
                               " lossy '{ type filter hook forward priority 0; }' && nft add rule bridge " + table() +
                               " lossy ether type ip numgen random mod 1000 '<' " + std::to_string(loss_per_mille) +
                               " counter drop";
      if (std::system(("(" + rule + ") > /dev/null 2>&1").c_str()) != 0)
        skip_ = "cannot drop packets on the bridge (nft from Debian's nftables, with nf_tables in the kernel)";
    }
  }
  ~Namespaces() {
    std::string teardown = "nft delete table bridge " + table() + " 2>/dev/null; nft delete table bridge " + cutTable() + " 2>/dev/null;";
    for (int i = 1; i <= 3; ++i) teardown += "ip netns del " + name(i) + " 2>/dev/null;";
    teardown += "ip link del " + br_ + " 2>/dev/null; true";
    std::system(teardown.c_str());
  }
  const std::string& skipReason() const { return skip_; }
  std::string name(int i) const { return "hs" + tag_ + "n" + std::to_string(i); }
  // Shell commands that cut namespace 1 (TR) from each of `others` (2: LM, 3: LC), both ways,
  // `at` seconds after they start, and restore the links `lasting` seconds later, in the order
  // of `others`, `stagger` seconds apart: a partition on the bridge, while every node stays up.
  // Run in the background beside the nodes (inside runWithin's single quotes: no single quote
  // in it).
  std::string partition(double at, double lasting, const std::vector<int>& others, double stagger = 0) const {
    std::string cut = "nft add table bridge " + cutTable() + ";", heal = "sleep " + std::to_string(lasting) + ";";
    const std::string tr = "hv" + tag_ + "1p";
    for (size_t k = 0; k < others.size(); ++k) {
      const std::string chain = "bridge " + cutTable() + " cut" + std::to_string(others[k]);
      cut += "nft add chain " + chain + " \"{ type filter hook forward priority 0; }\";";
      if (k > 0 && stagger > 0) heal += "sleep " + std::to_string(stagger) + ";";
      heal += "nft flush chain " + chain + ";";
    }
    cut += "sleep " + std::to_string(at) + ";";
    for (int i : others) {
      const std::string rule = "nft add rule bridge " + cutTable() + " cut" + std::to_string(i) + " iifname ";
      const std::string peer = "hv" + tag_ + std::to_string(i) + "p";
      cut += rule + tr + " oifname " + peer + " drop;" + rule + peer + " oifname " + tr + " drop;";
    }
    return "(" + cut + heal + ") > /dev/null 2>&1 & ";
  }
  // Packets the bridge dropped so far (the nft rule's counter).
  long dropped() const {
    const std::string cmd = "nft list table bridge " + table() + " 2>/dev/null | grep -o 'packets [0-9]*' | cut -d' ' -f2";
    FILE* f = popen(cmd.c_str(), "r");
    if (!f) return -1;
    long n = -1;
    if (std::fscanf(f, "%ld", &n) != 1) n = -1;
    pclose(f);
    return n;
  }

 private:
  std::string table() const { return "hsloss" + tag_; }
  std::string cutTable() const { return "hscut" + tag_; }
  std::string tag_, br_, skip_;
};

// TR, LM and LC in namespaces 1, 2 and 3 on `domain`; the exit status of TR (LM and LC are waited
// for, all three within 600 s). Logs are out/tr.log, lm.log and lc.log.
int runInNamespaces(const Namespaces& ns, const fs::path& out, int domain, const std::string& tr_options = "",
                    const std::string& before = "", const fs::path& seq = sequence(), bool atlases = false) {
  const std::string bin = HIVESLAM_BINARY, dom = " --domain " + std::to_string(domain) + " ";
  // Each node's maps saved as out/<task>/atlas.bin (expectSamePoses).
  auto atlas = [&](const char* task) { return atlases ? " --atlas-out " + (out / task / "atlas.bin").string() : std::string(); };
  auto node = [&](int i, const std::string& args) {
    const std::string log = i == 1 ? "tr.log" : i == 2 ? "lm.log" : "lc.log";
    return "ip netns exec " + ns.name(i) + " " + bin + " node" + dom + args + " > " + (out / log).string() + " 2>&1";
  };
  const std::string run = before + node(2, "--task lm --out " + (out / "lm").string() + atlas("lm")) + " & " +
                          node(3, "--task lc --out " + (out / "lc").string() + atlas("lc")) + " & " +
                          node(1, "--task tr " + seq.string() + tr_options + " --expect lm,lc --out " + (out / "tr").string() + atlas("tr")) +
                          "; status=$?; wait; exit $status";
  return runWithin(600, out, run);
}

TEST(NodeProcesses, ThreeNodesInThreeNetworkNamespaces) {
  if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
  const Namespaces ns;
  if (!ns.skipReason().empty()) GTEST_SKIP() << ns.skipReason();
  testing::TempDir out;
  const int status = runInNamespaces(ns, out.path(), 7);
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  const auto tr = report(out / "tr" / "report.json"), lm = report(out / "lm" / "report.json");
  EXPECT_EQ(tasks(tr), std::vector<std::string>{"tr"});
  EXPECT_GT(tr.value("tracked_frames", 0), 200);
  EXPECT_EQ(lm.value("end_of_run", ""), "completed");
  EXPECT_EQ(tr.value("s_full_keyframes", 0), lm.value("s_full_keyframes", -1));
  if (HasFailure()) std::cout << nodeEvents(out.path());
}

// One packet in 20 lost on every link, discovery and the end-of-run exchange included: the
// system still maps in real time, ends with one map on every node, and no node waits forever.
// With 64 KB datagrams (about 45 IP fragments each) and Fast DDS's 3 s heartbeat, 2% loss
// already left TR waiting on mapping for 170 frames and LC waiting for a Done that never came.
TEST(NodeProcesses, ThreeNodesOverALossyLink) {
  if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
  const Namespaces ns(50);
  if (!ns.skipReason().empty()) GTEST_SKIP() << ns.skipReason();
  testing::TempDir out;
  const int status = runInNamespaces(ns, out.path(), 8, kRealtime);
  EXPECT_GT(ns.dropped(), 100) << "the bridge dropped too few packets to test anything";
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  const auto tr = report(out / "tr" / "report.json"), lm = report(out / "lm" / "report.json"),
             lc = report(out / "lc" / "report.json");
  EXPECT_EQ(tasks(tr), std::vector<std::string>{"tr"});
  EXPECT_EQ(lm.value("end_of_run", ""), "completed");
  EXPECT_EQ(lc.value("end_of_run", ""), "completed");
  if (!kSanitized) {
    EXPECT_GT(tr.value("tracked_frames", 0), 200);
  }
  expectOneMap(tr, lm, lc);
  if (HasFailure()) std::cout << nodeEvents(out.path());
}

// A partition in mid-run, every node up: TR cut off from LM (and LC) by a rule on the bridge,
// then the link restored. During the cut each side sees the other leave after its lease; TR
// maps alone and, when the link is back, hands the map to the returning peers. The run ends with
// the same keyframes and points, to 1 mm, on all three, and TR's trajectory right
// (docs/RELIABILITY.md has the figures of longer runs against an uncut one).
void expectHealed(const fs::path& out) {
  const auto tr = report(out / "tr" / "report.json"), lm = report(out / "lm" / "report.json"),
             lc = report(out / "lc" / "report.json");
  EXPECT_EQ(tasks(tr), std::vector<std::string>{"tr"});
  for (const auto* r : {&tr, &lm, &lc}) EXPECT_EQ(r->value("end_of_run", ""), "completed") << r->value("task", "");
  expectOneMap(tr, lm, lc);
  expectSamePoses(out);
}

// The slower 900-frame loop (45 s, 9.4 m) with TR cut off from `peers` at `at` s for `lasting`
// s, in real time; the heal judged by expectHealed. On the 240-frame loop (12 s), cut at 3 s
// while its map was young and fast-growing, TR lost tracking in 2 of 14 runs while it waited
// out the 2 s lease for LM's answers, and started a second map: docs/RELIABILITY.md has that
// case open.
void expectHealsAfterCut(int domain, int at, int lasting, const std::vector<int>& peers, double stagger = 0) {
  const Namespaces ns;
  if (!ns.skipReason().empty()) GTEST_SKIP() << ns.skipReason();
  testing::TempDir out;
  // At the heal TR hands its map over while it tracks; the heal is judged here, not the policy
  // that releases peers over a slow link (tests of its own): under load the first answers of the
  // new gateway took over a second and TR released its peers, so TR keeps offloading.
  std::ofstream(out / "offload.yaml") << "distribution:\n  release_slow_gateway_ms: 0\n";
  const int status = runInNamespaces(ns, out.path(), domain, kRealtime + " --config " + (out / "offload.yaml").string(),
                                     ns.partition(at, lasting, peers, stagger), sequence(900), true);
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  expectHealed(out.path());
  if (::testing::Test::HasFailure()) std::cout << nodeEvents(out.path());
}

TEST(NodeProcesses, AFiveSecondPartitionBetweenTrackingAndMappingHeals) {
  if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
  expectHealsAfterCut(11, 10, 5, {2});
}

// 30 s, from both peers: LM and LC still hear each other, TR hears neither. LC's global BAs of
// the map as it was go on during the cut; at the heal TR's map, which holds the 30 s it mapped
// alone, must win over theirs whatever its label (it ended at 2.8% of the path when LC's newer
// label won).
TEST(NodeProcesses, AThirtySecondPartitionFromBothPeersHeals) {
  if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
  expectHealsAfterCut(12, 6, 30, {2, 3});
}

// The same cut, LC's link back 2 s after LM's: TR gives mapping to LM with its map before LC
// hears TR again, so LC misses that hand-over and would learn of the keyframes TR mapped alone
// only from LM's records of them, without their features. It asks LM for the map instead. The
// 30 s test above ended so twice under ctest -j2, where TR heard LC 80 ms after LM: LC with 14
// of the 78 keyframes in its map.
TEST(NodeProcesses, APartitionThatHealsForLoopClosingLastHeals) {
  if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
  expectHealsAfterCut(13, 6, 30, {2, 3}, 2);
}

// TR's link carries 5 Mbit/s each way, as a slow radio link would. TR sends 1-4 Mbit/s on
// average, in bursts of 50 KB keyframes, so it tracks worse than on a fast link; but the
// end-of-run exchange completes and every node ends with the same map, pose for pose. A leaving
// node waited 1 s for its last packets to be acknowledged: the gateway's last snapshot was still
// on the link when it left, and TR waited out 120 s for a Done that never came. Tracking is lost
// and maps are made and merged here, and a merge reaches TR late: a keyframe TR made in a map
// LC had merged away was dropped at LM, and TR ended 1 run in 4 a keyframe ahead.
TEST(NodeProcesses, ThreeNodesOverASlowLink) {
  if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
  const Namespaces ns(0, 5000);
  if (!ns.skipReason().empty()) GTEST_SKIP() << ns.skipReason();
  testing::TempDir out;
  // The exchange over a slow link, so TR keeps offloading: at 5 Mbit/s its acknowledgements
  // take up to 7 s, and it may otherwise release its peers (the next test).
  std::ofstream(out / "offload.yaml") << "distribution:\n  release_slow_gateway_ms: 0\n";
  const int status = runInNamespaces(ns, out.path(), 9, kRealtime + " --config " + (out / "offload.yaml").string(), "",
                                     sequence(), true);
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  const auto tr = report(out / "tr" / "report.json"), lm = report(out / "lm" / "report.json"),
             lc = report(out / "lc" / "report.json");
  EXPECT_EQ(tr.value("end_of_run", ""), "completed");
  EXPECT_EQ(lm.value("end_of_run", ""), "completed");
  EXPECT_EQ(lc.value("end_of_run", ""), "completed");
  expectSameMaps(tr, lm, lc);  // the trajectory itself may be worse than on a fast link
  expectSamePoses(out.path());
  if (HasFailure()) std::cout << nodeEvents(out.path());
}


// TR's link at 2 Mbit/s: an acknowledgement takes seconds, and offloading lost 4 maps of the
// 240-frame loop (1.3% ATE). TR now releases LM and LC at its first loss and maps alone: one
// map, nearly every frame tracked; LM and LC leave, their run "released". Real time only:
// offline, tracking waits for the gateway and never starves.
TEST(NodeProcesses, TrackingReleasesItsPeersOverAVerySlowLinkAndMapsAlone) {
  if (kSanitized) GTEST_SKIP() << "a release follows real-time starvation; sanitized builds run offline";
  if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root";
  const Namespaces ns(0, 2000);
  if (!ns.skipReason().empty()) GTEST_SKIP() << ns.skipReason();
  testing::TempDir out;
  const int status = runInNamespaces(ns, out.path(), 11, kRealtime);
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  const auto tr = report(out / "tr" / "report.json"), lm = report(out / "lm" / "report.json"),
             lc = report(out / "lc" / "report.json");
  ASSERT_TRUE(tr.contains("peers_released")) << nodeEvents(out.path());
  EXPECT_EQ(tr["peers_released"].size(), 2u);
  EXPECT_EQ(tasks(tr), (std::vector<std::string>{"tr", "lm", "lc"})) << "TR ends the run as the whole system";
  EXPECT_EQ(tr.value("end_of_run", ""), "completed");
  EXPECT_EQ(lm.value("end_of_run", ""), "released");
  EXPECT_EQ(lc.value("end_of_run", ""), "released");
  EXPECT_EQ(tr.value("maps", 0), 1);
  EXPECT_GT(tr.value("tracked_frames", 0), 200);
  EXPECT_LT(tr["ate"]["percent_of_path"].get<double>(), 0.5);
  if (HasFailure()) std::cout << nodeEvents(out.path());
}

// The mapping node dies after TR's EndOfSequence reached it, before its last snapshot and Done.
// TR stops waiting once the lease ends, maps again, and finishes the exchange with LC as the
// new gateway: both end with the exchange completed and the same map. Before, TR ended
// "incomplete" and LC waited for a Done until it was killed; and once TR asked LC, LC ignored
// TR's last snapshot as long as the global maps the dead LM had not relayed were not sent to
// TR again (TR's map stayed in an older epoch; LC ended 79-280 points short).
TEST(NodeProcesses, AMappingNodeThatDiesAtTheEndLeavesTrackingToFinishWithLoopClosing) {
  testing::TempDir out;
  const std::string bin = HIVESLAM_BINARY, domain = " --domain " + std::to_string(100 + getpid() % 50);
  const std::string lm_log = (out / "lm.log").string();
  const std::string run =
      bin + " node --task lm" + domain + " --out " + (out / "lm").string() + " > " + lm_log + " 2>&1 & lm=$!; " + bin +
      " node --task lc" + domain + " --out " + (out / "lc").string() + " > " + (out / "lc.log").string() +
      " 2>&1 & lc=$!; " + bin + " node --task tr " + sequence().string() + domain + " --expect lm,lc" + kRealtime +
      " --out " + (out / "tr").string() + " > " + (out / "tr.log").string() + " 2>&1 & tr=$!; " +
      "until ! kill -0 $tr || grep -q \"end of the sequence\" " + lm_log + "; do sleep 0.02; done; kill -9 $lm; " +
      "wait $tr; status=$?; " + awaitExit("lc") + "kill -0 $lc 2>/dev/null && { echo LC still waiting >> " + (out / "lc.log").string() + "; kill $lc; }; wait; exit $status";
  const int status = runWithin(300, out.path(), run);
  ASSERT_EQ(status, 0) << nodeEvents(out.path());
  ASSERT_FALSE(fs::exists(out / "lm" / "report.json")) << "LM ended before it was killed";
  const auto tr = report(out / "tr" / "report.json"), lc = report(out / "lc" / "report.json");
  EXPECT_EQ(tr.value("end_of_run", ""), "completed");
  EXPECT_EQ(lc.value("end_of_run", ""), "completed");
  EXPECT_EQ(lc.value("keyframes", -1), tr.value("keyframes", -2));
  EXPECT_EQ(lc.value("map_points", -1), tr.value("map_points", -2));
  EXPECT_EQ(lc.value("s_full_keyframes", -1), tr.value("s_full_keyframes", -2));
  expectSFullInMap(tr, "tr");
  expectSFullInMap(lc, "lc");
  EXPECT_LT(tr["ate"]["percent_of_path"].get<double>(), 1.0);
  if (HasFailure()) std::cout << nodeEvents(out.path());
}

}  // namespace
}  // namespace hiveslam
