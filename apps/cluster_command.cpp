// hiveslam cluster --nodes 1|2|3 DATASET --out DIR: the distributed system as separate
// processes on this machine. Writes DIR/trajectory.tum (and the rest of what `run` writes) from
// TR, and DIR/<task>/report.json for every node.
#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "apps/cluster.hpp"
#include "apps/commands.hpp"
#include "common/error.hpp"

extern char** environ;

namespace hiveslam::apps {

namespace {

namespace fs = std::filesystem;

pid_t spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ) != 0)
    throw InputError("cannot start a node process");
  return pid;
}

// Waits for a child up to `seconds`; then SIGTERM, then SIGKILL. Returns its exit status (-1
// when it had to be killed).
int reap(pid_t pid, int seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  int status = 0;
  for (int sig : {0, SIGTERM, SIGKILL}) {
    if (sig) kill(pid, sig);
    const auto until = sig == 0 ? deadline : std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (std::chrono::steady_clock::now() < until) {
      const pid_t r = waitpid(pid, &status, WNOHANG);
      if (r == pid) return sig == 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  waitpid(pid, &status, 0);
  return -1;
}

nlohmann::json readReport(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return nlohmann::json::object();
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception&) {
    return nlohmann::json::object();
  }
}

}  // namespace

ClusterResult runCluster(const ClusterOptions& o) {
  if (o.nodes < 1 || o.nodes > 3) throw InputError("--nodes must be 1, 2 or 3");
  if (!fs::exists(o.dataset)) throw InputError("dataset not found: " + o.dataset);
  const fs::path out(o.out);
  fs::create_directories(out);
  const int domain = o.domain >= 0 ? o.domain : 1 + static_cast<int>(getpid() % 200);
  std::vector<std::string> common;
  if (!o.config.empty()) common.insert(common.end(), {"--config", o.config});
  if (o.no_loop_closing) common.push_back("--no-loop-closing");
  if (!o.secure.empty()) common.insert(common.end(), {"--secure", o.secure});  // each node: DIR/<its task>
  std::vector<std::pair<std::string, pid_t>> services;
  const std::vector<std::string> tasks = o.nodes == 3 ? std::vector<std::string>{"lm", "lc"}
                                         : o.nodes == 2 ? std::vector<std::string>{"lm"}
                                                        : std::vector<std::string>{};
  for (const auto& task : tasks) {
    std::vector<std::string> args{"hiveslam", "node", "--task", task, "--domain", std::to_string(domain), "--out",
                                  (out / task).string()};
    args.insert(args.end(), common.begin(), common.end());
    if (o.save_atlases) args.insert(args.end(), {"--atlas-out", (out / task / "atlas.bin").string()});
    services.emplace_back(task, spawn(args));
  }
  // TR's input: the dataset itself, or (feed_topic) an image topic that a player publishes.
  std::vector<std::string> input{o.dataset};
  const std::string topic = "/camera/image_raw";
  if (o.feed_topic) {
    std::string calibration = o.config;
    if (calibration.empty() && fs::exists(fs::path(o.dataset) / "mav0/cam0/sensor.yaml"))
      calibration = (fs::path(o.dataset) / "mav0/cam0/sensor.yaml").string();
    if (calibration.empty()) throw InputError("feeding a topic needs the camera calibration: pass --config");
    input = {"--topic", topic, "--calibration", calibration, "--ground-truth", o.dataset};
  }
  // One node is the standalone system: no DDS participant at all (fed from a topic, only the
  // image reader's).
  std::vector<std::string> tr{"hiveslam"};
  if (o.nodes == 1) {
    tr.push_back("run");
    tr.insert(tr.end(), input.begin(), input.end());
    tr.insert(tr.end(), {"--out", (out / "tr").string()});
    if (o.feed_topic) tr.insert(tr.end(), {"--domain", std::to_string(domain)});
  } else {
    std::string expect;
    for (const auto& t : tasks) expect += (expect.empty() ? "" : ",") + t;
    tr.insert(tr.end(), {"node", "--task", "tr"});
    tr.insert(tr.end(), input.begin(), input.end());
    tr.insert(tr.end(), {"--domain", std::to_string(domain), "--out", (out / "tr").string(), "--expect", expect});
  }
  if (o.realtime) tr.push_back("--realtime");
  tr.insert(tr.end(), common.begin(), common.end());
  if (o.save_atlases) tr.insert(tr.end(), {"--atlas-out", (out / "tr" / "atlas.bin").string()});
  const pid_t tr_pid = spawn(tr);
  pid_t player = 0;
  if (o.feed_topic) {  // the player waits for TR's reader, which TR makes once its peers are there
    std::vector<std::string> args{"hiveslam", "play", o.dataset, "--topic", topic, "--domain", std::to_string(domain),
                                  "--wait", "60"};
    if (!o.secure.empty()) args.insert(args.end(), {"--secure", o.secure});
    player = spawn(args);
  }
  const int tr_status = reap(tr_pid, o.timeout_seconds);
  if (player && reap(player, 5) != 0) fmt::print(stderr, "cluster: the player did not end cleanly\n");
  // After TR's end-of-run exchange the others finish on their own; a stuck one is stopped.
  for (const auto& [task, pid] : services) {
    const int status = reap(pid, tr_status == 0 ? 30 : 1);
    if (status != 0) fmt::print(stderr, "cluster: the {} node ended with status {}\n", task, status);
  }
  if (tr_status != 0) throw InputError(fmt::format("the tr node failed (status {})", tr_status));
  for (const char* f : {"trajectory.tum", "keyframes.tum", "trajectory.png", "frames.csv"})
    if (fs::exists(out / "tr" / f)) fs::copy_file(out / "tr" / f, out / f, fs::copy_options::overwrite_existing);
  ClusterResult r;
  r.reports["tr"] = readReport(out / "tr" / "report.json");
  for (const auto& t : tasks) r.reports[t] = readReport(out / t / "report.json");
  return r;
}

void addClusterCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("cluster", "Run TR, LM and LC as separate processes on this machine");
  cmd->footer("Example:\n  hiveslam cluster --nodes 3 seq/figure8 --realtime --out out/cluster");
  auto o = std::make_shared<ClusterOptions>();
  cmd->add_option("--nodes", o->nodes, "1 (standalone), 2 (TR + LM) or 3 (TR + LM + LC)")->capture_default_str();
  cmd->add_option("DATASET", o->dataset, "What `hiveslam run` reads")->required();
  cmd->add_option("--out", o->out, "Output folder")->required();
  cmd->add_option("--config", o->config, "Settings YAML");
  cmd->add_option("--domain", o->domain, "DDS domain id (default: picked from the process id)");
  cmd->add_flag("--realtime", o->realtime, "Feed frames at their timestamps");
  cmd->add_flag("--no-loop-closing", o->no_loop_closing, "Switch loop closing off");
  cmd->add_flag("--atlases", o->save_atlases, "Each node saves its maps to DIR/<task>/atlas.bin (hiveslam run --atlas-in reads them)");
  cmd->add_flag("--feed-topic", o->feed_topic, "Play the dataset as a ROS 2 image topic to TR (the paper's set-up)");
  cmd->add_option("--secure", o->secure, "DDS Security: the keys folder `hiveslam keys` made (each node uses DIR/tr, DIR/lm, DIR/lc)");
  cmd->callback([o]() {
    const auto r = runCluster(*o);
    for (const auto& [task, j] : r.reports) {
      const double cpu = j.value("cpu_seconds", 0.0);
      fmt::print("{:<3} tasks {:<12} cpu {:6.1f} s  bandwidth {:6.2f} Mbps  keyframe msgs {:5.2f} Hz  map msgs {:5.2f} Hz\n",
                 task, j.contains("tasks") ? j["tasks"].dump() : std::string("[\"tr\",\"lm\",\"lc\"]"), cpu,
                 j.value("bandwidth_mbps", 0.0), j.value("keyframe_msgs_hz", 0.0), j.value("map_msgs_hz", 0.0));
    }
    const auto& tr = r.reports.at("tr");
    if (tr.contains("ate"))
      fmt::print("ATE RMSE {:.4f} m ({:.3f}% of the path), tracked {} of {} frames\n", tr["ate"]["rmse"].get<double>(),
                 tr["ate"]["percent_of_path"].get<double>(), tr.value("tracked_frames", 0), tr.value("frames", 0));
  });
}

}  // namespace hiveslam::apps
