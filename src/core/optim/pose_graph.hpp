#pragma once
// Pose graph optimization in Sim3 (the essential graph of a loop closure): keyframe poses S_iw
// linked by relative similarities measured before the correction (spanning tree, strong
// covisibility, earlier loops) and by the new loop's links measured after it. The error of a
// loop spreads along the graph, and scale drift is corrected with it.
#include <vector>

#include "core/geometry/sim3.hpp"

namespace hiveslam::core {

struct PoseGraphEdge {
  int i = 0, j = 0;
  Sim3 S_ij;  // measured S_iw * S_jw^-1
  double weight = 1.0;
};

struct PoseGraph {
  std::vector<Sim3> poses;  // S_iw
  std::vector<bool> fixed;
  std::vector<PoseGraphEdge> edges;
};

struct PoseGraphSummary {
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;
};

PoseGraphSummary optimizePoseGraph(PoseGraph& graph, int iterations = 20);

}  // namespace hiveslam::core
