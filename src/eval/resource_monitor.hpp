#pragma once
// What a node measures about itself: CPU time of this process (from /proc/self/stat), peak
// resident memory (VmHWM), wall time since start, and bytes/messages per named channel in
// both directions. Channel counting is thread-safe and cheap (one mutex per message).
#include <chrono>
#include <map>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <string>

namespace hiveslam::eval {

struct ChannelCount {
  uint64_t bytes_in = 0, bytes_out = 0, messages_in = 0, messages_out = 0;
};

class ResourceMonitor {
 public:
  ResourceMonitor();

  // User + system CPU seconds of the whole process since it started.
  static double processCpuSeconds();
  // Peak resident set size of the process, bytes.
  static uint64_t peakRssBytes();
  // CPU seconds of the threads alive now, summed per thread name (threads that already
  // ended are not in it): where a process spends its time.
  static std::map<std::string, double> threadCpuSeconds();

  double wallSeconds() const;
  double cpuSeconds() const;  // since this monitor was made
  // CPU time over wall time since construction, in percent of one core.
  double cpuPercent() const;

  void countIn(const std::string& channel, uint64_t bytes);
  void countOut(const std::string& channel, uint64_t bytes);
  std::map<std::string, ChannelCount> channels() const;

  // {"cpu_seconds", "wall_seconds", "cpu_percent", "peak_rss_mb", "bytes_in", "bytes_out",
  //  "messages_in", "messages_out", "channels": {name: {..., "mbps_in", "mbps_out",
  //  "hz_in", "hz_out"}}}
  nlohmann::json report() const;

 private:
  std::chrono::steady_clock::time_point start_;
  double cpu_start_;
  mutable std::mutex mutex_;
  std::map<std::string, ChannelCount> channels_;
};

}  // namespace hiveslam::eval
