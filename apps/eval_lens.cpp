#include "apps/eval_lens.hpp"

#include <fmt/format.h>

#include "common/error.hpp"
#include "core/camera/pinhole_radtan.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/optim/lens_refinement.hpp"
#include "io/camera_settings.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::apps {

namespace {

void printLens(const char* what, const core::LensParameters& l) {
  fmt::print("{:<10} fx {:8.2f}  fy {:8.2f}  cx {:7.2f}  cy {:7.2f}  k1 {:+.4f}\n", what, l.fx, l.fy, l.cx, l.cy, l.k1);
}

}  // namespace

void evalLens(const std::shared_ptr<core::Map>& map, const std::string& camera_file, const std::string& dataset,
              const std::string& write) {
  const io::CameraSettings cam = io::loadCameraFile(camera_file);
  const std::vector<double> p = cam.camera->parameters();
  if (cam.camera->type() != "pinhole-radtan")
    throw InputError(camera_file + ": eval lens refines a pinhole-radtan camera, not " + cam.camera->type());
  for (size_t i = 5; i < p.size(); ++i)
    if (p[i] != 0) throw InputError(camera_file + ": eval lens refines k1 alone; the camera has other distortion terms");
  const core::LensParameters nominal{p[0], p[1], p[2], p[3], p[4]};
  // The atlas keeps keypoint levels, not the pyramid's settings: the default pyramid.
  const features::OrbExtractor pyramid(features::OrbOptions{});
  core::LensRefinement r;
  {
    std::lock_guard lock(map->mutex);
    r = core::refineLens(core::rawObservations(core::buildMapBaProblem(*map, pyramid.scales())), nominal);
  }
  fmt::print("map {}: {} keyframes, {} observations of points seen 3 times or more, {} left out as outliers\n", map->id,
             map->keyframes.size(), r.observations, r.outliers);
  printLens("given", nominal);
  printLens("refined", r.lens);
  if (!dataset.empty()) {
    const synth::SequenceModel model = synth::buildSequence(synth::readSequenceOptions(dataset));
    const synth::Lens& t = model.true_lens;
    printLens("rendered", {t.fx, t.fy, t.cx, t.cy, t.k[0]});
  }
  fmt::print("reprojection RMS {:.3f} -> {:.3f} px per level{}\n", r.rms_before_px, r.rms_after_px,
             r.converged ? "" : " (not converged)");
  if (!write.empty()) {
    const camera::PinholeRadTan refined(cam.camera->width(), cam.camera->height(), r.lens.fx, r.lens.fy, r.lens.cx,
                                        r.lens.cy, {r.lens.k1, 0, 0, 0});
    io::writeSettingsCamera(write, refined, cam.fps);
    fmt::print("written to {}\n", write);
  }
}

}  // namespace hiveslam::apps
