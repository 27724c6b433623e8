// hiveslam synth: render a synthetic sequence (or a named suite) in the EuRoC ASL layout.
#include <fmt/format.h>

#include <filesystem>

#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "common/error.hpp"
#include "synth/suite.hpp"

namespace hiveslam::apps {

namespace {

void parseSize(const std::string& text, synth::SequenceOptions& o) {
  const auto x = text.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument(text);
    o.width = std::stoi(text.substr(0, x));
    o.height = std::stoi(text.substr(x + 1));
  } catch (const std::exception&) {
    throw InputError("--size must look like 752x480, got '" + text + "'");
  }
}

void render(const synth::SequenceOptions& o, const std::filesystem::path& out, const std::string& label) {
  Progress progress(label);
  const auto s = synth::writeSequence(o, out, [&](int d, int t) { progress.update(d, t); });
  fmt::print("{}: {} frames ({} blank), {:.1f} m in {:.1f} s, rendered in {:.1f} s -> {}\n", label,
             s.frames, s.blank_frames, s.path_length, s.duration, s.render_seconds, out.string());
}

}  // namespace

void addSynthCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("synth", "Render a synthetic sequence with exact ground truth (EuRoC layout)");
  cmd->footer("Example:\n  hiveslam synth --trajectory figure8 --seed 1 --frames 1000 --out seq/figure8");
  auto o = std::make_shared<synth::SequenceOptions>();
  auto out = std::make_shared<std::string>();
  auto size = std::make_shared<std::string>("752x480");
  auto suite_name = std::make_shared<std::string>();
  cmd->add_option("--trajectory", o->trajectory, "loop | figure8 | blackout | sweep | bigloop | handheld")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Varies textures, scene layout and the exact path")->capture_default_str();
  cmd->add_option("--frames", o->frames, "Number of frames")->capture_default_str()->check(CLI::Range(2, 1000000));
  cmd->add_option("--size", *size, "Image size WxH")->capture_default_str();
  cmd->add_option("--fps", o->fps, "Frame rate")->capture_default_str();
  cmd->add_option("--textures", o->textures, "Folder of photos to texture surfaces with (default: procedural)");
  cmd->add_flag("--distortion", o->distortion, "EuRoC-like radial-tangential lens distortion");
  cmd->add_option("--noise", o->noise, "Sensor noise sigma in grey levels")->capture_default_str();
  cmd->add_flag("--motion-blur", o->motion_blur, "Motion blur over a 10 ms exposure");
  cmd->add_flag("--exposure-changes", o->exposure_changes, "Slow exposure (gain) changes");
  cmd->add_flag("--realistic", o->realistic,
                "A furnished, lamp-lit room seen by a consumer camera: lens off its nominal calibration, motion blur, "
                "rolling shutter, auto exposure, vignetting, JPEG");
  cmd->add_option("--exposure-ms", o->exposure_ms, "With --realistic: exposure time (default 20)");
  cmd->add_option("--readout-ms", o->readout_ms, "With --realistic: rolling shutter readout, 0 for a global shutter (default 25)");
  cmd->add_option("--denoise", o->denoise, "With --realistic: the camera's denoising, grey levels, 0 for none (default 10)")
      ->check(CLI::Range(0.0, 255.0));
  cmd->add_option("--tremor-deg", o->tremor_deg, "With --realistic: the hand's tremor, 0 for none (default 0.3)");
  cmd->add_flag("!--exact-lens", o->lens_error, "With --realistic: the images made with the nominal lens of sensor.yaml");
  cmd->add_option("--photo-max-look-alikes", o->photo_max_look_alikes,
                  "With --textures: leave out photos whose features repeat more than this share, 0-1 (default 0.35 "
                  "with --realistic, the most repetitive real frames; otherwise 1, every photo)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--threads", o->threads, "Render threads (0: all cores)")->capture_default_str();
  cmd->add_option("--suite", *suite_name, "Render a named suite instead (standard | realistic)");
  cmd->add_option("--out", *out, "Output folder")->required();
  cmd->callback([=]() {
    if (!suite_name->empty()) {
      for (auto entry : synth::suite(*suite_name, o->textures)) {
        entry.options.threads = o->threads;
        render(entry.options, std::filesystem::path(*out) / entry.name, entry.name);
      }
      return;
    }
    parseSize(*size, *o);
    render(*o, *out, o->trajectory);
  });
}

}  // namespace hiveslam::apps
