// The plots from the command line: `eval ate --plot-time --plot-axes` and `eval bench --plot`
// write images of the expected shape.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "temp_dir.hpp"

namespace {

int run(const std::string& args) { return std::system((std::string(HIVESLAM_BINARY) + " " + args + " > /dev/null 2>&1").c_str()); }

TEST(PlotCommands, EvalAteDrawsTheErrorOverTimeAndPerAxis) {
  hiveslam::testing::TempDir dir;
  std::ofstream gt(dir / "gt.tum"), est(dir / "est.tum");
  for (int i = 0; i < 100; ++i) {
    gt << i * 0.05 << " " << i * 0.02 << " 0 0 0 0 0 1\n";
    est << i * 0.05 << " " << i * 0.02 << " " << 0.0005 * (i % 7) << " 0 0 0 0 1\n";
  }
  gt.close();
  est.close();
  ASSERT_EQ(run("eval ate " + (dir / "gt.tum").string() + " " + (dir / "est.tum").string() + " --plot-time " +
                (dir / "t.png").string() + " --plot-axes " + (dir / "xyz.png").string()),
            0);
  const cv::Mat t = cv::imread((dir / "t.png").string()), xyz = cv::imread((dir / "xyz.png").string());
  EXPECT_FALSE(t.empty());
  EXPECT_EQ(xyz.rows, 3 * t.rows * 260 / 380);
}

TEST(PlotCommands, EvalBenchDrawsTheTableAsAFigure) {
  hiveslam::testing::TempDir dir;
  nlohmann::json rows = nlohmann::json::array();
  for (int nodes : {1, 3}) {
    nlohmann::json r{{"sequence", "loop"}, {"nodes", nodes}, {"ground_truth", true}};
    for (const char* key : {"ate", "ate_percent", "fails", "tracked", "cpu_seconds", "cpu_percent", "bw_tr", "bw_lm",
                            "bw_lc", "kf_hz", "map_hz", "loops", "maps", "merges", "maps_2kf", "deferred", "dropped"})
      r[key] = {{"median", 0.002 * nodes}, {"max", 0.003 * nodes}, {"runs", {0.002 * nodes, 0.003 * nodes}}};
    rows.push_back(r);
  }
  std::ofstream(dir / "bench.json") << rows.dump();
  ASSERT_EQ(run("eval bench " + (dir / "bench.json").string() + " --plot " + (dir / "bench.png").string()), 0);
  const cv::Mat png = cv::imread((dir / "bench.png").string());
  ASSERT_FALSE(png.empty());
  EXPECT_EQ(png.rows, 3 * 380);  // ATE, CPU and bandwidth
}

}  // namespace
