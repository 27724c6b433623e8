#include "io/trajectory_io.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include "common/error.hpp"
#include "io/text_table.hpp"

namespace hiveslam::io {

TrajectoryFormat parseTrajectoryFormat(const std::string& name) {
  if (name == "tum") return TrajectoryFormat::Tum;
  if (name == "euroc") return TrajectoryFormat::Euroc;
  if (name == "kitti") return TrajectoryFormat::Kitti;
  throw InputError("unknown trajectory format '" + name + "' (tum, euroc or kitti)");
}

std::string toString(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::Tum: return "tum";
    case TrajectoryFormat::Euroc: return "euroc";
    case TrajectoryFormat::Kitti: return "kitti";
  }
  return "?";
}

TrajectoryFormat detectTrajectoryFormat(const std::filesystem::path& path) {
  if (path.extension() == ".csv") return TrajectoryFormat::Euroc;
  const auto rows = readTextTable(path);
  if (rows.empty()) throw InputError(path.string() + ": no poses in file");
  const auto& first = rows.front().fields;
  if (first.size() == 12) return TrajectoryFormat::Kitti;
  if (first.size() == 8) return TrajectoryFormat::Tum;
  if (first.size() >= 8) return TrajectoryFormat::Euroc;
  throw InputError(fmt::format("{}:{}: cannot tell the trajectory format from {} columns",
                               path.string(), rows.front().line, first.size()));
}

namespace {

Eigen::Isometry3d poseFrom(const Eigen::Vector3d& t, Eigen::Quaterniond q) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace

Trajectory readTrajectory(const std::filesystem::path& path,
                          std::optional<TrajectoryFormat> format) {
  if (!std::filesystem::exists(path)) throw InputError("trajectory file not found: " + path.string());
  const TrajectoryFormat f = format ? *format : detectTrajectoryFormat(path);
  const auto rows = readTextTable(path);
  Trajectory trajectory;
  const size_t needed = f == TrajectoryFormat::Kitti ? 12 : 8;
  for (const auto& row : rows) {
    if (row.fields.size() < needed || (f == TrajectoryFormat::Tum && row.fields.size() != 8) ||
        (f == TrajectoryFormat::Kitti && row.fields.size() != 12))
      throw InputError(fmt::format("{}:{}: {} fields where the {} format has {}", path.string(),
                                   row.line, row.fields.size(), toString(f), needed));
    double v[12];
    for (size_t i = 0; i < needed; ++i) v[i] = parseNumber(row.fields[i], path, row.line);
    switch (f) {
      case TrajectoryFormat::Tum:
        trajectory.add(v[0], poseFrom({v[1], v[2], v[3]}, Eigen::Quaterniond(v[7], v[4], v[5], v[6])));
        break;
      case TrajectoryFormat::Euroc:
        trajectory.add(v[0] / 1e9,
                       poseFrom({v[1], v[2], v[3]}, Eigen::Quaterniond(v[4], v[5], v[6], v[7])));
        break;
      case TrajectoryFormat::Kitti: {
        Eigen::Matrix3d R;
        R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        T.linear() = R;
        T.translation() = Eigen::Vector3d(v[3], v[7], v[11]);
        trajectory.add(static_cast<double>(trajectory.size()), T);
        break;
      }
    }
  }
  if (trajectory.empty()) throw InputError(path.string() + ": no poses in file");
  return trajectory;
}

void writeTrajectory(const std::filesystem::path& path, const Trajectory& trajectory,
                     TrajectoryFormat format) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  auto out = fmt::output_file(path.string());
  if (format == TrajectoryFormat::Euroc)
    out.print("#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],"
              "q_RS_y [],q_RS_z []\n");
  for (size_t i = 0; i < trajectory.size(); ++i) {
    const Eigen::Isometry3d& T = trajectory.poses[i];
    const Eigen::Vector3d p = T.translation();
    const Eigen::Quaterniond q(T.linear());
    switch (format) {
      case TrajectoryFormat::Tum:
        out.print("{:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", trajectory.stamps[i],
                  p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
        break;
      case TrajectoryFormat::Euroc:
        out.print("{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f}\n",
                  static_cast<long long>(std::llround(trajectory.stamps[i] * 1e9)), p.x(), p.y(),
                  p.z(), q.w(), q.x(), q.y(), q.z());
        break;
      case TrajectoryFormat::Kitti: {
        const Eigen::Matrix3d R = T.linear();
        out.print("{:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e}\n",
                  R(0, 0), R(0, 1), R(0, 2), p.x(), R(1, 0), R(1, 1), R(1, 2), p.y(), R(2, 0),
                  R(2, 1), R(2, 2), p.z());
        break;
      }
    }
  }
}

}  // namespace hiveslam::io
