#include "synth/trajectory_plan.hpp"

#include <cmath>

#include "common/error.hpp"

namespace hiveslam::synth {

const std::vector<std::string>& trajectoryKinds() {
  static const std::vector<std::string> kinds{"loop", "figure8", "blackout", "sweep", "bigloop", "handheld"};
  return kinds;
}

namespace {

// A waypoint whose target lies `reach` metres away in direction `yaw` (world, about z), a
// little below eye height so the floor is in view too: a single plane would make two-view
// initialization ambiguous.
Waypoint look(const Eigen::Vector3d& eye, double yaw, double reach = 3.0) {
  return {eye, eye + Eigen::Vector3d(reach * std::cos(yaw), reach * std::sin(yaw), -0.35 * reach / 3.0)};
}

}  // namespace

TrajectoryPlan planTrajectory(const std::string& kind, const Eigen::Vector3d& room,
                              std::mt19937_64& rng) {
  auto jitter = [&](double a) { return std::uniform_real_distribution<double>(-a, a)(rng); };
  const double hx = room.x() / 2, hy = room.y() / 2;
  auto height = [&]() { return 1.45 + jitter(0.12); };
  TrajectoryPlan plan;
  if (kind == "loop") {
    // Counter-clockwise around an ellipse, looking outwards and 35 degrees ahead.
    const double a = 0.3 * hx, b = 0.3 * hy;
    const int per_lap = 12;
    const int n = static_cast<int>(per_lap * 1.15) + 1;
    for (int k = 0; k <= n; ++k) {
      const double th = 2 * M_PI * k / per_lap;
      const Eigen::Vector3d eye(a * std::cos(th) + (k % per_lap ? jitter(0.12) : 0),
                                b * std::sin(th) + (k % per_lap ? jitter(0.12) : 0), height());
      plan.waypoints.push_back(look(eye, th + 35.0 * M_PI / 180.0));
    }
    plan.description = "1.15 laps of an ellipse looking outwards; returns to its start";
  } else if (kind == "bigloop") {
    // Close to the walls, looking at them 55 degrees ahead of the heading: the view changes
    // fast, keyframes share few points with those a few metres back, and monocular scale
    // drift builds up over the lap; the drift a loop closure has to remove.
    const double a = hx - 1.5, b = hy - 1.5;
    const int per_lap = 16;
    const int n = static_cast<int>(per_lap * 1.12) + 1;
    for (int k = 0; k <= n; ++k) {
      const double th = 2 * M_PI * k / per_lap;
      const Eigen::Vector3d eye(a * std::cos(th) + (k % per_lap ? jitter(0.1) : 0),
                                b * std::sin(th) + (k % per_lap ? jitter(0.1) : 0), height());
      const double heading = std::atan2(b * std::cos(th), -a * std::sin(th));
      plan.waypoints.push_back(look(eye, heading - 55.0 * M_PI / 180.0, 2.0));
    }
    plan.description = "1.12 laps near the walls looking at them; drift builds up before the return";
  } else if (kind == "figure8") {
    // Lemniscate of Gerono through the room centre, looking 40 degrees left of the heading.
    const double a = 0.45 * hx, b = 0.6 * hy;
    const int per_cycle = 16;
    const int n = static_cast<int>(per_cycle * 1.2) + 1;
    for (int k = 0; k <= n; ++k) {
      const double th = 2 * M_PI * k / per_cycle;
      const Eigen::Vector3d eye(a * std::sin(th), b * std::sin(th) * std::cos(th), height());
      const double heading = std::atan2(b * std::cos(2 * th), a * std::cos(th));
      plan.waypoints.push_back(look(eye, heading + 40.0 * M_PI / 180.0));
    }
    plan.description = "1.2 figure-eights; the first lobe is travelled twice";
  } else if (kind == "blackout") {
    const double x = 0.35 * hx, y = 0.45 * hy;
    const double west = M_PI, east = 0.0, south = -M_PI / 2;
    // A: walk north on the west side, looking at the west wall.
    for (int k = 0; k <= 4; ++k)
      plan.waypoints.push_back(look({-x + jitter(0.1), -y + 2 * y * k / 4, height()}, west + 0.25 * jitter(1)));
    const double blank_from = static_cast<double>(plan.waypoints.size()) - 1;
    // Blank transit: cross briskly to the east side while turning round.
    plan.waypoints.back().pace = 4.0;
    plan.waypoints.push_back(look({0.0, y, height()}, M_PI / 2));
    plan.waypoints.back().pace = 4.0;
    plan.waypoints.push_back(look({x, y, height()}, east));
    const double blank_to = static_cast<double>(plan.waypoints.size()) - 1 - 0.1;
    // B: walk south on the east side looking east, then west along the south side looking south.
    for (int k = 1; k <= 4; ++k)
      plan.waypoints.push_back(look({x + jitter(0.1), y - 2 * y * k / 4, height()}, east + 0.25 * jitter(1)));
    plan.waypoints.push_back(look({0.0, -y - 0.05, height()}, south + 0.3));
    // Back to the start of A, looking west again, and along A's first half: the revisit.
    for (int k = 0; k <= 2; ++k)
      plan.waypoints.push_back(look({-x + jitter(0.1), -y + 2 * y * k / 4, height()}, west + 0.25 * jitter(1)));
    plan.blank.emplace_back(blank_from + 0.2, blank_to);
    plan.description = "west side, blank transit to the east side, east and south sides, back to the west side";
  } else if (kind == "sweep") {
    const double x = 0.6 * hx, y = 0.25 * hy;
    const double north = M_PI / 2, south = -M_PI / 2;
    for (int k = 0; k <= 5; ++k)
      plan.waypoints.push_back(look({-x + 2 * x * k / 5, y + jitter(0.15), height()}, north + 0.35 * std::sin(k * 1.3)));
    plan.waypoints.push_back(look({x + 0.3, 0.0, height()}, 0.0));
    for (int k = 0; k <= 5; ++k)
      plan.waypoints.push_back(look({x - 2 * x * k / 5, -y + jitter(0.15), height()}, south + 0.35 * std::sin(k * 1.3)));
    plan.description = "along the north wall, round the east end, back along the south wall; no revisit";
  } else if (kind == "handheld") {
    // A person walking slowly round the middle of the room with a camera in hand, looking out at
    // the walls and furniture and swinging the view left and right, then past the start again
    // (the revisit). A lap of about 5.5 m; at 1000 frames of 30 Hz, about 0.2 m/s, turning
    // at about 15 degrees a second with peaks near 45.
    const double a = std::min(1.25, 0.3 * hx), b = std::min(0.95, 0.3 * hy);
    const int per_lap = 14;
    const int n = static_cast<int>(per_lap * 1.2) + 1;
    for (int k = 0; k <= n; ++k) {
      const double th = 2 * M_PI * k / per_lap;
      const double swing = (k % per_lap ? 0.3 : 0.0) * std::sin(2.3 * k);
      const Eigen::Vector3d eye(a * std::cos(th) + (k % per_lap ? jitter(0.15) : 0),
                                b * std::sin(th) + (k % per_lap ? jitter(0.15) : 0),
                                1.45 + (k % per_lap ? jitter(0.1) : 0));
      // Looking 15 degrees down, at table tops and the floor in front of the walls.
      Waypoint w = look(eye, th + 0.5 + swing, 2.5);
      w.target.z() = eye.z() - 2.5 * std::tan(15.0 * M_PI / 180.0);
      plan.waypoints.push_back(w);
    }
    plan.description = "a walk round the middle of the room looking out, view swinging; 1.2 laps (revisits its start)";
  } else {
    throw InputError("unknown trajectory '" + kind + "' (loop, figure8, blackout, sweep, bigloop, handheld)");
  }
  return plan;
}

}  // namespace hiveslam::synth
