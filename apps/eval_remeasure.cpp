#include "apps/eval_remeasure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <map>

#include "common/error.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/optim/remeasure_observations.hpp"
#include "core/system/slam_settings.hpp"
#include "eval/similarity.hpp"
#include "eval/trajectory_error.hpp"
#include "io/open_dataset.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::apps {

namespace {

// The final global BA of a run, as the loop closer runs it on re-measured observations (loose
// first, then sigma from the map's own median residual and an outlier round: core::solveGlobal).
double finalBundleAdjustment(core::BaProblem& ba) {
  const double sigma = core::solveGlobal(ba, 50, core::SlamSettings{}.global_ba_noise_factor, core::Outliers::SecondRound, true);
  return core::medianResidualSigma(ba) * sigma;  // in level pixels
}

// What a rendered scene says of each map point: the surface its anchor's ray meets, its normal in
// the map's frame, and what kind of surface it is.
struct SceneNormals {
  enum Surface { Room, Box, Pillar };
  std::vector<std::optional<Eigen::Vector3d>> normal;  // problem.points order
  std::vector<Surface> surface;
};

// The anchor's ray is cast from the anchor's true pose through its keypoint; the map's frame is
// put on the world's by the similarity of the keyframe centres.
SceneNormals sceneNormals(const synth::SequenceModel& model, const core::MapBaProblem& whole, const camera::CameraModel& camera) {
  Eigen::Matrix3Xd map_centres(3, static_cast<long>(whole.keyframes.size())), true_centres(3, map_centres.cols());
  for (size_t i = 0; i < whole.keyframes.size(); ++i) {
    map_centres.col(static_cast<long>(i)) = whole.problem.poses[i].T_cw().inverse().translation();
    true_centres.col(static_cast<long>(i)) = model.pose(static_cast<int>(whole.keyframes[i]->frame.index)).translation();
  }
  const Eigen::Matrix3d R_map_world = eval::umeyama(map_centres, true_centres, true).rotation.transpose();
  const std::vector<int> anchor = core::pointAnchors(whole);
  const auto& scene = model.scene;
  const int first_pillar_texture = scene.pillars.empty() ? static_cast<int>(scene.textures.size()) : scene.pillars.front().texture;
  SceneNormals out;
  out.normal.resize(whole.points.size());
  out.surface.resize(whole.points.size(), SceneNormals::Room);
  for (size_t p = 0; p < whole.points.size(); ++p) {
    const auto [kf, keypoint] = whole.sources[static_cast<size_t>(anchor[p])];
    const cv::Point2f& pt = kf->frame.keypoints[static_cast<size_t>(keypoint)].pt;
    const Eigen::Isometry3d T_wc = model.pose(static_cast<int>(kf->frame.index));
    const auto hit = scene.intersect(T_wc.translation(), T_wc.linear() * camera.unproject({pt.x, pt.y}).normalized());
    if (!hit) continue;
    out.normal[p] = R_map_world * hit->normal;
    out.surface[p] = hit->texture < 6 ? SceneNormals::Room : hit->texture < first_pillar_texture ? SceneNormals::Box : SceneNormals::Pillar;
  }
  return out;
}

// How far the normals patch alignment would use (the points' neighbours') are from the scene's,
// by the kind of surface.
void printNormalErrors(const SceneNormals& truth, const std::vector<std::optional<Eigen::Vector3d>>& fitted) {
  constexpr std::array<double, 4> kBounds{5, 10, 20, 40};
  std::array<std::array<size_t, 6>, 3> counts{};  // [surface][<5, 5-10, 10-20, 20-40, >40, no plane]
  for (size_t p = 0; p < fitted.size(); ++p) {
    if (!truth.normal[p]) continue;
    auto& row = counts[truth.surface[p]];
    if (!fitted[p]) {
      ++row[5];
      continue;
    }
    const double deg = std::acos(std::min(1.0, std::abs(fitted[p]->dot(*truth.normal[p])))) * 180.0 / M_PI;
    size_t bin = 0;
    while (bin < kBounds.size() && deg >= kBounds[bin]) ++bin;
    ++row[bin];
  }
  fmt::print("normals against the scene's   {:>7} {:>7} {:>7} {:>7} {:>7} {:>8}\n", "<5", "5-10", "10-20", "20-40", ">40", "no plane");
  const char* names[] = {"walls, floor, ceiling", "boxes", "pillars"};
  for (size_t s = 0; s < counts.size(); ++s)
    fmt::print("  {:<27} {:>7} {:>7} {:>7} {:>7} {:>7} {:>8}\n", names[s], counts[s][0], counts[s][1], counts[s][2], counts[s][3],
               counts[s][4], counts[s][5]);
}

// The problem without the observations of the poses `out` marks, and without the points that
// leaves with fewer than two.
core::BaProblem withoutPoses(const core::BaProblem& ba, const std::vector<bool>& out) {
  core::BaProblem kept = ba;
  kept.observations.clear();
  std::vector<int> views(ba.points.size(), 0);
  for (const auto& ob : ba.observations)
    if (!out[static_cast<size_t>(ob.pose)]) ++views[static_cast<size_t>(ob.point)];
  for (const auto& ob : ba.observations)
    if (!out[static_cast<size_t>(ob.pose)] && views[static_cast<size_t>(ob.point)] >= 2) kept.observations.push_back(ob);
  return kept;
}

io::Trajectory keyframeTrajectory(const core::BaProblem& ba, const std::vector<double>& stamps) {
  io::Trajectory t;
  for (size_t i = 0; i < ba.poses.size(); ++i) t.add(stamps[i], ba.poses[i].T_cw().inverse());
  return t;
}

}  // namespace

