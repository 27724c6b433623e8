#pragma once
// Every observation of a map measured again by patch alignment: each point's patch in the first
// keyframe that saw it (its anchor), warped into every other keyframe that sees it through the
// plane the point lies on, and aligned there from the keypoint found. The points keep their
// anchors' corners; the other views then measure the same texture location instead of a corner
// that moves with the view (features/patch_alignment.hpp).
//
// Why: on sweep, a whole-map BA of the re-measured observations bends the map through the turn
// about half as much (scale step sd 0.21% -> 0.10%; keyframe ATE median 3.6 -> 1.5 mm over 12 maps),
// where a BA of the detected corners returns to the step from the true poses: the corners hold it. The plane comes from the point's neighbours
// (map/point_normals.hpp); the fronto-parallel guess gains nothing.
#include <functional>
#include <memory>

#include "core/camera/camera_model.hpp"
#include "core/features/image_pyramid.hpp"
#include "core/features/patch_alignment.hpp"
#include "core/map/point_normals.hpp"
#include "core/optim/map_ba_problem.hpp"
#include "core/optim/remeasurements.hpp"

namespace hiveslam::core {

struct RemeasureOptions {
  int patch_half = 4;
  features::PatchAlignmentOptions alignment;
  PlaneNormalOptions normals;
};

struct RemeasureStats {
  size_t anchors = 0;        // observations that define their point, kept as found
  size_t aligned = 0;        // measured again
  size_t kept = 0;           // alignment failed or no image: kept as found
  size_t plane_normals = 0;  // points with a normal from their neighbours (others: facing the anchor)
};

// The grey image pyramid of a keyframe (null when it is not at hand: the observation is kept).
// Shared, so that a cache may let it go while an alignment still reads it. The observations are
// taken anchor by anchor, each anchor's in keyframe order: a cache of a few dozen pyramids serves
// them (KeyframeImageStore).
using KeyframeImages = std::function<std::shared_ptr<const features::ImagePyramid>(const KeyFrame&)>;

// Replaces the `uv` of the observations of `mp` (buildMapBaProblem, with its poses and points)
// by re-measured ones, and adds each to `measured` when given. The caller holds the map's mutex.
RemeasureStats remeasureObservations(MapBaProblem& mp, const camera::CameraModel& camera, const KeyframeImages& images,
                                     const RemeasureOptions& options = {}, Remeasurements* measured = nullptr);

// The same through the normals given (problem.points order; nothing: facing the anchor) instead
// of those of the points' neighbours: evaluations compare the normals a scene really has.
RemeasureStats remeasureObservations(MapBaProblem& mp, const camera::CameraModel& camera, const KeyframeImages& images,
                                     const std::vector<std::optional<Eigen::Vector3d>>& normals,
                                     const RemeasureOptions& options = {}, Remeasurements* measured = nullptr);

}  // namespace hiveslam::core
