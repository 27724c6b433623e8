#pragma once
// Camera calibration from the three places it is found: our settings YAML (section
// `camera:`), a EuRoC/TUM-VI `sensor.yaml`, and a KITTI-style key-value `calib.txt`.
// Every reader validates sizes and values and throws InputError naming the file.
#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/camera/camera_model.hpp"

namespace hiveslam::io {

struct CameraSettings {
  std::shared_ptr<const camera::CameraModel> camera;
  double fps = 0.0;                                        // 0 when the file does not say
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();  // EuRoC's T_BS
};

// Builds a model from its parts; `source` names the file in error messages.
// model: "pinhole-radtan" (alias "pinhole") or "kannala-brandt" (aliases "equidistant",
// "fisheye").
std::shared_ptr<const camera::CameraModel> makeCamera(const std::string& model, int width,
                                                      int height,
                                                      const std::vector<double>& intrinsics,
                                                      const std::vector<double>& distortion,
                                                      const std::string& source);

// The keys of a settings file's `camera:` section; any other key there is an error.
const std::vector<std::string>& cameraSettingKeys();

CameraSettings loadSettingsCamera(const std::filesystem::path& settings_yaml);
// Whether a settings file has a `camera:` section (one with only `slam:` settings leaves the
// calibration to the dataset).
bool hasCameraSection(const std::filesystem::path& settings_yaml);
CameraSettings loadEurocSensorYaml(const std::filesystem::path& sensor_yaml);
CameraSettings loadCalibTxt(const std::filesystem::path& calib_txt);

// Any of the three, told apart by content: `.txt` is calib.txt, a YAML with a `camera:`
// section is a settings file, any other YAML a sensor.yaml.
CameraSettings loadCameraFile(const std::filesystem::path& path);

// Writes the `camera:` section of a settings file (used by `hiveslam synth`).
void writeSettingsCamera(const std::filesystem::path& path, const camera::CameraModel& camera,
                         double fps);

}  // namespace hiveslam::io
