#include "apps/eval_matches.hpp"

#include <fmt/format.h>

#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>

#include "common/look_alikes.hpp"
#include "core/camera/pinhole_radtan.hpp"
#include "core/features/hamming.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/map/map.hpp"
#include "core/map/map_point.hpp"
#include "core/system/slam_system.hpp"
#include "eval/trajectory_error.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::apps {

namespace {

// A match joins two different scene points when its keypoint lies further from where the scene
// point truly appears than this many pixels times the keypoint's pyramid scale (the corner
// detector places a keypoint to about a pixel of its level).
constexpr double kWrongPx = 4.0;

// The scene a rendered sequence was made of, asked where a map point truly is and where it truly
// appears in a frame.
class SceneOracle {
 public:
  explicit SceneOracle(const synth::SequenceModel& model) : model_(model) {
    for (int f = 0; f < model.options.frames; ++f) frame_at_[model.stamp(f)] = f;
  }

  std::optional<int> frameOf(double stamp) const {
    const auto it = frame_at_.find(stamp);
    if (it == frame_at_.end()) return std::nullopt;
    return it->second;
  }

  // The scene point behind a detected (distorted) keypoint of frame f.
  std::optional<Eigen::Vector3d> scenePoint(const cv::Point2f& pixel, int f) const {
    const Eigen::Vector2d n = model_.true_lens.pixelToNormalized(pixel.x, pixel.y);
    const Eigen::Isometry3d T_wc = model_.pose(f);
    const Eigen::Vector3d dir = (T_wc.linear() * Eigen::Vector3d(n.x(), n.y(), 1)).normalized();
    const auto hit = model_.scene.intersect(T_wc.translation(), dir);
    if (!hit) return std::nullopt;
    return Eigen::Vector3d(T_wc.translation() + hit->t * dir);
  }

  // Where a map point truly is: the scene point behind its first keyframe's keypoint.
  std::optional<Eigen::Vector3d> truePoint(const core::MapPoint& p) const {
    for (const auto& [kf, idx] : p.observations) {
      if (kf->id != p.first_keyframe) continue;
      const auto f = frameOf(kf->frame.timestamp);
      if (!f) return std::nullopt;
      return scenePoint(kf->frame.keypoints[static_cast<size_t>(idx)].pt, *f);
    }
    return std::nullopt;
  }

  // The (distorted) pixel where a world point appears in frame f.
  std::optional<Eigen::Vector2d> appears(const Eigen::Vector3d& X, int f) const {
    const Eigen::Vector3d c = model_.pose(f).inverse() * X;
    if (c.z() <= 0) return std::nullopt;
    const synth::Lens& L = model_.true_lens;
    const Eigen::Vector2d d = L.distort({c.x() / c.z(), c.y() / c.z()});
    return Eigen::Vector2d(L.fx * d.x() + L.cx, L.fy * d.y() + L.cy);
  }

  const synth::SequenceModel& model() const { return model_; }

 private:
  const synth::SequenceModel& model_;
  std::map<double, int> frame_at_;
};

double scaleOf(int octave) { return std::pow(1.2, octave); }

class MatchProbe : public core::SystemEvents {
 public:
  MatchProbe(const SceneOracle& oracle, bool erase_wrong) : oracle_(oracle), erase_wrong_(erase_wrong) {}

  void mapCreated(const std::shared_ptr<core::Map>& map) override {
    std::lock_guard l(mutex_);
    fmt::print("map {} started\n", map->id);
    origin_.reset();
  }

