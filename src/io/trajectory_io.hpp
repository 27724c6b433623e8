#pragma once
// Trajectory files in the three formats the community uses, with evo's reading rules:
//  TUM   "t x y z qx qy qz qw" (seconds)
//  EuRoC "t[ns],px,py,pz,qw,qx,qy,qz[,...]" (ground-truth csv; stamps divided by 1e9)
//  KITTI 12 numbers per line, the row-major 3x4 [R|t]; no stamps (line index is used)
#include <filesystem>
#include <optional>
#include <string>

#include "io/trajectory.hpp"

namespace hiveslam::io {

enum class TrajectoryFormat { Tum, Euroc, Kitti };

TrajectoryFormat parseTrajectoryFormat(const std::string& name);  // "tum", "euroc", "kitti"
std::string toString(TrajectoryFormat format);
// Guesses from the file: a .csv or a first column in ns is EuRoC, 12 fields KITTI, 8 TUM.
TrajectoryFormat detectTrajectoryFormat(const std::filesystem::path& path);

Trajectory readTrajectory(const std::filesystem::path& path,
                          std::optional<TrajectoryFormat> format = std::nullopt);
void writeTrajectory(const std::filesystem::path& path, const Trajectory& trajectory,
                     TrajectoryFormat format);

}  // namespace hiveslam::io
