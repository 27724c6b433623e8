// The live view of real processes: a 3-node cluster's ROS 2 visualization topics, read with
// plain DDS readers of the standard types, listed by `hiveslam topics`, and watched by
// `hiveslam view` without it becoming anyone's peer; and the web page of a real-time run, drawn
// by headless Chromium (skipped with a message where Chromium is not installed).
#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "sensor_msgs/msg/PointCloud2PubSubTypes.h"
#include "rendered_sequence.hpp"
#include "temp_dir.hpp"
#include "tf2_msgs/msg/TFMessagePubSubTypes.h"
#include "visualization_msgs/msg/MarkerArrayPubSubTypes.h"
#include "viz/ros/ros_messages.hpp"
#include "viz/ros/viz_participant.hpp"

namespace hiveslam {
namespace {

namespace fs = std::filesystem;
namespace dds = eprosima::fastdds::dds;

constexpr bool kSanitized = HIVESLAM_SANITIZED;
const std::string kRealtime = kSanitized ? "" : " --realtime";

// The rendered loop of these tests.
const fs::path& sequence(int frames) { return testing::renderedLoop(frames); }

std::string slurp(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string run(const std::string& cmd) {
  std::string out;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, f)) out.append(buf, n);
  pclose(f);
  return out;
}

// The frame TR's progress line reached ("tracking 60/240"), 0 before the first.
int trackedSoFar(const fs::path& log) {
  const std::string text = slurp(log);
  static const std::regex progress("tracking ([0-9]+)/");
  int last = 0;
  for (std::sregex_iterator it(text.begin(), text.end(), progress), end; it != end; ++it) last = std::stoi((*it)[1]);
  return last;
}

void waitUntil(const std::function<bool()>& done, std::chrono::seconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!done() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

nlohmann::json report(const fs::path& file) {
  std::ifstream in(file);
  return in ? nlohmann::json::parse(in, nullptr, false) : nlohmann::json::object();
}

// The last message of each topic, as a ROS 2 tool would read them.
struct Received {
  std::mutex mutex;
  std::optional<geometry_msgs::msg::PoseStamped> pose;
  std::optional<tf2_msgs::msg::TFMessage> tf;
  std::optional<nav_msgs::msg::Path> path;
  std::optional<sensor_msgs::msg::PointCloud2> points;
  std::optional<visualization_msgs::msg::MarkerArray> markers;
  int messages = 0;
};

template <class T, class PubSub>
void listen(viz::ros::VizParticipant& p, const std::string& topic, Received& r, std::optional<T> Received::*slot) {
  p.reader(topic, dds::TypeSupport(new PubSub()), 1,
           [&r, slot](dds::DataReader* reader) {
             viz::ros::takeAll<T>(reader, [&](T& m) {
               std::lock_guard lock(r.mutex);
               r.*slot = m;
               ++r.messages;
             });
           },
           true);
}

TEST(LiveViewProcesses, AClusterPublishesTheRosTypesAndAViewJoinsWithoutATask) {
  testing::TempDir out;
  const int domain = 100 + getpid() % 40;
  const std::string bin = HIVESLAM_BINARY, d = " --domain " + std::to_string(domain);
  Received got;
  viz::ros::VizParticipant p(domain, "test-reader");
  listen<geometry_msgs::msg::PoseStamped, geometry_msgs::msg::PoseStampedPubSubType>(p, "rt/hiveslam/tr/pose", got, &Received::pose);
  listen<tf2_msgs::msg::TFMessage, tf2_msgs::msg::TFMessagePubSubType>(p, "rt/hiveslam/tr/tf", got, &Received::tf);
  listen<nav_msgs::msg::Path, nav_msgs::msg::PathPubSubType>(p, "rt/hiveslam/tr/path", got, &Received::path);
  listen<sensor_msgs::msg::PointCloud2, sensor_msgs::msg::PointCloud2PubSubType>(p, "rt/hiveslam/lm/points", got, &Received::points);
  listen<visualization_msgs::msg::MarkerArray, visualization_msgs::msg::MarkerArrayPubSubType>(
      p, "rt/hiveslam/lm/keyframe_markers", got, &Received::markers);

  const fs::path seq = sequence(240);
  auto node = [&](const std::string& task, const std::string& extra) {
    return bin + " node --task " + task + extra + d + " --out " + (out / task).string() + " > " + (out / (task + ".log")).string() + " 2>&1";
  };
  std::thread cluster([&] {
    std::system(("timeout 240 bash -c '" + node("lm", "") + " & " + node("lc", "") + " & " +
                 node("tr", " " + seq.string() + " --expect lm,lc" + kRealtime) + "; wait'").c_str());
  });
  waitUntil([&] { return trackedSoFar(out / "tr.log") >= 60; }, std::chrono::seconds(120));
  const std::string topics = run(bin + " topics" + d + " --wait 3");
  const std::string view = run(bin + " view" + d + " --port 0 --seconds 4 2>&1");
  cluster.join();

  for (const char* line : {"/hiveslam/tr/pose [geometry_msgs/msg/PoseStamped]", "/hiveslam/tr/path [nav_msgs/msg/Path]",
                           "/hiveslam/tr/tf [tf2_msgs/msg/TFMessage]", "/hiveslam/lm/points [sensor_msgs/msg/PointCloud2]",
                           "/hiveslam/lm/keyframe_markers [visualization_msgs/msg/MarkerArray]"})
    EXPECT_NE(topics.find(line), std::string::npos) << line << " not in:\n" << topics;

  const auto tr = report(out / "tr" / "report.json"), lm = report(out / "lm" / "report.json"),
             lc = report(out / "lc" / "report.json");
  ASSERT_TRUE(tr.contains("tracked_frames")) << slurp(out / "tr.log");
  // The view was no one's peer and moved no task.
  EXPECT_EQ(tr.value("peers", -1), 2) << slurp(out / "tr.log") << slurp(out / "lm.log") << slurp(out / "lc.log");
  EXPECT_EQ(tr["tasks"], nlohmann::json({"tr"}));
  EXPECT_EQ(lm["tasks"], nlohmann::json({"lm"}));
  EXPECT_EQ(lc["tasks"], nlohmann::json({"lc"}));
  EXPECT_EQ(tr.value("end_of_run", ""), "completed");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(view, m, std::regex("view: ([0-9]+) messages read"))) << view;
  EXPECT_GT(std::stoi(m[1]), 10) << view;

  std::lock_guard lock(got.mutex);
  ASSERT_TRUE(got.pose && got.tf && got.path && got.points && got.markers) << got.messages << " messages";
  EXPECT_EQ(got.pose->header().frame_id(), "map");
  ASSERT_EQ(got.tf->transforms().size(), 1u);
  EXPECT_EQ(got.tf->transforms()[0].header().frame_id(), "map");
  EXPECT_EQ(got.tf->transforms()[0].child_frame_id(), "camera");
  // The last path, sent as TR left, has every tracked frame.
  EXPECT_EQ(static_cast<int>(got.path->poses().size()), tr["tracked_frames"].get<int>());
  EXPECT_EQ(got.path->header().frame_id(), "map");
  // The points lie around the trajectory, within a few of its extents (a room seen from inside).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& q : got.path->poses()) centre += Eigen::Vector3d(q.pose().position().x(), q.pose().position().y(), q.pose().position().z());
  centre /= std::max<size_t>(got.path->poses().size(), 1);
  double extent = 0;
  for (const auto& q : got.path->poses())
    extent = std::max(extent, (Eigen::Vector3d(q.pose().position().x(), q.pose().position().y(), q.pose().position().z()) - centre).norm());
  const viz::MapScene cloud = viz::ros::fromPointCloud(*got.points);
  ASSERT_GT(cloud.points.size(), 500u);
  EXPECT_EQ(got.points->header().frame_id(), "map");
  size_t inside = 0;
  for (const auto& q : cloud.points) {
    ASSERT_TRUE(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z));
    if ((Eigen::Vector3d(q.x, q.y, q.z) - centre).norm() < 5 * extent) ++inside;
  }
  EXPECT_GT(inside, cloud.points.size() * 9 / 10) << "extent " << extent;
  EXPECT_EQ(static_cast<int>(cloud.points.size()), lm["map_points"].get<int>());
  ASSERT_EQ(got.markers->markers().size(), 3u);
  EXPECT_EQ(static_cast<int>(got.markers->markers()[0].points().size()), 16 * lm["keyframes"].get<int>());
}

