// TUM RGB-D layout: rgb.txt ("timestamp filename"), groundtruth.txt (TUM format). The
// calibration is not part of the format, so it comes from --config (or a calib.txt beside).
#include "common/error.hpp"
#include "io/image_list_source.hpp"
#include "io/open_dataset.hpp"
#include "io/text_table.hpp"
#include "io/trajectory_io.hpp"

namespace hiveslam::io {

namespace fs = std::filesystem;

std::unique_ptr<FrameSource> openTumRgbd(const fs::path& root, const DatasetOptions& options) {
  CameraSettings camera = resolveCamera(options, root / "calib.txt", &loadCalibTxt, root);
  const fs::path list = root / "rgb.txt";
  std::vector<ImageEntry> entries;
  std::vector<double> stamps;
  std::vector<int> lines;
  for (const auto& row : readTextTable(list)) {
    if (row.fields.size() < 2)
      throw InputError(list.string() + ":" + std::to_string(row.line) +
                       ": expected 'timestamp filename'");
    entries.push_back({parseNumber(row.fields[0], list, row.line), root / row.fields[1]});
    stamps.push_back(entries.back().timestamp);
    lines.push_back(row.line);
  }
  checkIncreasing(stamps, list, lines);
  std::optional<Trajectory> gt;
  if (fs::exists(root / "groundtruth.txt"))
    gt = readTrajectory(root / "groundtruth.txt", TrajectoryFormat::Tum);
  return std::make_unique<ImageListSource>("TUM RGB-D", root, std::move(entries),
                                           std::move(camera), std::move(gt));
}

}  // namespace hiveslam::io
