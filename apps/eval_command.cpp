// hiveslam eval ate|rpe GT EST: trajectory errors with evo's rules, as a table or JSON.
// hiveslam eval scale-step GT EST and scale-precision ATLAS: a monocular run's scale step
// between two stretches, and how precisely the map's own measurements could fix it.
// hiveslam eval bench DIR/bench.json: a saved bench's table and acceptance rules, again.
// hiveslam eval remeasure ATLAS DATASET: a saved map on patch-aligned observations (eval_remeasure).
// hiveslam eval lens ATLAS CAMERA: the lens a saved map was seen with (eval_lens).
// hiveslam eval matches DATASET: data association against a render's scene (eval_matches).
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

#include "apps/bench.hpp"
#include "apps/commands.hpp"
#include "apps/eval_matches.hpp"
#include "apps/eval_lens.hpp"
#include "apps/eval_remeasure.hpp"
#include "common/error.hpp"
#include "eval/scale_precision.hpp"
#include "eval/scale_step.hpp"
#include "eval/stretch_errors.hpp"
#include "eval/trajectory_error.hpp"
#include "eval/error_plots.hpp"
#include "eval/trajectory_plot.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/optim/map_ba_problem.hpp"
#include "io/atlas_file.hpp"
#include "io/slam_settings_io.hpp"
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

void addSplit(CLI::App* cmd, eval::StretchSplit& split) {
  cmd->add_option("--before", split.before, "First stretch: up to this many seconds into the run")->required();
  cmd->add_option("--after", split.after, "Second stretch: from this many seconds into the run")->required();
  cmd->add_option("--first-from", split.first_from, "First stretch: from this many seconds into the run (default: the start)");
  cmd->add_option("--second-until", split.second_until, "Second stretch: up to this many seconds into the run (default: the end)");
}

// The map with the most keyframes, or the one asked for.
std::shared_ptr<core::Map> pickMap(const std::vector<std::shared_ptr<core::Map>>& maps, long id) {
  std::shared_ptr<core::Map> best;
  for (const auto& m : maps)
    if (id >= 0 ? static_cast<long>(m->id) == id : !best || m->keyframes.size() > best->keyframes.size()) best = m;
  if (!best) throw InputError(id >= 0 ? fmt::format("the atlas has no map {}", id) : "the atlas has no map");
  return best;
}

}  // namespace

