// libFuzzer target: the readers of files a user or a dataset hands to hiveslam (settings YAML
// with its camera, slam, distribution, dds and view sections; EuRoC sensor.yaml; KITTI
// calib.txt; times files). The first byte picks the reader; the rest is the file. A reader may
// accept the file or throw InputError (one line, the command exits non-zero); anything else
// (another exception, a crash, a sanitizer report) is a finding. Settings a reader accepts
// must then work: the camera projects and unprojects, the ORB options build an extractor that
// runs on an image.
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

#include <opencv2/core.hpp>

#include "common/error.hpp"
#include "core/features/orb_extractor.hpp"
#include "io/camera_settings.hpp"
#include "io/slam_settings_io.hpp"
#include "io/times_file.hpp"

using namespace hiveslam;

namespace {

// One file per process, rewritten for each input: the readers take paths.
const std::string& scratch(const char* extension) {
  static const std::string yaml = "/tmp/hiveslam_settings_fuzz_" + std::to_string(getpid()) + ".yaml";
  static const std::string txt = "/tmp/hiveslam_settings_fuzz_" + std::to_string(getpid()) + ".txt";
  return std::string(extension) == ".txt" ? txt : yaml;
}

void useCamera(const io::CameraSettings& c) {
  const auto& cam = *c.camera;
  const Eigen::Vector2d centre(cam.width() / 2.0, cam.height() / 2.0);
  Eigen::Vector2d uv;
  (void)cam.project(cam.unproject(centre), uv);
}

void useOrb(const core::SlamSettings& s) {
  features::OrbExtractor extractor(s.orb);
  cv::Mat image(96, 128, CV_8U);
  cv::randu(image, 0, 255);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  extractor.extract(image, keypoints, descriptors);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const int reader = data[0] % 6;
  const std::string& file = scratch(reader == 4 || reader == 5 ? ".txt" : ".yaml");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    switch (reader) {
      case 0: {
        core::SlamSettings s;
        io::applySlamSettings(file, s);
        useOrb(s);
        break;
      }
      case 1: {
        distribution::DistributionSettings d;
        io::applyDistributionSettings(file, d);
        communication::DdsOptions o;
        io::applyDdsSettings(file, o);
        viz::ViewSettings v;
        io::applyViewSettings(file, v);
        break;
      }
      case 2:
        useCamera(io::loadSettingsCamera(file));
        break;
      case 3:
        useCamera(io::loadEurocSensorYaml(file));
        break;
      case 4:
        useCamera(io::loadCalibTxt(file));
        break;
      default:
        io::readTimesFile(file);
    }
  } catch (const InputError&) {
  }
  return 0;
}
