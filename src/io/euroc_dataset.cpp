// EuRoC ASL layout (also TUM-VI's): mav0/cam0/{data.csv,data/,sensor.yaml} and ground truth in
// mav0/state_groundtruth_estimate0/data.csv (TUM-VI: mav0/mocap0/data.csv) as body poses,
// turned into camera poses with the sensor's T_BS.
#include <charconv>

#include "common/error.hpp"
#include "io/image_list_source.hpp"
#include "io/open_dataset.hpp"
#include "io/text_table.hpp"
#include "io/trajectory_io.hpp"

namespace hiveslam::io {

namespace fs = std::filesystem;

std::unique_ptr<FrameSource> openEuroc(const fs::path& root, const DatasetOptions& options) {
  const fs::path mav0 = fs::exists(root / "mav0") ? root / "mav0" : root;
  const fs::path cam0 = mav0 / "cam0";
  const fs::path csv = cam0 / "data.csv";
  CameraSettings camera = resolveCamera(options, cam0 / "sensor.yaml", &loadEurocSensorYaml, root);

  std::vector<ImageEntry> entries;
  std::vector<double> stamps;
  std::vector<int> lines;
  for (const auto& row : readTextTable(csv)) {
    if (row.fields.size() < 2)
      throw InputError(csv.string() + ":" + std::to_string(row.line) +
                       ": expected 'timestamp [ns],filename'");
    long long ns = 0;
    const std::string& f = row.fields[0];
    auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), ns);
    if (ec != std::errc() || ptr != f.data() + f.size())
      throw InputError(csv.string() + ":" + std::to_string(row.line) + ": '" + f +
                       "' is not a timestamp in ns");
    entries.push_back({static_cast<double>(ns) / 1e9, cam0 / "data" / row.fields[1]});
    stamps.push_back(entries.back().timestamp);
    lines.push_back(row.line);
  }
  checkIncreasing(stamps, csv, lines);

  std::optional<Trajectory> gt;
  for (const char* sub : {"state_groundtruth_estimate0", "mocap0"}) {
    const fs::path file = mav0 / sub / "data.csv";
    if (!fs::exists(file)) continue;
    Trajectory body = readTrajectory(file, TrajectoryFormat::Euroc);
    for (auto& T : body.poses) T = T * camera.T_body_cam;
    gt = std::move(body);
    break;
  }
  return std::make_unique<ImageListSource>("EuRoC", root, std::move(entries), std::move(camera),
                                           std::move(gt));
}

}  // namespace hiveslam::io
