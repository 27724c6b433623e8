#include "io/camera_settings.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <map>

#include "common/error.hpp"
#include "core/camera/kannala_brandt.hpp"
#include "core/camera/pinhole_radtan.hpp"
#include "io/text_table.hpp"
#include "io/yaml_file.hpp"

namespace hiveslam::io {

std::shared_ptr<const camera::CameraModel> makeCamera(const std::string& model, int width,
                                                      int height,
                                                      const std::vector<double>& intrinsics,
                                                      const std::vector<double>& distortion,
                                                      const std::string& source) {
  if (width <= 0 || height <= 0)
    throw InputError(fmt::format("{}: image size {}x{} is not valid", source, width, height));
  if (intrinsics.size() != 4)
    throw InputError(fmt::format("{}: intrinsics need 4 values (fx fy cx cy), got {}", source,
                                 intrinsics.size()));
  for (double v : intrinsics)
    if (!std::isfinite(v)) throw InputError(source + ": intrinsics must be finite numbers");
  const double fx = intrinsics[0], fy = intrinsics[1], cx = intrinsics[2], cy = intrinsics[3];
  if (fx <= 0 || fy <= 0)
    throw InputError(fmt::format("{}: focal lengths must be positive (fx={}, fy={})", source, fx, fy));
  if (cx < 0 || cy < 0 || cx > width || cy > height)
    throw InputError(fmt::format("{}: principal point ({}, {}) lies outside the {}x{} image",
                                 source, cx, cy, width, height));
  if (model == "pinhole" || model == "pinhole-radtan" || model == "radial-tangential" ||
      model == "radtan") {
    if (!distortion.empty() && distortion.size() != 4 && distortion.size() != 5)
      throw InputError(fmt::format(
          "{}: radial-tangential distortion needs 4 or 5 coefficients, got {}", source,
          distortion.size()));
    return std::make_shared<camera::PinholeRadTan>(width, height, fx, fy, cx, cy, distortion);
  }
  if (model == "kannala-brandt" || model == "kannala_brandt" || model == "equidistant" ||
      model == "fisheye") {
    if (distortion.size() != 4)
      throw InputError(fmt::format("{}: Kannala-Brandt distortion needs 4 coefficients, got {}",
                                   source, distortion.size()));
    return std::make_shared<camera::KannalaBrandt>(width, height, fx, fy, cx, cy, distortion);
  }
  throw InputError(source + ": unknown camera model '" + model + "'");
}

namespace {

template <typename T>
T required(const YAML::Node& node, const std::string& key, const std::filesystem::path& path) {
  if (!node[key]) throw InputError(path.string() + ": missing key '" + key + "'");
  try {
    return node[key].as<T>();
  } catch (const YAML::Exception&) {
    throw InputError(path.string() + ": key '" + key + "' has the wrong type");
  }
}

template <typename T>
T optional(const YAML::Node& node, const std::string& key, T fallback,
           const std::filesystem::path& path) {
  if (!node[key]) return fallback;
  return required<T>(node, key, path);
}

}  // namespace

const std::vector<std::string>& cameraSettingKeys() {
  static const std::vector<std::string> keys{"model", "width", "height", "intrinsics", "distortion", "fps"};
  return keys;
}

bool hasCameraSection(const std::filesystem::path& path) { return static_cast<bool>(loadYamlMap(path)["camera"]); }

CameraSettings loadSettingsCamera(const std::filesystem::path& path) {
  const YAML::Node root = loadYamlMap(path);
  const YAML::Node cam = mapAt(root, "camera", path);
  if (!cam) throw InputError(path.string() + ": no 'camera' section");
  for (const auto& kv : cam) {
    if (!kv.first.IsScalar()) throw InputError(path.string() + ": a key in 'camera' is not a name");
    const auto key = kv.first.Scalar();
    if (std::find(cameraSettingKeys().begin(), cameraSettingKeys().end(), key) == cameraSettingKeys().end())
      throw InputError(path.string() + ": unknown setting 'camera." + key + "'");
  }
  // One statement per key so that the first missing key is the one reported.
  const auto model = required<std::string>(cam, "model", path);
  const int width = required<int>(cam, "width", path);
  const int height = required<int>(cam, "height", path);
  const auto intrinsics = required<std::vector<double>>(cam, "intrinsics", path);
  const auto distortion = optional<std::vector<double>>(cam, "distortion", {}, path);
  CameraSettings s;
  s.camera = makeCamera(model, width, height, intrinsics, distortion, path.string());
  s.fps = optional<double>(cam, "fps", 0.0, path);
  return s;
}

CameraSettings loadEurocSensorYaml(const std::filesystem::path& path) {
  const YAML::Node root = loadYamlMap(path);
  const auto resolution = required<std::vector<int>>(root, "resolution", path);
  if (resolution.size() != 2)
    throw InputError(fmt::format("{}: 'resolution' needs 2 values, got {}", path.string(),
                                 resolution.size()));
  const std::string projection = optional<std::string>(root, "camera_model", "pinhole", path);
  if (projection != "pinhole")
    throw InputError(path.string() + ": camera_model '" + projection + "' is not supported");
  const auto model = optional<std::string>(root, "distortion_model", "radial-tangential", path);
  const auto intrinsics = required<std::vector<double>>(root, "intrinsics", path);
  const auto distortion = optional<std::vector<double>>(root, "distortion_coefficients", {}, path);
  CameraSettings s;
  s.camera = makeCamera(model, resolution[0], resolution[1], intrinsics, distortion, path.string());
  s.fps = optional<double>(root, "rate_hz", 0.0, path);
  if (const YAML::Node t_bs = mapAt(root, "T_BS", path)) {
    const auto data = required<std::vector<double>>(t_bs, "data", path);
    if (data.size() != 16)
      throw InputError(fmt::format("{}: T_BS needs 16 values, got {}", path.string(), data.size()));
    Eigen::Matrix4d M;
    for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = data[i];
    s.T_body_cam.matrix() = M;
  }
  return s;
}

CameraSettings loadCalibTxt(const std::filesystem::path& path) {
  std::map<std::string, double> kv;
  for (const auto& row : readTextTable(path)) {
    if (row.fields.size() != 2)
      throw InputError(fmt::format("{}:{}: expected 'key value'", path.string(), row.line));
    kv[row.fields[0]] = parseNumber(row.fields[1], path, row.line);
  }
  auto get = [&](const std::string& key) {
    auto it = kv.find(key);
    if (it == kv.end()) throw InputError(path.string() + ": missing '" + key + "'");
    return it->second;
  };
  std::vector<double> distortion;
  if (kv.count("k1")) {
    for (const char* key : {"k1", "k2", "p1", "p2"}) distortion.push_back(get(key));
    if (kv.count("k3")) distortion.push_back(get("k3"));
  }
  // Checked before the casts: a width of 1e30 or NaN has no int (UB, a fuzzer finding).
  for (const char* key : {"width", "height"})
    if (!(get(key) >= 1 && get(key) <= 100000))
      throw InputError(fmt::format("{}: '{}' must be 1 to 100000 pixels", path.string(), key));
  CameraSettings s;
  s.camera = makeCamera("pinhole", static_cast<int>(get("width")), static_cast<int>(get("height")),
                        {get("fx"), get("fy"), get("cx"), get("cy")}, distortion, path.string());
  s.fps = kv.count("fps") ? kv["fps"] : 0.0;
  return s;
}

CameraSettings loadCameraFile(const std::filesystem::path& path) {
  if (path.extension() == ".txt") return loadCalibTxt(path);
  return loadYamlMap(path)["camera"] ? loadSettingsCamera(path) : loadEurocSensorYaml(path);
}

void writeSettingsCamera(const std::filesystem::path& path, const camera::CameraModel& camera,
                         double fps) {
  const auto p = camera.parameters();
  std::ofstream out(path);
  out << "# hiveslam settings\ncamera:\n";
  out << "  model: " << camera.type() << "\n";
  out << "  width: " << camera.width() << "\n  height: " << camera.height() << "\n";
  out << fmt::format("  intrinsics: [{}]\n", fmt::join(p.begin(), p.begin() + 4, ", "));
  out << fmt::format("  distortion: [{}]\n", fmt::join(p.begin() + 4, p.end(), ", "));
  out << "  fps: " << fps << "\n";
  if (!out) throw InputError("cannot write " + path.string());
}

}  // namespace hiveslam::io