  // New points as local mapping made them: does each join one scene point in every view?
  void keyframeTriangulated(const std::shared_ptr<core::Map>& map, const std::shared_ptr<core::KeyFrame>& kf) override {
    std::lock_guard l(mutex_);
    std::lock_guard lock(map->mutex);
    const auto f = oracle_.frameOf(kf->frame.timestamp);
    if (!f) return;
    int made = 0, wrong = 0;
    std::vector<std::shared_ptr<core::MapPoint>> to_erase;
    for (size_t i = 0; i < kf->points.size(); ++i) {
      const auto& p = kf->points[i];
      if (!p || p->bad || p->first_keyframe != kf->id) continue;
      const auto X = oracle_.truePoint(*p);
      if (!X) continue;
      ++made;
      const bool joins_two = seesAnotherPoint(*p, *X, kf->frame.keypoints[i].octave);
      wrong += joins_two;
      if (joins_two && erase_wrong_) to_erase.push_back(p);
      const bool weak = std::any_of(p->observations.begin(), p->observations.end(), [&](const auto& o) {
        return features::isWeakCorner(o.first->frame.keypoints[static_cast<size_t>(o.second)]);
      });
      weak_points_ += weak;
      weak_wrong_ += weak && joins_two;
      if (p->observations.size() == 2) {
        const auto a = *p->observations.begin(), b = *std::next(p->observations.begin());
        const int d = features::hamming(a.first->frame.descriptors.ptr<uchar>(a.second), b.first->frame.descriptors.ptr<uchar>(b.second));
        ++distances_[weak][joins_two][std::min(d / 10, 5)];
        const int nn = std::min(selfNearest(*a.first, a.second), selfNearest(*b.first, b.second));
        const double r = nn > 0 ? static_cast<double>(d) / nn : 9.0;
        ++ratios_[weak][joins_two][std::min(static_cast<int>(r / 0.2), 6)];
      }
    }
    new_points_ += made;
    new_wrong_ += wrong;
    pending_[kf->id] = {made, wrong};
    for (const auto& p : to_erase) map->erase(*p);
  }

  // The keyframe after local BA: its rotation error and the map's scale around it.
  void keyframeMapped(const std::shared_ptr<core::Map>& map, const std::shared_ptr<core::KeyFrame>& kf) override {
    std::lock_guard l(mutex_);
    std::lock_guard lock(map->mutex);
    const auto f = oracle_.frameOf(kf->frame.timestamp);
    if (!f) return;
    if (!origin_ && map->origin) {
      const auto g = oracle_.frameOf(map->origin->frame.timestamp);
      if (g) origin_ = Origin{map->origin->T_cw, oracle_.model().pose(*g)};
    }
    // The map's scale: the median over the keyframe's points of true over estimated distance.
    std::vector<double> ratios;
    const Eigen::Vector3d center = kf->center(), true_center = oracle_.model().pose(*f).translation();
    for (size_t i = 0; i < kf->points.size(); ++i) {
      const auto& p = kf->points[i];
      if (!p || p->bad) continue;
      const auto X = oracle_.scenePoint(kf->frame.keypoints[i].pt, *f);
      const double est = (p->position - center).norm();
      if (X && est > 0) ratios.push_back((*X - true_center).norm() / est);
    }
    double scale = 0, misplaced = 0;
    if (!ratios.empty()) {
      std::vector<double> sorted = ratios;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
      scale = sorted[sorted.size() / 2];
      // Misplaced: at a distance from the keyframe more than 25% off what the map's scale there
      // makes of the true one, whether its partner was right or not.
      for (double r : ratios) misplaced += std::abs(r / scale - 1) > 0.25;
      misplaced /= static_cast<double>(ratios.size());
    }
    const auto made = pending_[kf->id];
    pending_.erase(kf->id);
    fmt::print("keyframe {:6} at {:7.2f} s: {:4} new points, {:5.1f}% joining two scene points | {:5.1f}% of its {:4} points misplaced | rotation error {:6.2f} deg | {:7.3f} m per map unit\n",
               kf->id, oracle_.model().stamp(*f) - oracle_.model().stamp(0), made.first,
               made.first ? 100.0 * made.second / made.first : 0.0, 100.0 * misplaced, ratios.size(),
               rotationError(kf->T_cw, *f), scale);
    misplaced_sum_ += misplaced;
    ++keyframes_;
  }

  // A tracked frame's inliers: is each keypoint where its map point's scene point appears?
  void frame(const core::FrameRecord& r, const Eigen::Isometry3d& T_cw, const std::shared_ptr<core::Map>& map) {
    const auto f = oracle_.frameOf(r.timestamp);
    if (!f) return;
    std::lock_guard l(mutex_);
    Second& s = seconds_[static_cast<int>(oracle_.model().stamp(*f) - oracle_.model().stamp(0))];
    ++s.frames;
    if (!r.tracked || !map) return;
    ++s.tracked;
    std::lock_guard lock(map->mutex);
    for (const auto& o : r.observations) {
      const auto it = map->points.find(o.point);
      if (it == map->points.end()) continue;
      const auto X = oracle_.truePoint(*it->second);
      if (!X) continue;
      const auto at = oracle_.appears(*X, *f);
      Eigen::Vector2d raw;
      const Eigen::Vector3d ray((o.uv.x() - K_.cx) / K_.fx, (o.uv.y() - K_.cy) / K_.fy, 1.0);
      if (!camera_ || !camera_->project(ray, raw)) continue;
      ++s.matches;
      s.wrong += !at || (*at - raw).norm() > kWrongPx * scaleOf(o.octave);
    }
    s.rotation_error = std::max(s.rotation_error, rotationError(T_cw, *f));
  }

