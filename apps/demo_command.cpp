// hiveslam demo: the README's main job on a built-in default. Until the SLAM core lands it
// renders a sequence, streams it back through the dataset reader, and checks the evaluation
// on a known answer: the ground truth moved by a known similarity plus noise of known size.
#include <fmt/format.h>

#include <filesystem>
#include <random>

#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "eval/resource_monitor.hpp"
#include "eval/trajectory_error.hpp"
#include "eval/trajectory_plot.hpp"
#include "io/open_dataset.hpp"
#include "io/trajectory_io.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::apps {

void addDemoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Render a sequence, read it back and evaluate (built-in default)");
  auto out = std::make_shared<std::string>("demo_out");
  auto options = std::make_shared<synth::SequenceOptions>();
  options->frames = 300;
  cmd->add_option("--out", *out, "Output folder")->capture_default_str();
  cmd->add_option("--frames", options->frames, "Frames to render")->capture_default_str();
  cmd->add_option("--trajectory", options->trajectory, "loop | figure8 | blackout | sweep")->capture_default_str();
  cmd->callback([=]() {
    eval::ResourceMonitor monitor;
    const std::filesystem::path root(*out);
    const std::filesystem::path seq = root / options->trajectory;
    Progress render_progress("rendering");
    const auto summary = synth::writeSequence(*options, seq, [&](int d, int t) { render_progress.update(d, t); });

    auto source = io::openDataset(seq);
    Progress read_progress("reading");
    int frames = 0;
    while (source->next()) read_progress.update(++frames, static_cast<int>(*source->size()));
    const io::Trajectory& gt = *source->groundTruth();

    // A stand-in estimate with a known answer: scale 0.5, rotated, shifted, 2 cm noise per axis.
    std::mt19937_64 rng(7);
    std::normal_distribution<double> noise(0.0, 0.02);
    io::Trajectory est;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    for (size_t i = 0; i < gt.size(); ++i) {
      Eigen::Isometry3d T = gt.poses[i];
      T.translation() = 0.5 * (R * T.translation() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))) +
                        Eigen::Vector3d(1, -2, 0.5);
      T.linear() = R * T.linear();
      est.add(gt.stamps[i], T);
    }
    io::writeTrajectory(root / "estimate.tum", est, io::TrajectoryFormat::Tum);
    const auto ate = eval::computeAte(gt, est);
    eval::plotTopView(root / "trajectory.png", ate.pair.ref, ate.pair.est,
                      {fmt::format("demo: ATE RMSE {:.4f} m", ate.stats.rmse), 900, {}});

    fmt::print("\n{:<34} {}\n", "sequence", seq.string());
    fmt::print("{:<34} {}\n", "dataset", source->describe());
    fmt::print("{:<34} {} ({} blank)\n", "frames rendered", summary.frames, summary.blank_frames);
    fmt::print("{:<34} {}\n", "frames read back", frames);
    fmt::print("{:<34} {:.2f} m in {:.1f} s\n", "camera path", summary.path_length, summary.duration);
    fmt::print("{:<34} {:.1f} s ({:.1f} frames/s)\n", "render time", summary.render_seconds,
               summary.frames / summary.render_seconds);
    fmt::print("{:<34} {:.4f} m (expected {:.4f} m: 2 cm noise per axis)\n", "ATE RMSE of the stand-in",
               ate.stats.rmse, 0.02 * std::sqrt(3.0));
    fmt::print("{:<34} {:.4f} (expected 2.0000)\n", "recovered scale", ate.pair.alignment.scale);
    fmt::print("{:<34} {:.1f} % of one core, {:.0f} MB peak\n", "process CPU", monitor.cpuPercent(),
               eval::ResourceMonitor::peakRssBytes() / 1048576.0);
    fmt::print("{:<34} {}\n", "plot", (root / "trajectory.png").string());
  });
}

}  // namespace hiveslam::apps