void addEvalCommand(CLI::App& app) {
  auto* eval = app.add_subcommand("eval", "Evaluate a trajectory against ground truth");
  eval->footer("Example:\n  hiveslam eval ate seq/figure8/mav0/state_groundtruth_estimate0/data.csv out/figure8/trajectory.tum");
  eval->require_subcommand(1);

  auto ate = std::make_shared<Common>();
  auto* ate_cmd = eval->add_subcommand("ate", "Absolute trajectory error (evo_ape -as equivalent)");
  ate_cmd->footer("Example:\n  hiveslam eval ate seq/figure8/mav0/state_groundtruth_estimate0/data.csv out/figure8/trajectory.tum --stretches 10");
  addCommon(ate_cmd, *ate);
  auto plots = std::make_shared<std::pair<std::string, std::string>>();
  ate_cmd->add_option("--plot-time", plots->first, "Write a PNG of the position error over time");
  ate_cmd->add_option("--plot-axes", plots->second, "Write a PNG of the error along x, y and z over time");
  auto stretches = std::make_shared<int>(0);
  ate_cmd->add_option("--stretches", *stretches,
                      "Also cut the run into N equal stretches of time: each one's mean error, own Sim3 scale and turn")
      ->check(CLI::Range(1, 1000));
  ate_cmd->callback([ate, stretches, plots]() {
    const Loaded l = load(*ate);
    const auto r = eval::computeAte(l.gt, l.est, l.match);
    const std::string title = fmt::format("ATE RMSE {:.4f} m ({} poses)", r.stats.rmse, r.stats.count);
    if (!ate->plot.empty()) eval::plotTopView(ate->plot, r.pair.ref, r.pair.est, {title, 900, {}});
    if (!plots->first.empty()) eval::plotErrorOverTime(plots->first, r, title);
    if (!plots->second.empty()) eval::plotAxisErrors(plots->second, r, title);
    if (ate->json) {
      nlohmann::json j = eval::toJson(r.stats);
      j["alignment"] = eval::toString(l.match.alignment);
      j["scale"] = r.pair.alignment.scale;
      j["reference_length"] = r.reference_length;
      if (*stretches > 0) {
        j["stretches"] = nlohmann::json::array();
        for (const auto& s : eval::stretchErrors(r, *stretches))
          j["stretches"].push_back({{"from", s.from}, {"to", s.to}, {"poses", s.poses}, {"mean_error", s.mean_error},
                                    {"scale", s.scale}, {"turn_deg", s.turn}, {"turn_estimate_deg", s.turn_estimate},
                                    {"turn_error_deg", s.turn_error}});
      }
      fmt::print("{}\n", j.dump(2));
      return;
    }
    printStats(fmt::format("ATE, translation part ({} alignment, scale {:.6f})", eval::toString(l.match.alignment),
                           r.pair.alignment.scale),
               r.stats, "m");
    if (*stretches > 0) {
      fmt::print("{:>16}  {:>6}  {:>12}  {:>12}  {:>22}\n", "stretch (s)", "poses", "mean error", "own scale",
                 "turn, deg: true / est / err");
      for (const auto& s : eval::stretchErrors(r, *stretches))
        fmt::print("{:>7.1f} - {:>6.1f}  {:>6}  {:>10.4f} m  {:>12.4f}  {:>8.2f} {:>6.2f} {:>6.2f}\n", s.from, s.to,
                   s.poses, s.mean_error, s.scale, s.turn, s.turn_estimate, s.turn_error);
    }
  });

  auto rpe = std::make_shared<Common>();
  auto delta = std::make_shared<double>(1.0);
  auto unit = std::make_shared<std::string>("frames");
  auto rotation = std::make_shared<bool>(false);
  auto all_pairs = std::make_shared<bool>(false);
  auto* rpe_cmd = eval->add_subcommand("rpe", "Relative pose error (evo_rpe equivalent)");
  rpe_cmd->footer("Example:\n  hiveslam eval rpe GT.tum out/figure8/trajectory.tum --delta 1 --unit m");
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

  auto step = std::make_shared<Common>();
  auto step_split = std::make_shared<eval::StretchSplit>();
  auto* step_cmd = eval->add_subcommand("scale-step", "Scale of a later stretch of the run relative to an earlier one");
  step_cmd->footer("Example:\n  hiveslam eval scale-step GT.tum out/sweep/trajectory.tum --before 16 --after 24");
  addCommon(step_cmd, *step);
  addSplit(step_cmd, *step_split);
  step_cmd->callback([=]() {
    const Loaded l = load(*step);
    const auto r = eval::computeScaleStep(l.gt, l.est, *step_split, l.match);
    if (step->json) {
      nlohmann::json j{{"step", r.step()}, {"first_scale", r.first_scale}, {"second_scale", r.second_scale},
                       {"first_poses", r.first_poses}, {"second_poses", r.second_poses}};
      fmt::print("{}\n", j.dump(2));
      return;
    }
    fmt::print("scale step {:.4f}: stretch up to {} s at {:.4f} of true size ({} poses), from {} s at {:.4f} ({} poses)\n",
               r.step(), step_split->before, r.first_scale, r.first_poses, step_split->after, r.second_scale,
               r.second_poses);
  });

  auto precision = std::make_shared<eval::ScalePrecisionOptions>();
  auto atlas = std::make_shared<std::string>();
  auto map_id = std::make_shared<long>(-1);
  auto* precision_cmd = eval->add_subcommand(
      "scale-precision", "How precisely a saved map's measurements fix the scale step between two stretches");
  precision_cmd->footer("Example:\n  hiveslam eval scale-precision out/sweep/atlas.bin --before 16 --after 24");
  precision_cmd->add_option("ATLAS", *atlas, "Atlas file (hiveslam run --atlas-out)")->required();
  addSplit(precision_cmd, precision->split);
  precision_cmd->add_option("--map", *map_id, "Map id (default: the one with the most keyframes)");
  precision_cmd->add_option("--noise", precision->noise, "Noise per coordinate in level sigmas (default: the map's residuals)");
  precision_cmd->add_option("--trials", precision->trials, "Noise draws, each a full bundle adjustment")
      ->capture_default_str()->check(CLI::Range(2, 1000));
  precision_cmd->callback([=]() {
    const auto map = pickMap(io::loadAtlas(*atlas), *map_id);
    // The atlas keeps keypoint levels, not the pyramid's factor: the default pyramid's scales.
    const features::OrbExtractor pyramid;
    std::lock_guard lock(map->mutex);
    const core::MapBaProblem whole = core::buildMapBaProblem(*map, pyramid.scales());
    std::vector<double> stamps;
    for (const core::KeyFrame* k : whole.keyframes) stamps.push_back(k->frame.timestamp);
    const auto r = eval::computeScalePrecision(whole.problem, stamps, *precision);
    fmt::print("map {}: {} keyframes ({} and {} in the stretches), {} points, {} observations\n", map->id,
               r.keyframes, r.first_keyframes, r.second_keyframes, r.points, r.observations);
    fmt::print("residual noise {:.3f} sigma per coordinate; {} trials at {:.3f} sigma\n", r.residual_noise, r.steps.size(),
               r.noise);
    fmt::print("scale step: mean {:.4f}, sd {:.4f} ({:.2f}%)\n", r.mean, r.sd, 100.0 * r.sd);
  });

  auto remeasure_atlas = std::make_shared<std::string>(), remeasure_dataset = std::make_shared<std::string>();
  auto remeasure_split = std::make_shared<eval::StretchSplit>();
  auto remeasure_map = std::make_shared<long>(-1);
  auto* remeasure_cmd = eval->add_subcommand(
      "remeasure", "A saved map bundle-adjusted on its corners and on patch-aligned observations, against ground truth");
  remeasure_cmd->footer("Example:\n  hiveslam eval remeasure out/sweep/atlas.bin seq/sweep --before 16 --after 24");
  remeasure_cmd->add_option("ATLAS", *remeasure_atlas, "Atlas file (hiveslam run --atlas-out)")->required();
  remeasure_cmd->add_option("DATASET", *remeasure_dataset, "The dataset the map was made from (its images and ground truth)")
      ->required();
  addSplit(remeasure_cmd, *remeasure_split);
  remeasure_cmd->add_option("--map", *remeasure_map, "Map id (default: the one with the most keyframes)");
  auto remeasure_leave_out = std::make_shared<std::vector<std::string>>();
  remeasure_cmd->add_option("--leave-out", *remeasure_leave_out,
                            "FROM:TO, seconds from the first keyframe: solve again without those keyframes (repeatable)");
  remeasure_cmd->callback([=]() {
    std::vector<std::pair<double, double>> windows;
    for (const std::string& w : *remeasure_leave_out) {
      double from = 0, to = 0;
      char colon = 0;
      std::istringstream in(w);
      if (!(in >> from >> colon >> to) || colon != ':' || to < from || !(in >> std::ws).eof())
        throw InputError("--leave-out takes FROM:TO in seconds, not '" + w + "'");
      windows.emplace_back(from, to);
    }
    evalRemeasure(pickMap(io::loadAtlas(*remeasure_atlas), *remeasure_map), *remeasure_dataset, *remeasure_split, windows);
  });

  auto lens_atlas = std::make_shared<std::string>(), lens_camera = std::make_shared<std::string>(),
       lens_dataset = std::make_shared<std::string>(), lens_write = std::make_shared<std::string>();
  auto lens_map = std::make_shared<long>(-1);
  auto* lens_cmd = eval->add_subcommand(
      "lens", "The lens a saved map was seen with: the given calibration refined against the map's own keypoints");
  lens_cmd->footer("Example:\n  hiveslam eval lens out/handheld4/atlas.bin seq/handheld4/mav0/cam0/sensor.yaml --rendered seq/handheld4");
  lens_cmd->add_option("ATLAS", *lens_atlas, "Atlas file (hiveslam run --atlas-out)")->required();
  lens_cmd->add_option("CAMERA", *lens_camera, "The calibration the run was given (settings YAML, sensor.yaml or calib.txt)")
      ->required();
  lens_cmd->add_option("--rendered", *lens_dataset, "A sequence hiveslam synth wrote: print the lens its images were made with");
  lens_cmd->add_option("--map", *lens_map, "Map id (default: the one with the most keyframes)");
  lens_cmd->add_option("--write", *lens_write, "Write the refined lens as a settings file's camera section (for run --config)");
  lens_cmd->callback([=]() {
    evalLens(pickMap(io::loadAtlas(*lens_atlas), *lens_map), *lens_camera, *lens_dataset, *lens_write);
  });

  auto matches_dataset = std::make_shared<std::string>(), matches_config = std::make_shared<std::string>();
  auto matches_options = std::make_shared<MatchesOptions>();
  auto* matches_cmd = eval->add_subcommand(
      "matches", "A rendered sequence run again (sequential) with its scene as the judge of every new point and tracked match");
  matches_cmd->footer("Example:\n  hiveslam eval matches seq/handheld1 --frames 300 --sharp");
  matches_cmd->add_option("DATASET", *matches_dataset, "A sequence written by hiveslam synth (its sequence.json)")->required();
  matches_cmd->add_option("--frames", matches_options->frames, "Only the first N frames")->check(CLI::Range(1, 1000000));
  matches_cmd->add_flag("--true-lens", matches_options->true_lens,
                         "Give the SLAM the calibration the images were rendered with (a realistic render's nominal one is off)");
  matches_cmd->add_flag("--oracle", matches_options->oracle,
                        "Erase each new point that joins two scene points before its local BA (triangulation's pairs all right)");
  matches_cmd->add_flag("--sharp", matches_options->sharp,
                        "Render without motion blur, rolling shutter, hand tremor and lens error");
  matches_cmd->add_option("--config", *matches_config, "Settings YAML (its slam section)");
  matches_cmd->callback([=]() {
    core::SlamSettings settings;
    if (!matches_config->empty()) io::applySlamSettings(*matches_config, settings);
    evalMatches(*matches_dataset, settings, *matches_options);
  });

  auto bench_file = std::make_shared<std::string>();
  auto* bench_cmd = eval->add_subcommand("bench", "A saved bench's table and acceptance rules (DIR/bench.json)");
  bench_cmd->footer("Example:\n  hiveslam eval bench out/bench/bench.json");
  bench_cmd->add_option("BENCH_JSON", *bench_file, "bench.json written by hiveslam bench")->required();
  auto bench_plot = std::make_shared<std::string>();
  bench_cmd->add_option("--plot", *bench_plot, "Write the table as a figure (ATE, CPU and bandwidth at TR) to this PNG");
  bench_cmd->callback([bench_file, bench_plot]() {
    std::ifstream in(*bench_file);
    if (!in) throw InputError("cannot open " + *bench_file);
    const auto rows = nlohmann::json::parse(in, nullptr, false);
    if (rows.is_discarded() || !rows.is_array()) throw InputError(*bench_file + " is not a bench.json (a JSON array of rows)");
    try {
      fmt::print("{}{}", benchTable(rows), benchRules(rows));
      if (!bench_plot->empty()) plotBench(*bench_plot, rows);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(*bench_file + ": a row lacks what hiveslam bench writes (" + e.what() + ")");
    }
  });
}

}  // namespace hiveslam::apps
