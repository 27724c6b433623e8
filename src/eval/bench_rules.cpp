#include "eval/bench_rules.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <map>

#include "eval/error_stats.hpp"

namespace hiveslam::eval {

namespace {

// A run without a trajectory to score (the bench records -1) is as bad as a run can be.
std::vector<double> scored(const std::vector<double>& ate_m) {
  std::vector<double> out;
  for (double a : ate_m) out.push_back(a < 0 ? std::numeric_limits<double>::infinity() : a);
  return out;
}

}  // namespace

std::vector<RuleCheck> checkBenchRules(const std::vector<SequenceRuns>& sequences, const BenchRules& rules) {
  std::vector<RuleCheck> out;
  for (const auto& s : sequences) {
    const ConfigRuns &one = s.one_node, &three = s.three_nodes;
    if (one.ate_m.empty() || three.ate_m.empty()) continue;
    if (s.ground_truth) {
      const ErrorStats ate1 = summarize(scored(one.ate_m)), ate3 = summarize(scored(three.ate_m));
      const double allowance = std::max(rules.median_ratio * ate1.median, rules.median_floor_m);
      out.push_back({s.sequence, "median 3-node - 1-node, mm", 1e3 * (ate3.median - ate1.median), 1e3 * allowance,
                     ate3.median - ate1.median <= allowance});
      for (const auto& [name, ate] : {std::pair{"outliers 1-node, max/median", ate1}, {"outliers 3-node, max/median", ate3}}) {
        const double ratio = ate.median > 0 ? ate.max / ate.median : std::numeric_limits<double>::infinity();
        out.push_back({s.sequence, name, ratio, rules.outlier_ratio, ratio <= rules.outlier_ratio});
      }
    }
    const double cpu1 = summarize(one.tr_cpu_seconds).median, cpu3 = summarize(three.tr_cpu_seconds).median;
    const double cpu = cpu1 > 0 ? cpu3 / cpu1 : std::numeric_limits<double>::infinity();
    out.push_back({s.sequence, "TR CPU 3-node/1-node", cpu, rules.cpu_ratio, cpu <= rules.cpu_ratio});
    const double bw = summarize(three.tr_mbps).max;
    out.push_back({s.sequence, "TR bandwidth 3-node max, Mbps", bw, rules.tr_mbps, bw < rules.tr_mbps});
  }
  return out;
}

std::string ruleTable(const std::vector<RuleCheck>& checks) {
  std::vector<std::string> sequences, rules;
  std::map<std::pair<std::string, std::string>, const RuleCheck*> cell;
  for (const auto& c : checks) {
    if (std::find(sequences.begin(), sequences.end(), c.sequence) == sequences.end()) sequences.push_back(c.sequence);
    if (std::find(rules.begin(), rules.end(), c.rule) == rules.end()) rules.push_back(c.rule);
    cell[{c.rule, c.sequence}] = &c;
  }
  std::string t = fmt::format("{:<30}", "rule (value/limit)");
  for (const auto& s : sequences) t += fmt::format(" {:>17}", s);
  t += "\n";
  for (const auto& r : rules) {
    t += fmt::format("{:<30}", r);
    for (const auto& s : sequences) {
      const auto it = cell.find({r, s});
      t += it == cell.end() ? fmt::format(" {:>17}", "-")
                            : fmt::format(" {:>17}", fmt::format("{:.2f}/{:.2f} {}", it->second->value, it->second->limit,
                                                                   it->second->holds ? "ok" : "FAIL"));
    }
    t += "\n";
  }
  return t;
}

std::string pairedCpuLine(const std::vector<SequenceRuns>& sequences) {
  std::string t = fmt::format("{:<30}", "TR CPU per pair, min-max");
  bool any = false;
  for (const auto& s : sequences) {
    const auto &cpu1 = s.one_node.tr_cpu_seconds, &cpu3 = s.three_nodes.tr_cpu_seconds;
    if (s.one_node.ate_m.empty() || s.three_nodes.ate_m.empty()) continue;  // as checkBenchRules
    std::vector<double> ratios;
    for (size_t i = 0; i < std::min(cpu1.size(), cpu3.size()); ++i)
      if (cpu1[i] > 0) ratios.push_back(cpu3[i] / cpu1[i]);
    const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
    t += ratios.empty() ? fmt::format(" {:>17}", "-") : fmt::format(" {:>17}", fmt::format("{:.2f}-{:.2f}", *lo, *hi));
    any = true;
  }
  return any ? t + "\n" : "";
}

}  // namespace hiveslam::eval
