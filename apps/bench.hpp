#pragma once
// The paper's benchmark protocol (hiveslam bench), also behind the demo.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace hiveslam::apps {

struct BenchOptions {
  // Datasets, each optionally followed by ":SETTINGS.yaml", its own settings (the camera of a
  // real sequence, its feature budget); the others take `config`.
  std::vector<std::string> sequences;
  std::string out, config;
  int repeats = 1;
  std::vector<int> nodes{1, 3};
  bool realtime = true;
  bool feed_topic = false;  // TR reads a played image topic instead of the files
};

struct BenchRow {
  std::string sequence;
  int nodes = 1;
  bool ground_truth = true;  // false: the ATE columns stay empty
  std::vector<double> ate, ate_percent, fails, tracked, cpu_seconds, cpu_percent, bw_tr, bw_lm, bw_lc, kf_hz, map_hz,
      loops, maps;
  // What a sequence without ground truth still tells: merges, maps of two keyframes or more at
  // the end, keyframes deferred and frames dropped (each as a percentage of the frames).
  std::vector<double> merges, maps_2kf, deferred, dropped;
  nlohmann::json toJson() const;
};

nlohmann::json runBench(const BenchOptions& options);
// "PATH[:SETTINGS]" split into the dataset and its settings file (empty: none given).
std::pair<std::string, std::string> splitSequence(const std::string& arg);
std::string benchTable(const nlohmann::json& rows);
// The table as a figure (bench.png): ATE, CPU and bandwidth at TR per sequence and node count.
void plotBench(const std::filesystem::path& png, const nlohmann::json& rows);
// Which of issue 5's acceptance rules the rows' 1-node and 3-node runs hold; empty without both.
std::string benchRules(const nlohmann::json& rows);

}  // namespace hiveslam::apps
