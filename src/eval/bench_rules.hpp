#pragma once
// The acceptance rules of the distributed system (issue 5), read off a bench's runs: for each
// sequence run in the 1-node and the 3-node configuration,
//   median:   the 3-node median ATE at most 10% (or 5 mm, the larger) above the 1-node one;
//   outliers: in each configuration, no run above 1.5x that configuration's median ATE;
//   TR CPU:   the 3-node TR's median CPU time at most 60% of the 1-node TR's;
//   TR BW:    every 3-node run's TR bandwidth below 5 Mbps.
// The bench prints them after its table, so that a run of the protocol says which hold
// instead of leaving it to arithmetic by hand. The median rule is one-sided: a 3-node median
// below the 1-node one is not a regression.
#include <string>
#include <vector>

namespace hiveslam::eval {

struct BenchRules {
  double median_ratio = 0.10;       // of the 1-node median
  double median_floor_m = 0.005;    // the allowance when 10% is smaller
  double outlier_ratio = 1.5;       // max over runs / median
  double cpu_ratio = 0.60;          // 3-node TR CPU / 1-node TR CPU (medians)
  double tr_mbps = 5.0;             // TR bandwidth, every 3-node run
};

// One configuration's runs of one sequence.
struct ConfigRuns {
  std::vector<double> ate_m, tr_cpu_seconds, tr_mbps;
};

struct SequenceRuns {
  std::string sequence;
  ConfigRuns one_node, three_nodes;
  bool ground_truth = true;  // without it only the CPU and bandwidth rules apply
};

struct RuleCheck {
  std::string sequence, rule;
  double value = 0.0, limit = 0.0;  // in the rule's own unit (mm, ratio, Mbps)
  bool holds = false;
};

// Sequences missing either configuration, or with a configuration that has no runs, give no
// checks.
std::vector<RuleCheck> checkBenchRules(const std::vector<SequenceRuns>& sequences, const BenchRules& rules = {});

// A rule per line, a sequence per column: "value/limit ok" or "value/limit FAIL".
std::string ruleTable(const std::vector<RuleCheck>& checks);

// Not a rule: the TR CPU ratio of each interleaved pair (run i of each configuration, made one
// after the other), as "min-max" per sequence, in the rule table's columns. A pair shares the
// machine's speed of the moment, which drifts by 15% and more between runs: the spread of the
// pairs says how far a bench's ratio of medians is the machine's.
std::string pairedCpuLine(const std::vector<SequenceRuns>& sequences);

}  // namespace hiveslam::eval