void evalRemeasure(const std::shared_ptr<core::Map>& map, const std::string& dataset, const eval::StretchSplit& split,
                   const std::vector<std::pair<double, double>>& leave_out) {
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
  // A rendered sequence's scene is the oracle for the normals (hiveslam synth writes sequence.json).
  std::optional<SceneNormals> scene;
  if (std::filesystem::exists(std::filesystem::path(dataset) / "sequence.json"))
    scene = sceneNormals(synth::buildSequence(synth::readSequenceOptions(dataset)), whole, camera);
  const core::KeyframeImages at_hand = [&](const core::KeyFrame& k) {
    return std::shared_ptr<const features::ImagePyramid>(std::shared_ptr<void>(), &images.at(&k));
  };
  core::MapBaProblem through_scene = whole;
  if (scene) {
    std::vector<Eigen::Vector3d> positions;
    for (const core::BaPoint& p : whole.problem.points) positions.push_back(p.p_w);
    const auto fitted = core::planeNormals(positions);
    printNormalErrors(*scene, fitted);
    core::remeasureObservations(through_scene, camera, at_hand, scene->normal);
  }
  const core::RemeasureStats stats = core::remeasureObservations(whole, camera, at_hand);
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
  const core::BaProblem remeasured = whole.problem;
  const double remeasured_noise = finalBundleAdjustment(whole.problem);
  report("whole-map BA, re-measured", whole.problem, remeasured_noise);
  for (const auto& [from, to] : leave_out) {
    std::vector<bool> out(stamps.size(), false);
    for (size_t k = 0; k < stamps.size(); ++k) out[k] = stamps[k] - stamps.front() >= from && stamps[k] - stamps.front() <= to;
    core::BaProblem cut = withoutPoses(remeasured, out);
    const double noise = finalBundleAdjustment(cut);
    report(fmt::format("re-measured, {:.2f}-{:.2f} s left out ({})", from, to, std::count(out.begin(), out.end(), true)).c_str(),
           cut, noise);
  }
  if (scene) {
    const double scene_noise = finalBundleAdjustment(through_scene.problem);
    report("whole-map BA, the scene's normals", through_scene.problem, scene_noise);
  }
}

}  // namespace hiveslam::apps
