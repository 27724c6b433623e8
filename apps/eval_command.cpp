// hiveslam eval ate|rpe GT EST: trajectory errors with evo's rules, as a table or JSON.
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "eval/trajectory_error.hpp"
#include "eval/trajectory_plot.hpp"
#include "io/trajectory_io.hpp"

namespace hiveslam::apps {

namespace {

struct Common {
  std::string gt, est, gt_format, est_format, plot;
  double max_diff = 0.01;
  bool se3 = false, no_align = false, json = false;
};

void addCommon(CLI::App* cmd, Common& c) {
  cmd->add_option("GT", c.gt, "Ground-truth trajectory (TUM, EuRoC csv or KITTI)")->required();
  cmd->add_option("EST", c.est, "Estimated trajectory")->required();
  cmd->add_option("--gt-format", c.gt_format, "tum | euroc | kitti (default: detected)");
  cmd->add_option("--est-format", c.est_format, "tum | euroc | kitti (default: detected)");
  cmd->add_option("--max-diff", c.max_diff, "Largest stamp difference of a matched pair, s")->capture_default_str();
  cmd->add_flag("--se3", c.se3, "Align without scale (default: Sim3, for monocular)");
  cmd->add_flag("--no-align", c.no_align, "Compare without any alignment");
  cmd->add_flag("--json", c.json, "Print JSON instead of a table");
  cmd->add_option("--plot", c.plot, "Write a top-view PNG of the aligned estimate");
}

struct Loaded {
  io::Trajectory gt, est;
  eval::MatchOptions match;
};

Loaded load(const Common& c) {
  Loaded l;
  const auto gf = c.gt_format.empty() ? io::detectTrajectoryFormat(c.gt) : io::parseTrajectoryFormat(c.gt_format);
  const auto ef = c.est_format.empty() ? io::detectTrajectoryFormat(c.est) : io::parseTrajectoryFormat(c.est_format);
  l.gt = io::readTrajectory(c.gt, gf);
  l.est = io::readTrajectory(c.est, ef);
  l.match.max_diff = c.max_diff;
  l.match.by_index = gf == io::TrajectoryFormat::Kitti || ef == io::TrajectoryFormat::Kitti;
  l.match.alignment = c.no_align ? eval::Alignment::None : c.se3 ? eval::Alignment::SE3 : eval::Alignment::Sim3;
  return l;
}

void printStats(const std::string& title, const eval::ErrorStats& s, const std::string& unit) {
  fmt::print("{}\n", title);
  for (auto [name, v] : {std::pair{"max", s.max}, {"mean", s.mean}, {"median", s.median}, {"min", s.min},
                         {"rmse", s.rmse}, {"sse", s.sse}, {"std", s.std}})
    fmt::print("{:>10}  {:.6f} {}\n", name, v, unit);
  fmt::print("{:>10}  {}\n", "matched", s.count);
}

}  // namespace

void addEvalCommand(CLI::App& app) {
  auto* eval = app.add_subcommand("eval", "Evaluate a trajectory against ground truth");
  eval->require_subcommand(1);

  auto ate = std::make_shared<Common>();
  auto* ate_cmd = eval->add_subcommand("ate", "Absolute trajectory error (evo_ape -as equivalent)");
  addCommon(ate_cmd, *ate);
  ate_cmd->callback([ate]() {
    const Loaded l = load(*ate);
    const auto r = eval::computeAte(l.gt, l.est, l.match);
    if (!ate->plot.empty())
      eval::plotTopView(ate->plot, r.pair.ref, r.pair.est,
                        {fmt::format("ATE RMSE {:.4f} m ({} poses)", r.stats.rmse, r.stats.count), 900, {}});
    if (ate->json) {
      nlohmann::json j = eval::toJson(r.stats);
      j["alignment"] = eval::toString(l.match.alignment);
      j["scale"] = r.pair.alignment.scale;
      j["reference_length"] = r.reference_length;
      fmt::print("{}\n", j.dump(2));
      return;
    }
    printStats(fmt::format("ATE, translation part ({} alignment, scale {:.6f})", eval::toString(l.match.alignment),
                           r.pair.alignment.scale),
               r.stats, "m");
  });

  auto rpe = std::make_shared<Common>();
  auto delta = std::make_shared<double>(1.0);
  auto unit = std::make_shared<std::string>("frames");
  auto rotation = std::make_shared<bool>(false);
  auto all_pairs = std::make_shared<bool>(false);
  auto* rpe_cmd = eval->add_subcommand("rpe", "Relative pose error (evo_rpe equivalent)");
  addCommon(rpe_cmd, *rpe);
  rpe_cmd->add_option("--delta", *delta, "Distance between the poses of a pair")->capture_default_str();
  rpe_cmd->add_option("--unit", *unit, "frames | m")->capture_default_str()->check(CLI::IsMember({"frames", "m"}));
  rpe_cmd->add_flag("--rotation", *rotation, "Rotation angle error in degrees instead of translation");
  rpe_cmd->add_flag("--all-pairs", *all_pairs, "Use all pairs instead of consecutive ones");
  rpe_cmd->callback([=]() {
    const Loaded l = load(*rpe);
    eval::RpeOptions o;
    o.match = l.match;
    o.delta = *delta;
    o.unit = *unit == "m" ? eval::DeltaUnit::Meters : eval::DeltaUnit::Frames;
    o.relation = *rotation ? eval::RpeRelation::RotationDeg : eval::RpeRelation::Translation;
    o.all_pairs = *all_pairs;
    const auto r = eval::computeRpe(l.gt, l.est, o);
    if (rpe->json) {
      nlohmann::json j = eval::toJson(r.stats);
      j["pairs"] = r.pairs.size();
      fmt::print("{}\n", j.dump(2));
      return;
    }
    printStats(fmt::format("RPE, {} part, delta {} {}", *rotation ? "rotation" : "translation", *delta, *unit),
               r.stats, *rotation ? "deg" : "m");
  });
}

}  // namespace hiveslam::apps
