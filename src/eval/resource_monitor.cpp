#include "eval/resource_monitor.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace hiveslam::eval {

ResourceMonitor::ResourceMonitor()
    : start_(std::chrono::steady_clock::now()), cpu_start_(processCpuSeconds()) {}

namespace {

// utime + stime of a /proc stat file, in seconds.
double statCpuSeconds(const std::string& path) {
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The command name (field 2) may hold spaces: parse after its closing parenthesis.
  const size_t close = text.rfind(')');
  if (close == std::string::npos) return 0.0;
  std::istringstream rest(text.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

}  // namespace

double ResourceMonitor::processCpuSeconds() { return statCpuSeconds("/proc/self/stat"); }

std::map<std::string, double> ResourceMonitor::threadCpuSeconds() {
  std::map<std::string, double> per_name;
  std::error_code ec;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    std::ifstream comm(task.path() / "comm");
    std::string name;
    if (!std::getline(comm, name)) continue;
    per_name[name] += statCpuSeconds(task.path() / "stat");
  }
  return per_name;
}

uint64_t ResourceMonitor::peakRssBytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  return 0;
}

double ResourceMonitor::wallSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double ResourceMonitor::cpuSeconds() const { return processCpuSeconds() - cpu_start_; }

double ResourceMonitor::cpuPercent() const {
  const double wall = wallSeconds();
  return wall > 0 ? 100.0 * cpuSeconds() / wall : 0.0;
}

void ResourceMonitor::countIn(const std::string& channel, uint64_t bytes) {
  std::lock_guard lock(mutex_);
  auto& c = channels_[channel];
  c.bytes_in += bytes;
  ++c.messages_in;
}

void ResourceMonitor::countOut(const std::string& channel, uint64_t bytes) {
  std::lock_guard lock(mutex_);
  auto& c = channels_[channel];
  c.bytes_out += bytes;
  ++c.messages_out;
}

std::map<std::string, ChannelCount> ResourceMonitor::channels() const {
  std::lock_guard lock(mutex_);
  return channels_;
}

nlohmann::json ResourceMonitor::report() const {
  const double wall = std::max(wallSeconds(), 1e-9);
  nlohmann::json j;
  j["cpu_seconds"] = cpuSeconds();
  j["wall_seconds"] = wall;
  j["cpu_percent"] = cpuPercent();
  j["peak_rss_mb"] = static_cast<double>(peakRssBytes()) / (1024.0 * 1024.0);
  ChannelCount total;
  nlohmann::json per = nlohmann::json::object();
  for (const auto& [name, c] : channels()) {
    total.bytes_in += c.bytes_in;
    total.bytes_out += c.bytes_out;
    total.messages_in += c.messages_in;
    total.messages_out += c.messages_out;
    per[name] = {{"bytes_in", c.bytes_in},
                 {"bytes_out", c.bytes_out},
                 {"messages_in", c.messages_in},
                 {"messages_out", c.messages_out},
                 {"mbps_in", 8e-6 * static_cast<double>(c.bytes_in) / wall},
                 {"mbps_out", 8e-6 * static_cast<double>(c.bytes_out) / wall},
                 {"hz_in", static_cast<double>(c.messages_in) / wall},
                 {"hz_out", static_cast<double>(c.messages_out) / wall}};
  }
  j["bytes_in"] = total.bytes_in;
  j["bytes_out"] = total.bytes_out;
  j["messages_in"] = total.messages_in;
  j["messages_out"] = total.messages_out;
  j["channels"] = per;
  return j;
}

}  // namespace hiveslam::eval
