#include "eval/bench_rules.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hiveslam::eval {
namespace {

// Five runs per configuration, ATE in metres, the shape of a bench row.
SequenceRuns sequence(std::vector<double> ate1, std::vector<double> ate3, std::vector<double> cpu1 = {20, 20, 20, 20, 20},
                      std::vector<double> cpu3 = {10, 10, 10, 10, 10}, std::vector<double> bw3 = {3, 3, 3, 3, 3}) {
  SequenceRuns s;
  s.sequence = "seq";
  s.one_node = {std::move(ate1), std::move(cpu1), {0, 0, 0, 0, 0}};
  s.three_nodes = {std::move(ate3), std::move(cpu3), std::move(bw3)};
  return s;
}

const RuleCheck& find(const std::vector<RuleCheck>& checks, const std::string& prefix) {
  for (const auto& c : checks)
    if (c.rule.rfind(prefix, 0) == 0) return c;
  throw std::runtime_error("no rule " + prefix);
}

TEST(BenchRules, ABenchWithinEveryRuleHoldsThemAll) {
  const auto checks = checkBenchRules({sequence({.006, .005, .007, .006, .006}, {.007, .006, .008, .007, .007})});
  ASSERT_EQ(checks.size(), 5u);
  for (const auto& c : checks) EXPECT_TRUE(c.holds) << c.rule << " " << c.value << "/" << c.limit;
  EXPECT_NEAR(find(checks, "median").value, 1.0, 1e-9);  // mm
  EXPECT_NEAR(find(checks, "median").limit, 5.0, 1e-9);  // 10% of 6 mm is below the 5 mm floor
  EXPECT_NEAR(find(checks, "outliers 1-node").value, 7.0 / 6.0, 1e-9);
  EXPECT_NEAR(find(checks, "outliers 3-node").value, 8.0 / 7.0, 1e-9);
  EXPECT_NEAR(find(checks, "TR CPU").value, 0.5, 1e-9);
  EXPECT_NEAR(find(checks, "TR bandwidth").value, 3.0, 1e-9);
}

TEST(BenchRules, ASequenceWithoutGroundTruthIsJudgedOnCpuAndBandwidthOnly) {
  SequenceRuns s = sequence({-1, -1, -1, -1, -1}, {-1, -1, -1, -1, -1});
  s.ground_truth = false;
  const auto checks = checkBenchRules({s});
  ASSERT_EQ(checks.size(), 2u);
  EXPECT_TRUE(find(checks, "TR CPU").holds);
  EXPECT_TRUE(find(checks, "TR bandwidth").holds);
}

TEST(BenchRules, OneRunAboveOneAndAHalfTimesTheMedianFailsItsConfigurationOnly) {
  const auto checks = checkBenchRules({sequence({.006, .006, .006, .006, .006}, {.006, .006, .006, .006, .0091})});
  EXPECT_TRUE(find(checks, "outliers 1-node").holds);
  EXPECT_FALSE(find(checks, "outliers 3-node").holds);
  EXPECT_NEAR(find(checks, "outliers 3-node").value, 9.1 / 6.0, 1e-9);
  EXPECT_TRUE(find(checks, "median").holds);
}

TEST(BenchRules, TheMedianAllowanceIsTenPercentAboveFiftyMillimetres) {
  // 1-node median 80 mm: the allowance is 8 mm, so +7 holds and +9 fails.
  EXPECT_TRUE(find(checkBenchRules({sequence({.08, .08, .08, .08, .08}, {.087, .087, .087, .087, .087})}), "median").holds);
  const auto fail = checkBenchRules({sequence({.08, .08, .08, .08, .08}, {.089, .089, .089, .089, .089})});
  EXPECT_FALSE(find(fail, "median").holds);
  EXPECT_NEAR(find(fail, "median").limit, 8.0, 1e-9);
  // A 3-node median below the 1-node one is no regression, however far below.
  EXPECT_TRUE(find(checkBenchRules({sequence({.08, .08, .08, .08, .08}, {.01, .01, .01, .01, .01})}), "median").holds);
}

TEST(BenchRules, CpuAndBandwidthLimits) {
  const auto checks = checkBenchRules(
      {sequence({.006, .006, .006, .006, .006}, {.006, .006, .006, .006, .006}, {20, 20, 20, 20, 20},
                {13, 13, 13, 13, 13}, {3, 3, 5, 3, 3})});
  EXPECT_FALSE(find(checks, "TR CPU").holds);  // 65% of the 1-node TR's
  EXPECT_FALSE(find(checks, "TR bandwidth").holds);  // one run at 5 Mbps: the rule is "below"
}

TEST(BenchRules, ARunWithoutATrajectoryIsAnOutlier) {
  const auto checks = checkBenchRules({sequence({.006, .006, .006, .006, .006}, {.006, .006, -1, .006, .006})});
  EXPECT_FALSE(find(checks, "outliers 3-node").holds);
}

TEST(BenchRules, ASequenceRunInOneConfigurationOnlyIsNotJudged) {
  auto s = sequence({.006, .006, .006, .006, .006}, {});
  EXPECT_TRUE(checkBenchRules({s}).empty());
  EXPECT_EQ(ruleTable({}), "rule (value/limit)            \n");
}

TEST(BenchRules, TheTableSaysOkOrFailPerSequence) {
  auto a = sequence({.006, .006, .006, .006, .006}, {.006, .006, .006, .006, .006});
  auto b = sequence({.006, .006, .006, .006, .006}, {.006, .006, .006, .006, .010});
  a.sequence = "alpha";
  b.sequence = "beta";
  const std::string t = ruleTable(checkBenchRules({a, b}));
  EXPECT_NE(t.find("alpha"), std::string::npos);
  EXPECT_NE(t.find("beta"), std::string::npos);
  EXPECT_NE(t.find("1.67/1.50 FAIL"), std::string::npos) << t;
  EXPECT_NE(t.find("1.00/1.50 ok"), std::string::npos) << t;
}

// Each pair is run i of one configuration against run i of the other: 12/20, 9/15, 12/20, 9/15
// and 11/20 give 0.55-0.60 (the rule itself takes the medians, 11/20).
TEST(BenchRules, ThePairedCpuLineGivesTheRangeOfThePairsRatios) {
  auto a = sequence({.006, .006, .006, .006, .006}, {.006, .006, .006, .006, .006}, {20, 15, 20, 15, 20},
                    {12, 9, 12, 9, 11});
  auto b = sequence({.006, .006}, {.006, .006}, {10, 10}, {5, 6});
  a.sequence = "alpha";
  b.sequence = "beta";
  const std::string line = pairedCpuLine({a, b});
  EXPECT_NE(line.find("0.55-0.60"), std::string::npos) << line;
  EXPECT_NE(line.find("0.50-0.60"), std::string::npos) << line;
  // In the rule table's columns: a 30-character label, then 18 characters per sequence.
  EXPECT_EQ(line.find("0.55-0.60") + 9, 30u + 18u) << line;
  EXPECT_EQ(line.find("0.50-0.60") + 9, 30u + 36u) << line;
  EXPECT_EQ(pairedCpuLine({}), "");
}

}  // namespace
}  // namespace hiveslam::eval
