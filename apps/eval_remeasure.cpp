#include "apps/eval_remeasure.hpp"

#include <fmt/format.h>

#include <map>

#include "common/error.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/optim/remeasure_observations.hpp"
#include "core/system/slam_settings.hpp"
#include "eval/trajectory_error.hpp"
#include "io/open_dataset.hpp"

namespace hiveslam::apps {

namespace {

// The final global BA of a run, as the loop closer runs it on re-measured observations (loose
// first, then sigma from the map's own median residual and an outlier round: core::solveGlobal).
double finalBundleAdjustment(core::BaProblem& ba) {
  const double sigma = core::solveGlobal(ba, 50, core::SlamSettings{}.global_ba_noise_factor, core::Outliers::SecondRound, true);
  return core::medianResidualSigma(ba) * sigma;  // in level pixels
}

io::Trajectory keyframeTrajectory(const core::BaProblem& ba, const std::vector<double>& stamps) {
  io::Trajectory t;
  for (size_t i = 0; i < ba.poses.size(); ++i) t.add(stamps[i], ba.poses[i].T_cw().inverse());
  return t;
}

}  // namespace

void evalRemeasure(const std::shared_ptr<core::Map>& map, const std::string& dataset, const eval::StretchSplit& split) {
  auto source = io::openDataset(dataset);
  if (!source->groundTruth()) throw InputError("the dataset has no ground truth: " + dataset);
  const io::Trajectory& gt = *source->groundTruth();
  const camera::CameraModel& camera = *source->camera().camera;
  // The atlas keeps keypoint levels, not the pyramid's settings: the default pyramid.
  const features::OrbOptions orb;
  const features::OrbExtractor pyramid(orb);

  std::lock_guard lock(map->mutex);
  core::MapBaProblem whole = core::buildMapBaProblem(*map, pyramid.scales());
  std::vector<double> stamps;
  std::map<size_t, const core::KeyFrame*> by_frame;
  for (const core::KeyFrame* k : whole.keyframes) {
    stamps.push_back(k->frame.timestamp);
    by_frame[k->frame.index] = k;
  }
  std::map<const core::KeyFrame*, features::ImagePyramid> images;
  while (images.size() < by_frame.size()) {
    auto frame = source->next();
    if (!frame) break;
    const auto it = by_frame.find(frame->index);
    if (it != by_frame.end()) images.emplace(it->second, features::ImagePyramid(frame->image, orb.levels, orb.scale_factor));
  }
  if (images.size() < by_frame.size())
    throw InputError(fmt::format("the dataset holds the images of {} of the map's {} keyframes", images.size(), by_frame.size()));

  core::BaProblem detected = whole.problem;
  const core::RemeasureStats stats = core::remeasureObservations(
      whole, camera, [&](const core::KeyFrame& k) { return std::shared_ptr<const features::ImagePyramid>(std::shared_ptr<void>(), &images.at(&k)); });
  fmt::print("map {}: {} keyframes, {} points, {} observations: {} anchors, {} measured again, {} kept as found; "
             "{} points with a plane from their neighbours\n",
             map->id, whole.keyframes.size(), whole.points.size(), whole.problem.observations.size(), stats.anchors,
             stats.aligned, stats.kept, stats.plane_normals);
  const auto report = [&](const char* what, const core::BaProblem& ba, double noise) {
    const io::Trajectory est = keyframeTrajectory(ba, stamps);
    const auto ate = eval::computeAte(gt, est);
    const auto step = eval::computeScaleStep(gt, est, split);
    fmt::print("{:<36} keyframe ATE {:6.2f} mm  scale step {:+.3f}%  residual noise {:.3f} px per level\n", what,
               1000.0 * ate.stats.rmse, 100.0 * (step.step() - 1.0), noise);
  };
  report("as saved", detected, core::medianResidualSigma(detected));
  const double detected_noise = finalBundleAdjustment(detected);
  report("whole-map BA, detected corners", detected, detected_noise);
  const double remeasured_noise = finalBundleAdjustment(whole.problem);
  report("whole-map BA, re-measured", whole.problem, remeasured_noise);
}

}  // namespace hiveslam::apps
