// hiveslam demo: the README's main job on a built-in default. Renders a synthetic sequence,
// runs the SLAM system on it, and prints a result table. (The 3-node configuration joins the
// table when the distribution layer lands.)
#include <fmt/format.h>

#include <filesystem>

#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "apps/run_slam.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::apps {

void addDemoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Render a sequence and run SLAM on it (built-in default)");
  auto out = std::make_shared<std::string>("demo_out");
  auto options = std::make_shared<synth::SequenceOptions>();
  options->frames = 400;
  cmd->add_option("--out", *out, "Output folder")->capture_default_str();
  cmd->add_option("--frames", options->frames, "Frames to render")->capture_default_str();
  cmd->add_option("--trajectory", options->trajectory, "loop | figure8 | blackout | sweep")->capture_default_str();
  cmd->callback([=]() {
    const std::filesystem::path root(*out);
    const std::filesystem::path seq = root / options->trajectory;
    Progress render_progress("rendering");
    const auto rendered = synth::writeSequence(*options, seq, [&](int d, int t) { render_progress.update(d, t); });
    RunOptions run;
    run.dataset = seq.string();
    run.out = (root / "slam").string();
    const RunSummary s = runSlam(run);
    const auto& r = s.report;
    auto num = [&](const char* a, const char* b = nullptr) {
      const auto& v = b ? r.at(a).at(b) : r.at(a);
      return v.get<double>();
    };
    fmt::print("\n{:<28} {}\n", "sequence", fmt::format("{} ({} frames, {:.1f} m, rendered in {:.1f} s)", seq.string(),
                                                         rendered.frames, rendered.path_length, rendered.render_seconds));
    fmt::print("{:<28} {}\n", "configuration", "1 node (standalone: tracking, local mapping, loop closing threads)");
    fmt::print("{:<28} {:.0f} of {:.0f} ({:.1f}%)\n", "tracked frames", num("tracked_frames"), num("frames"),
               100.0 * num("tracked_frames") / std::max(num("frames"), 1.0));
    fmt::print("{:<28} {:.0f}\n", "failures", num("failures"));
    fmt::print("{:<28} {:.0f} in {:.0f} map(s)\n", "keyframes", num("keyframes"), num("maps"));
    fmt::print("{:<28} {:.0f} loop(s), {:.0f} merge(s), {:.0f} global BA(s)\n", "loop closing", num("loops"),
               num("merges"), num("global_bas"));
    if (r.contains("ate"))
      fmt::print("{:<28} {:.4f} m ({:.2f}% of {:.1f} m)\n", "ATE RMSE (Sim3)", num("ate", "rmse"),
                 num("ate", "percent_of_path"), num("ate", "path_length"));
    fmt::print("{:<28} median {:.1f} ms, p95 {:.1f} ms\n", "tracking time", num("tracking_ms", "median"),
               num("tracking_ms", "p95"));
    fmt::print("{:<28} {:.1f} s CPU in {:.1f} s ({:.0f}% of one core)\n", "CPU", num("cpu_seconds"),
               num("wall_seconds"), num("cpu_percent"));
    fmt::print("{:<28} {}\n", "outputs", (root / "slam").string() + "/{trajectory.tum,report.json,trajectory.png}");
  });
}

}  // namespace hiveslam::apps
