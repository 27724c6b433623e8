#pragma once
// The named camera motions of `hiveslam synth --trajectory`: waypoints for the eye and the
// look-at target inside a room of the given size, and the stretches of the path where the
// images are blank (forced tracking loss).
#include <random>
#include <string>
#include <vector>

#include "synth/camera_path.hpp"

namespace hiveslam::synth {

struct TrajectoryPlan {
  std::vector<Waypoint> waypoints;
  // Spline parameter ranges [from, to) during which frames are blank.
  std::vector<std::pair<double, double>> blank;
  std::string description;
};

// kind: loop (about 1.15 laps, returns to the start), figure8 (about 1.2 figure-eights,
// revisiting the first lobe), blackout (west side, blank transit, east side, back to the west
// side), sweep (along one wall and back along the opposite one, no place revisited).
TrajectoryPlan planTrajectory(const std::string& kind, const Eigen::Vector3d& room_size,
                              std::mt19937_64& rng);

const std::vector<std::string>& trajectoryKinds();

}  // namespace hiveslam::synth
