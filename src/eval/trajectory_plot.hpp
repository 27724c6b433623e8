#pragma once
// Top view of an estimate against ground truth, as a PNG. The view plane is the one spanned by
// the two axes along which the reference moves most (x-y for a car, x-z for a camera frame).
#include <filesystem>
#include <string>
#include <vector>

#include "io/trajectory.hpp"

namespace hiveslam::eval {

struct PlotEvent {
  double stamp;       // placed at the estimate pose nearest in time
  std::string label;  // e.g. "loop", "merge"
};

struct PlotOptions {
  std::string title;
  int size = 900;  // pixels, square
  std::vector<PlotEvent> events;
};

void plotTopView(const std::filesystem::path& png, const io::Trajectory& reference,
                 const io::Trajectory& estimate, const PlotOptions& options);

}  // namespace hiveslam::eval