// Pixels of the 3D view that are not its background: points, frusta, the path.
int drawnPixels(const cv::Mat& shot, int view_width) {
  int n = 0;
  for (int y = 40; y < shot.rows; ++y)
    for (int x = 0; x < std::min(view_width, shot.cols); ++x) {
      const cv::Vec3b c = shot.at<cv::Vec3b>(y, x);  // background 0x15171c
      if (std::abs(c[0] - 0x1c) + std::abs(c[1] - 0x17) + std::abs(c[2] - 0x15) > 60) ++n;
    }
  return n;
}

TEST(LiveViewProcesses, TheWebPageDrawsTheMapAndItsCountsRise) {
  if (kSanitized) GTEST_SKIP() << "the page is read from a real-time run";
  const std::string chromium = run("command -v chromium chromium-browser 2>/dev/null | head -n 1");
  if (chromium.empty()) GTEST_SKIP() << "Chromium is not installed (scripts/setup installs it)";
  // Bounded: a page that never lets the network go idle must fail the test, not hang it.
  const std::string browser = "timeout 60 " + chromium.substr(0, chromium.find('\n')) +
                              " --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader"
                              " --virtual-time-budget=5000 --window-size=1280,720";
  testing::TempDir out;
  const std::string bin = HIVESLAM_BINARY;
  // --viewer-wait: the page stays up after the run until SIGINT, for the screenshot.
  std::thread slam([&] {
    std::system(("bash -c '" + bin + " run " + sequence(400).string() + " --realtime --viewer 0 --viewer-wait --out " +
                 (out / "run").string() + " > " + (out / "run.log").string() + " 2>&1 & echo $! > " +
                 (out / "pid").string() + "; wait'")
                    .c_str());
  });
  std::smatch m;
  std::string log;
  waitUntil([&] { log = slurp(out / "run.log"); return std::regex_search(log, m, std::regex("live view: (http://[^ \n]+)")); },
            std::chrono::seconds(60));
  ASSERT_FALSE(m.empty()) << log;
  const std::string url = m[1];
  waitUntil([&] { return trackedSoFar(out / "run.log") >= 60; }, std::chrono::seconds(60));
  // ?panels=N: the page stops listening after N updates, so that the browser's network goes idle.
  auto count = [&] {
    const std::string dom = run(browser + " --dump-dom '" + url + "?panels=2' 2>/dev/null");
    std::smatch c;
    return std::regex_search(dom, c, std::regex("data-count=\"([0-9]+)\"")) ? std::stoi(c[1]) : -1;
  };
  const int first = count();
  const int second = count();
  run(browser + " --screenshot=" + (out / "page.png").string() + " '" + url + "?panels=3' 2>/dev/null");
  // Ctrl-C once the run is over: before, it comes while SIGINT is still ignored (bash starts a
  // background job so), and the page then stayed up for good (a CI run hung here).
  waitUntil([&] { return slurp(out / "run.log").find("run over") != std::string::npos; }, std::chrono::seconds(120));
  std::system(("kill -INT $(cat " + (out / "pid").string() + ")").c_str());
  slam.join();
  const cv::Mat shot = cv::imread((out / "page.png").string());
  ASSERT_FALSE(shot.empty()) << "no screenshot";
  EXPECT_GT(drawnPixels(shot, shot.cols - 360), 2000) << "the 3D view looks empty";
  EXPECT_GT(first, 0);
  EXPECT_GT(second, first);
}

}  // namespace
}  // namespace hiveslam
