// hiveslam demo: the README's main job on a built-in default. Renders a synthetic sequence, runs
// it through the 1-node (standalone) and the 3-node system (TR, LM and LC as separate processes
// over Fast DDS on this machine), and prints the paper's result table.
#include <fmt/format.h>

#include <filesystem>

#include "apps/bench.hpp"
#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::apps {

void addDemoCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Render a sequence, run it on 1 and 3 nodes, print a table (built-in default)");
  cmd->footer("Example:\n  hiveslam demo --out demo_out");
  auto out = std::make_shared<std::string>("demo_out");
  auto options = std::make_shared<synth::SequenceOptions>();
  auto repeats = std::make_shared<int>(1);
  options->frames = 400;
  cmd->add_option("--out", *out, "Output folder")->capture_default_str();
  cmd->add_option("--frames", options->frames, "Frames to render")->capture_default_str();
  cmd->add_option("--trajectory", options->trajectory, "loop | figure8 | blackout | sweep | bigloop")->capture_default_str();
  cmd->add_option("--repeats", *repeats, "Runs per configuration")->capture_default_str();
  cmd->callback([=]() {
    const std::filesystem::path root(*out);
    const std::filesystem::path seq = root / options->trajectory;
    Progress render_progress("rendering");
    const auto rendered = synth::writeSequence(*options, seq, [&](int d, int t) { render_progress.update(d, t); });
    BenchOptions b;
    b.sequences = {seq.string()};
    b.out = (root / "bench").string();
    b.repeats = *repeats;
    const auto rows = runBench(b);
    fmt::print("\nsequence {}: {} frames at 20 Hz, {:.1f} m, rendered in {:.1f} s\n", seq.string(), rendered.frames,
               rendered.path_length, rendered.render_seconds);
    fmt::print("1 node: the standalone system (tracking, local mapping, loop closing threads; no network)\n");
    fmt::print("3 nodes: TR, LM and LC as separate processes over Fast DDS (loopback), frames at their timestamps\n\n");
    fmt::print("{}", benchTable(rows));
    fmt::print("outputs: {}/<config>_run<n>/{{trajectory.tum,trajectory.png,tr,lm,lc}}, {}/bench.json\n",
               (root / "bench" / options->trajectory).string(), (root / "bench").string());
  });
}

}  // namespace hiveslam::apps