  // The map as the run left it: its points with an observation away from their scene point.
  void judgeMap(const core::Map& map) {
    std::lock_guard l(mutex_);
    int points = 0, wrong = 0;
    for (const auto& [id, p] : map.points) {
      if (p->bad) continue;
      const auto X = oracle_.truePoint(*p);
      if (!X) continue;
      ++points;
      wrong += seesAnotherPoint(*p, *X, 0);
    }
    fmt::print("map {} at the end: {} points, {:.1f}% with an observation of another scene point\n", map.id, points,
               points ? 100.0 * wrong / points : 0.0);
  }

  void setCamera(std::shared_ptr<const camera::CameraModel> camera, const core::Intrinsics& K) {
    camera_ = std::move(camera);
    K_ = K;
  }

  void summary() {
    std::lock_guard l(mutex_);
    fmt::print("\nsecond | frames tracked | tracking inliers joined to another scene point | largest rotation error, deg\n");
    int64_t matches = 0, wrong = 0;
    for (const auto& [second, s] : seconds_) {
      fmt::print("{:6} | {:3} of {:3} | {:5.1f}% of {:5} | {:6.2f}\n", second, s.tracked, s.frames,
                 s.matches ? 100.0 * static_cast<double>(s.wrong) / static_cast<double>(s.matches) : 0.0, s.matches,
                 s.rotation_error);
      matches += s.matches;
      wrong += s.wrong;
    }
    fmt::print("\nnew points: {}, {:.1f}% joining two scene points; tracking inliers: {}, {:.1f}% joined to another scene point\n",
               new_points_, new_points_ ? 100.0 * new_wrong_ / new_points_ : 0.0, matches,
               matches ? 100.0 * static_cast<double>(wrong) / static_cast<double>(matches) : 0.0);
    fmt::print("new points by the distance of their two descriptors (0-9, 10-19, 20-29, 30-39, 40-49, 50+) | by that "
               "distance over the nearer look-alike's in either image (under 0.2, 0.4, 0.6, 0.8, 1.0, 1.2, more):\n");
    for (int weak : {0, 1})
      for (int wrong : {0, 1})
        fmt::print("  {:6} {:5}: {:>5} | {:>5}\n", weak ? "weak" : "strong", wrong ? "wrong" : "right",
                   fmt::join(distances_[weak][wrong], " "), fmt::join(ratios_[weak][wrong], " "));
    fmt::print("new points with a keypoint found only at the detector's lower threshold: {} ({:.1f}%), {:.1f}% of them joining two scene points; the others {:.1f}%\n",
               weak_points_, new_points_ ? 100.0 * weak_points_ / new_points_ : 0.0,
               weak_points_ ? 100.0 * weak_wrong_ / weak_points_ : 0.0,
               new_points_ > weak_points_ ? 100.0 * (new_wrong_ - weak_wrong_) / (new_points_ - weak_points_) : 0.0);
    fmt::print("keyframes after local BA: {}, on average {:.1f}% of their points misplaced (25% off the map's scale)\n",
               keyframes_, keyframes_ ? 100.0 * misplaced_sum_ / keyframes_ : 0.0);
  }

 private:
  struct Origin {
    Eigen::Isometry3d T_cw, T_wc_true;
  };
  struct Second {
    int frames = 0, tracked = 0;
    int64_t matches = 0, wrong = 0;
    double rotation_error = 0;
  };

  // Whether a keyframe sees the map point whose scene point is X away from where X appears: its
  // keypoint further than kWrongPx times its level's scale (at least `min_octave`'s).
  bool seesAnotherPoint(const core::MapPoint& p, const Eigen::Vector3d& X, int min_octave) const {
    for (const auto& [kf, idx] : p.observations) {
      const auto g = oracle_.frameOf(kf->frame.timestamp);
      if (!g) continue;
      const auto& kp = kf->frame.keypoints[static_cast<size_t>(idx)];
      const auto at = oracle_.appears(X, *g);
      if (!at || (*at - Eigen::Vector2d(kp.pt.x, kp.pt.y)).norm() > kWrongPx * scaleOf(std::max(kp.octave, min_octave)))
        return true;
    }
    return false;
  }

