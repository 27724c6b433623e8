#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "eval/resource_monitor.hpp"

namespace hiveslam::eval {
namespace {

TEST(ResourceMonitor, MeasuresCpuTimeOfBusyWork) {
  ResourceMonitor monitor;
  volatile double sink = 0;
  const double start = monitor.cpuSeconds();
  while (monitor.cpuSeconds() - start < 0.05)
    for (int i = 0; i < 100000; ++i) sink = sink + i * 1e-9;
  EXPECT_GE(monitor.cpuSeconds(), 0.05);
  EXPECT_GT(monitor.cpuPercent(), 0.0);
  EXPECT_GT(ResourceMonitor::peakRssBytes(), 1u << 20);
}

TEST(ResourceMonitor, CountsChannelsFromManyThreads) {
  ResourceMonitor monitor;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 1000; ++i) {
        monitor.countOut("rt/hiveslam/keyframes", 100);
        monitor.countIn("rt/hiveslam/local_map", 10);
      }
    });
  for (auto& t : threads) t.join();
  const auto c = monitor.channels();
  EXPECT_EQ(c.at("rt/hiveslam/keyframes").bytes_out, 400000u);
  EXPECT_EQ(c.at("rt/hiveslam/keyframes").messages_out, 4000u);
  EXPECT_EQ(c.at("rt/hiveslam/local_map").bytes_in, 40000u);
  const nlohmann::json j = monitor.report();
  EXPECT_EQ(j["bytes_out"].get<uint64_t>(), 400000u);
  EXPECT_EQ(j["messages_in"].get<uint64_t>(), 4000u);
  EXPECT_GT(j["channels"]["rt/hiveslam/keyframes"]["mbps_out"].get<double>(), 0.0);
  for (const char* key : {"cpu_seconds", "wall_seconds", "cpu_percent", "peak_rss_mb"}) EXPECT_TRUE(j.contains(key)) << key;
}

}  // namespace
}  // namespace hiveslam::eval