  // Rotation since the map's first keyframe, estimated against true, in degrees.
  double rotationError(const Eigen::Isometry3d& T_cw, int f) const {
    if (!origin_) return 0;
    const Eigen::Matrix3d est = origin_->T_cw.linear() * T_cw.linear().transpose();
    const Eigen::Matrix3d truth = origin_->T_wc_true.linear().transpose() * oracle_.model().pose(f).linear();
    return Eigen::AngleAxisd(est.transpose() * truth).angle() * 180.0 / M_PI;
  }

  const SceneOracle& oracle_;
  const bool erase_wrong_;
  std::mutex mutex_;
  std::optional<Origin> origin_;
  std::map<core::Id, std::pair<int, int>> pending_;
  std::map<int, Second> seconds_;
  int new_points_ = 0, new_wrong_ = 0, keyframes_ = 0, weak_points_ = 0, weak_wrong_ = 0;
  std::array<std::array<std::array<int, 6>, 2>, 2> distances_{};
  std::array<std::array<std::array<int, 7>, 2>, 2> ratios_{};
  std::map<core::Id, std::vector<uint8_t>> self_nn_;
  // A keypoint's nearest look-alike in its own keyframe, computed once per keyframe.
  int selfNearest(const core::KeyFrame& kf, int i) {
    auto& v = self_nn_[kf.id];
    if (v.empty()) v = lookAlikeDistances(kf.frame.keypoints, kf.frame.descriptors);
    return v[static_cast<size_t>(i)];
  }
  double misplaced_sum_ = 0;
  std::shared_ptr<const camera::CameraModel> camera_;
  core::Intrinsics K_;
};

}  // namespace

void evalMatches(const std::string& dataset, const core::SlamSettings& settings, const MatchesOptions& options) {
  synth::SequenceOptions o = synth::readSequenceOptions(dataset);
  if (options.sharp) {
    o.motion_blur = false;
    o.exposure_ms = 0;
    o.readout_ms = 0;
    o.tremor_deg = 0;
    o.lens_error = false;
  }
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.true_lens);
  const synth::Lens& L = options.true_lens ? model.true_lens : model.lens;
  auto camera = std::make_shared<camera::PinholeRadTan>(L.width, L.height, L.fx, L.fy, L.cx, L.cy,
                                                        std::vector<double>(L.k.begin(), L.k.end()));
  SceneOracle oracle(model);
  MatchProbe probe(oracle, options.oracle);
  core::SlamSettings s = settings;
  s.refine_frames = true;  // the frames' inliers
  core::SlamSystem slam(s, camera, core::SlamSystem::Mode::Sequential);
  // Inliers come as undistorted pixels of the camera's pinhole part: back to raw pixels.
  probe.setCamera(camera, {L.fx, L.fy, L.cx, L.cy});
  slam.setEvents(&probe);
  slam.setFrameListener([&](const core::FrameRecord& r, const Eigen::Isometry3d& T_cw, const std::vector<cv::KeyPoint>&,
                            const cv::Mat&) { probe.frame(r, T_cw, slam.findMap(r.map)); });
  const int frames = options.frames > 0 ? std::min(options.frames, o.frames) : o.frames;
  fmt::print("{}: {} frames{}{}{}, sequential\n", dataset, frames, options.sharp ? ", sharp (no blur, rolling shutter, tremor or lens error)" : "",
             options.true_lens ? ", true lens" : "", options.oracle ? ", wrong new points erased" : "");
  for (int f = 0; f < frames; ++f) slam.process(model.renderImage(f, rays), model.stamp(f));
  slam.finish();
  slam.refineFrames();
  probe.summary();
  const auto map = slam.largestMap();
  if (!map) return;
  {
    std::lock_guard lock(map->mutex);
    probe.judgeMap(*map);
  }
  io::Trajectory truth, estimate;
  for (int f = 0; f < frames; ++f) truth.add(model.stamp(f), model.pose(f));
  for (const auto& r : slam.frames())
    if (r.tracked && slam.currentMapId(r.map) == map->id) estimate.add(r.timestamp, slam.poseOf(r));
  if (estimate.size() < 3) return;
  const auto ate = eval::computeAte(truth, estimate);
  fmt::print("largest map of {}: {} of {} frames, ATE RMSE {:.4f} m ({:.2f}% of {:.2f} m)\n", slam.liveMaps().size(),
             estimate.size(), frames, ate.stats.rmse, 100.0 * ate.stats.rmse / std::max(ate.reference_length, 1e-9),
             ate.reference_length);
}

}  // namespace hiveslam::apps
